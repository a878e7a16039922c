//! The conventional readings of an Allan-deviation curve, as most papers
//! and Stable32 report them, read off the measured points themselves
//! (physics.md section 3): N where the -1/2 line crosses tau = 1 s, the
//! floor (the curve's minimum) and B = floor/0.664, and whether the curve
//! turns up after the floor (else the floor is only an upper bound on the
//! bias instability).

/// Largest distance of a local slope from -1/2 on the -1/2 region.
pub const SLOPE_TOLERANCE: f64 = 0.1;
/// Shortest -1/2 region read, as a ratio of averaging times.
pub const MIN_SPAN: f64 = 3.0;
/// Half-width of the window of a local slope, decades.
const WINDOW_DECADES: f64 = 0.2;

#[derive(Clone, Debug, PartialEq)]
pub struct Readings {
    /// N read at tau = 1 s on the -1/2 line through the -1/2 region,
    /// deg/sqrt(h); None where the curve has no such region.
    pub arw_dpsh: Option<f64>,
    /// The -1/2 region read, s.
    pub arw_region_s: Option<(f64, f64)>,
    /// The curve's minimum (among well-determined points), deg/h, and
    /// where.
    pub floor_dph: f64,
    pub floor_tau_s: f64,
    /// floor / 0.664, deg/h.
    pub bias_instability_dph: f64,
    /// Whether the curve rises significantly after the floor (a later
    /// point's interval wholly above the floor's).
    pub resolved: bool,
    /// The highest point after the floor (tau s, deg/h), where one is
    /// above it: a rise the intervals may or may not resolve.
    pub rise: Option<(f64, f64)>,
}

