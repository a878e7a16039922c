//! Scratch: fast simulator against the brute force.
use gyro_sim::rlg_dither::{BruteForce, DitherParams, DitheredRlg, Latch};

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let p = DitherParams {
        counts_per_deg: args.first().copied().unwrap_or(2000.0),
        lock_in_dps: args.get(1).copied().unwrap_or(0.2),
        dither_dps: args.get(2).copied().unwrap_or(100.0),
        dither_hz: args.get(3).copied().unwrap_or(500.0),
        noise_frac: args.get(4).copied().unwrap_or(0.05),
        accuracy: gyro_sim::rlg_dither::Accuracy {
            c1: args.get(8).copied().unwrap_or(7.0),
            c2: 50.0,
            step_rad: args.get(9).copied().unwrap_or(0.8),
            fast_trig: false,
        },
        ..Default::default()
    };
    let rate = args.get(5).copied().unwrap_or(0.0);
    let dur = args.get(6).copied().unwrap_or(0.1);
    let spr = args.get(7).copied().unwrap_or(16.0);
    let mut a: Vec<Latch> = vec![];
    let t0 = std::time::Instant::now();
    let n = (dur * 500.0) as usize;
    let w = if std::env::var("F32").is_ok() {
        let mut fast = DitheredRlg::<f32>::new(p);
        for k in 1..=n {
            fast.advance(k as f64 / 500.0, rate, |l| a.push(*l));
        }
        fast.window_dps()
    } else {
        let mut fast = DitheredRlg::<f64>::new(p);
        for k in 1..=n {
            fast.advance(k as f64 / 500.0, rate, |l| a.push(*l));
        }
        fast.window_dps()
    };
    let tf = t0.elapsed().as_secs_f64();
    let mut b: Vec<Latch> = vec![];
    let t0 = std::time::Instant::now();
    let mut bf = BruteForce::new(p, p.dither_dps * 1.5 + rate.abs(), spr);
    for k in 1..=n {
        bf.advance(k as f64 / 500.0, rate, |l| b.push(*l));
    }
    let tb = t0.elapsed().as_secs_f64();
    let m = a.len().min(b.len());
    let mut se = 0.0;
    let mut kick = 0.0;
    let mut maxd: f64 = 0.0;
    for i in 0..m {
        let d = a[i].truth_counts - b[i].truth_counts;
        se += d * d;
        maxd = maxd.max(d.abs());
        if i > 0 {
            let k = b[i].truth_counts
                - b[i - 1].truth_counts
                - rate * p.counts_per_deg * (b[i].t_s - b[i - 1].t_s);
            kick += k * k;
        }
    }
    let blk = m / 10;
    let krms = |v: &Vec<Latch>, b: usize| {
        ((b * blk + 1..(b + 1) * blk)
            .map(|i| {
                let k = v[i].truth_counts
                    - v[i - 1].truth_counts
                    - rate * p.counts_per_deg * (v[i].t_s - v[i - 1].t_s);
                k * k
            })
            .sum::<f64>()
            / blk as f64)
            .sqrt()
    };
    for bb in 0..10 {
        print!("{:.5}/{:.5} ", krms(&a, bb), krms(&b, bb));
    }
    println!();
    let mut inc = 0.0;
    for i in 1..m {
        let d = (a[i].truth_counts - a[i - 1].truth_counts)
            - (b[i].truth_counts - b[i - 1].truth_counts);
        inc += d * d;
    }
    println!(
        "per-crossing error rms / kick rms: {:.2e}",
        (inc / kick).sqrt()
    );
    let q = m / 4;
    println!(
        "diff at quarter/half/end: {:.2e} {:.2e} {:.2e}",
        a[q].truth_counts - b[q].truth_counts,
        a[2 * q].truth_counts - b[2 * q].truth_counts,
        a[m - 1].truth_counts - b[m - 1].truth_counts
    );
    println!(
        "latches {} {} | rms diff {:.3e} counts, max {:.3e} | rms kick {:.3e} counts | ratio {:.2e} | fast {:.3} s brute {:.3} s | window {:.1} dps | last truth {:.4} {:.4}",
        a.len(), b.len(), (se / m as f64).sqrt(), maxd, (kick / (m - 1) as f64).sqrt(),
        (se / kick * (m-1) as f64 / m as f64).sqrt(), tf, tb, w,
        a[m-1].truth_counts, b[m-1].truth_counts
    );
}
