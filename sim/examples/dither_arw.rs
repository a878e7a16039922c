//! Scratch: the lock-in error's random walk against Killpatrick's formula.
use gyro_sim::rlg_dither::{DitherParams, DitheredRlg};

fn main() {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let p = DitherParams {
        counts_per_deg: a[0],
        lock_in_dps: a[1],
        dither_dps: a[2],
        dither_hz: a[3],
        noise_frac: a[4],
        seed: a.get(7).copied().unwrap_or(1.0) as u64,
        ..Default::default()
    };
    let rate = a[5];
    let dur = a[6];
    let mut s = DitheredRlg::<f64>::new(p);
    let n = (dur * 10.0) as usize;
    let mut e = vec![];
    let t0 = std::time::Instant::now();
    for k in 1..=n {
        let r = s.advance(k as f64 / 10.0, rate, |_| {});
        if !r.lockin_counts.is_finite() && std::env::var("DBG").is_ok() {
            println!("NaN at k {k} t {}", k as f64 / 10.0);
            std::process::exit(1);
        }
        e.push(r.lockin_counts / p.counts_per_deg); // deg
    }
    let wall = t0.elapsed().as_secs_f64();
    let pred = p.killpatrick_arw_dps_rts();
    let mut out = String::new();
    for tau_n in [1usize, 10, 100] {
        let m = e.len() / tau_n;
        let d: Vec<f64> = (1..m).map(|i| e[i * tau_n] - e[(i - 1) * tau_n]).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (d.len() - 1) as f64;
        let tau = tau_n as f64 / 10.0;
        out += &format!(
            " tau {tau}: N/pred {:.3} (n {})",
            (var / tau).sqrt() / pred,
            d.len()
        );
    }
    let mean_rate = (e[e.len() - 1] - e[0]) / (dur - 0.1) * 3600.0;
    println!("K {} OL {} Od {} fd {} noise {} rate {}: sigma_phi {:.2} rad, pred {:.3e} deg/rts |{out} | mean err {mean_rate:.4} deg/h | wall {wall:.1} s",
        p.counts_per_deg, p.lock_in_dps, p.dither_dps, p.dither_hz, p.noise_frac, rate, p.crossing_phase_rms_rad(), pred);
}
