//! Scratch: per-crossing kicks, their autocorrelation and sum.
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
        pickoff_delay_s: 0.0,
        ..Default::default()
    };
    let rate = a[5];
    let dur = a[6];
    let mut s = DitheredRlg::<f64>::new(p);
    let mut tr = vec![];
    let mut ts = vec![];
    let n = (dur * 10.0) as usize;
    for k in 1..=n {
        s.advance(k as f64 / 10.0, rate, |l| {
            tr.push(l.truth_counts);
            ts.push(l.t_s);
        });
    }
    let kicks: Vec<f64> = (1..tr.len())
        .map(|i| tr[i] - tr[i - 1] - rate * p.counts_per_deg * (ts[i] - ts[i - 1]))
        .collect();
    let blk = kicks.len() / 10;
    let r: Vec<f64> = (0..10)
        .map(|b| {
            (kicks[b * blk..(b + 1) * blk]
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
                / blk as f64)
                .sqrt()
        })
        .collect();
    println!(
        "block rms {:?}",
        r.iter()
            .map(|x| (x * 1e5).round() / 1e5)
            .collect::<Vec<_>>()
    );
    let m = kicks.len() as f64;
    let mean = kicks.iter().sum::<f64>() / m;
    let var = kicks.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / m;
    let mut ac = vec![];
    for lag in 1..6 {
        let c: f64 = (lag..kicks.len())
            .map(|i| (kicks[i] - mean) * (kicks[i - lag] - mean))
            .sum::<f64>()
            / m;
        ac.push(c / var);
    }
    // predicted kick rms in counts
    let kfr = p.fringes_per_deg();
    let amp = p.lock_in_dps * (1.0 / (kfr * p.omega_dot())).sqrt() * p.counts_per_deg;
    println!(
        "kick rms {:.4e} pred {:.4e} ratio {:.3}; autocorr {:?}; sum-of-kicks N ratio {:.3}",
        var.sqrt(),
        amp / 2f64.sqrt(),
        var.sqrt() / (amp / 2f64.sqrt()),
        ac.iter()
            .map(|x| (x * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>(),
        (var * (1.0 + 2.0 * ac.iter().sum::<f64>())).sqrt() / (amp / 2f64.sqrt())
    );
}
