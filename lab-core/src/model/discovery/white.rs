//! The white noise of a series from its neighbours' differences: the
//! level the first pass of discovery whitens with, the spikes and steps
//! are judged against, and the noise floor is read from (noise_floor.rs,
//! noise_model.rs, transients.rs).

/// The ratio of the lower to the upper quartile of the squared neighbour
/// differences of white Gaussian noise (chi-square(1)'s 0.1015/1.3233),
/// and the band around it a series is read as such in.
const QUARTILE_RATIO_BAND: (f64, f64) = (0.02, 0.4);
/// ... and the most its 95 % quantile may exceed its median by (8.4 for
/// a Gaussian; a few steps in a rate table's residual stay far below).
const TAIL_RATIO_MAX: f64 = 100.0;

/// The variance of one value of a series of white noise from its
/// neighbours' squared differences `d2`: robustly, half their median over
/// chi-square(1)'s (slow effects and a few steps are differenced away);
/// but where the differences are not spread as a Gaussian's (their lower
/// to upper quartile ratio, 0.077 for one, below 0.02 or above 0.4, or
/// their 95 % quantile a hundred medians out: an RLG's angle counts or a
/// MEMS gyro's word, the output quantised as coarsely as its noise, its
/// differences clustered at zero and one count whatever smooth fit was
/// taken off) the median is no measure (it reads nearly zero, or one
/// count) and the mean of the squares is taken, its
/// largest 1 % left out, over the share of a Gaussian's mean below its
/// 99 % quantile (P(chi2_3 < 6.635)/0.99): the quantisation is part of the
/// floor. None for fewer than two.
pub fn white_var_of_diffs(d2: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = d2.iter().copied().filter(|x| x.is_finite()).collect();
    if v.len() < 2 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let (q25, q50, q75, q95) = (q(0.25), q(0.5), q(0.75), q(0.95));
    let gaussian = q75 > 0.0 && {
        let r = q25 / q75;
        (QUARTILE_RATIO_BAND.0..=QUARTILE_RATIO_BAND.1).contains(&r) && q95 < TAIL_RATIO_MAX * q50
    };
    if gaussian {
        return Some(v[v.len() / 2] / (2.0 * 0.454_936));
    }
    let kept = &v[..((v.len() as f64 * 0.99).ceil() as usize).max(1)];
    let ms = kept.iter().sum::<f64>() / kept.len() as f64;
    Some(ms / (2.0 * 0.915_508 / 0.99))
}