/// Least-squares slope of ln y on ln x over points i in `idx`.
fn slope(lx: &[f64], ly: &[f64], idx: &[usize]) -> Option<f64> {
    if idx.len() < 3 {
        return None;
    }
    let n = idx.len() as f64;
    let mx = idx.iter().map(|&i| lx[i]).sum::<f64>() / n;
    let my = idx.iter().map(|&i| ly[i]).sum::<f64>() / n;
    let sxx: f64 = idx.iter().map(|&i| (lx[i] - mx).powi(2)).sum();
    let sxy: f64 = idx.iter().map(|&i| (lx[i] - mx) * (ly[i] - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Reads the curve: `taus` s, the Allan deviation `adev` and its 95 %
/// interval `lo`..`hi`, all in deg/h.
pub fn read(taus: &[f64], adev: &[f64], lo: &[f64], hi: &[f64]) -> Readings {
    let n = taus.len();
    let lx: Vec<f64> = taus.iter().map(|t| t.ln()).collect();
    let ly: Vec<f64> = adev.iter().map(|v| v.max(f64::MIN_POSITIVE).ln()).collect();
    // Points determined well enough to read a slope from (95 % interval
    // within a factor 1.5).
    let good: Vec<bool> = (0..n)
        .map(|i| hi[i] / lo[i].max(f64::MIN_POSITIVE) < 1.5)
        .collect();
    let w = WINDOW_DECADES * std::f64::consts::LN_10;
    let local: Vec<Option<f64>> = (0..n)
        .map(|i| {
            if !good[i] {
                return None;
            }
            let idx: Vec<usize> = (0..n)
                .filter(|&k| good[k] && (lx[k] - lx[i]).abs() <= w)
                .collect();
            slope(&lx, &ly, &idx)
        })
        .collect();
    // Runs of points on the -1/2 slope.
    let mut runs: Vec<(usize, usize)> = vec![];
    let mut start: Option<usize> = None;
    for i in 0..=n {
        let on = i < n && local[i].is_some_and(|s| (s + 0.5).abs() <= SLOPE_TOLERANCE);
        match (on, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                runs.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
    }
    runs.retain(|&(a, b)| taus[b] / taus[a] >= MIN_SPAN);
    // The run nearest tau = 1 s (log distance; zero if it spans 1 s).
    let dist = |&(a, b): &(usize, usize)| {
        if lx[a] <= 0.0 && lx[b] >= 0.0 {
            0.0
        } else {
            lx[a].abs().min(lx[b].abs())
        }
    };
    let run = runs
        .iter()
        .min_by(|x, y| dist(x).total_cmp(&dist(y)))
        .copied();
    let arw_dpsh = run.map(|(a, b)| {
        let m = (a..=b).map(|i| ly[i] + 0.5 * lx[i]).sum::<f64>() / (b - a + 1) as f64;
        // deg/h at 1 s -> deg/sqrt(h): sigma(1 s) [deg/h] / 60.
        m.exp() / 60.0
    });
    let cand: Vec<usize> = {
        let c: Vec<usize> = (0..n)
            .filter(|&i| hi[i] / lo[i].max(f64::MIN_POSITIVE) < 3.0)
            .collect();
        if c.is_empty() {
            (0..n).collect()
        } else {
            c
        }
    };
    let imin = cand
        .iter()
        .copied()
        .min_by(|&a, &b| adev[a].total_cmp(&adev[b]))
        .unwrap_or(0);
    let floor = adev.get(imin).copied().unwrap_or(f64::NAN);
    let resolved = (imin + 1..n).any(|i| lo[i] > hi[imin]);
    let rise = (imin + 1..n)
        .filter(|&i| adev[i] > floor)
        .max_by(|&a, &b| adev[a].total_cmp(&adev[b]))
        .map(|i| (taus[i], adev[i]));
    Readings {
        rise,
        arw_dpsh,
        arw_region_s: run.map(|(a, b)| (taus[a], taus[b])),
        floor_dph: floor,
        floor_tau_s: taus.get(imin).copied().unwrap_or(f64::NAN),
        bias_instability_dph: floor / 0.664,
        resolved,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textbook_curve_is_read_as_the_formulas_say() {
        // sigma^2 = N^2/tau + (0.664 B)^2 + K^2 tau/3 with N = 0.1 deg/s/sqrt(s)... in
        // deg/h units: N = 6 deg/h sqrt(s) (0.1 deg/sqrt(h)), B = 1 deg/h,
        // K = 0.001 deg/h/sqrt(s); 1 % intervals.
        let taus: Vec<f64> = (0..75)
            .map(|i| 10f64.powf(-2.0 + i as f64 / 10.0))
            .collect();
        let (n, b, k) = (6.0f64, 1.0f64, 0.001f64);
        let adev: Vec<f64> = taus
            .iter()
            .map(|t| (n * n / t + (0.664 * b).powi(2) + k * k * t / 3.0).sqrt())
            .collect();
        let lo: Vec<f64> = adev.iter().map(|v| v * 0.99).collect();
        let hi: Vec<f64> = adev.iter().map(|v| v * 1.01).collect();
        let r = read(&taus, &adev, &lo, &hi);
        let arw = r.arw_dpsh.unwrap();
        // The region reaches where B adds: a little above 0.1.
        assert!((arw / 0.1 - 1.0).abs() < 0.03, "{arw}");
        let (a, z) = r.arw_region_s.unwrap();
        assert!(a <= 0.011 && z > 1.0, "{a} {z}");
        // The minimum of N^2/tau + 0.4409 B^2 + K^2 tau/3 lies at tau* =
        // sqrt(3) N/K; floor/0.664 overstates B while N still adds there.
        let tstar = 3f64.sqrt() * n / k;
        let want = (2.0 * n * k / 3f64.sqrt() + (0.664 * b).powi(2)).sqrt();
        assert!(
            (r.floor_dph / want - 1.0).abs() < 0.01,
            "{} {want}",
            r.floor_dph
        );
        assert!(
            (r.floor_tau_s / tstar).ln().abs() < 0.3,
            "{} {tstar}",
            r.floor_tau_s
        );
        assert!(r.bias_instability_dph > b);
        assert!(r.resolved);
        // Cut the curve at the floor: the minimum is its last point, the
        // floor an upper bound only.
        let m = taus.iter().position(|&t| t > tstar).unwrap();
        let r2 = read(&taus[..m], &adev[..m], &lo[..m], &hi[..m]);
        assert!(!r2.resolved);
    }
}
