//! The classic multi-point calibration (IEEE 952): each temperature
//! plateau is a least-squares line through its rate sequence (scale factor,
//! bias, asymmetry and nonlinearity), the table interpolates between the
//! plateaus; a knee is tested on the plateau points (BIC), its interval is
//! where the points cannot place it.

use super::families::{choose, Family, Scored};
use super::input::SfInput;
use super::residual::{noise_floor_ppm, window_rms_ppm, RESIDUAL_WINDOW_S};
use super::result::{Est, FitMethod, Interval, Segment, SfFit, SfFitError};
use super::tabulate::{firmware_error_ppm, Tabulation};
use super::warnings;
use crate::numerics::lsq::{wls, LsFit};
use crate::numerics::search::CHI2_1_95;
use gyro_coeffs::fog_scale_factor::{ScaleFactorTable, MAX_NODES};

/// Plateaus of a multi-point run: the rotating rows split where their
/// sensor temperatures, sorted, leave a gap over 3 degC, if every group
/// spans under 3 degC. None for a continuous run.
pub fn plateaus(inp: &SfInput, rot: &[usize]) -> Option<Vec<Vec<usize>>> {
    let mut idx = rot.to_vec();
    idx.sort_by(|&a, &b| inp.ts[a].total_cmp(&inp.ts[b]));
    let mut groups: Vec<Vec<usize>> = vec![];
    for &k in &idx {
        match groups.last_mut() {
            Some(g) if inp.ts[k] - inp.ts[*g.last().unwrap_or(&k)] <= 3.0 => g.push(k),
            _ => groups.push(vec![k]),
        }
    }
    let narrow = groups.iter().all(|g| {
        let (a, b) = (g[0], g[g.len() - 1]);
        inp.ts[b] - inp.ts[a] < 3.0
    });
    (groups.len() >= 2 && narrow).then(|| {
        groups
            .into_iter()
            .map(|mut g| {
                g.sort_unstable();
                g
            })
            .collect()
    })
}

/// One plateau of a multi-point run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Plateau {
    pub temp_c: f64,
    pub sf_ppm: Est,
    pub bias_dph: Est,
    pub asymmetry_ppm: Option<Est>,
    pub nonlinearity_ppm: Option<Est>,
}

/// The IEEE 952 asymmetry: y = b + K+ w+ + K- w-, with two magnitudes or
/// more; (K+ - K-) over their mean, ppm.
fn two_slope_fit(w: &[f64], y: &[f64]) -> Option<LsFit> {
    let cols = vec![
        w.iter().map(|&x| x.max(0.0)).collect(),
        w.iter().map(|&x| x.min(0.0)).collect(),
        vec![1.0; w.len()],
    ];
    wls(&cols, y, None)
}

fn asymmetry(g: &LsFit, n: f64) -> Est {
    let var = g.sse / (n - 3.0).max(1.0);
    let mean = 0.5 * (g.coef[0] + g.coef[1]);
    Est {
        value: (g.coef[0] - g.coef[1]) / mean * 1e6,
        se: g.se_of(&[1.0, -1.0, 0.0], var) / mean * 1e6,
    }
}

/// Nonlinearity (IEEE 952): the largest deviation of a rate point's mean
/// output from the least-squares line (`resid`, variance `var`) over the
/// full-scale output (scale factor `k`), ppm. Noise makes the largest
/// deviation read high by about its standard error.
fn nonlinearity(w: &[f64], resid: &[f64], var: f64, k: f64) -> Est {
    let mut pts: std::collections::BTreeMap<i64, (f64, f64)> = Default::default();
    for (i, &x) in w.iter().enumerate() {
        let e = pts.entry((x * 1e3).round() as i64).or_default();
        e.0 += resid[i];
        e.1 += 1.0;
    }
    let fs = w.iter().fold(0.0f64, |a, x| a.max(x.abs())) * k;
    let (dev, cnt) = pts
        .values()
        .map(|(s, c)| (s / c, *c))
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
        .unwrap_or((0.0, 1.0));
    Est {
        value: dev.abs() / fs * 1e6,
        se: (var / cnt).sqrt() / fs * 1e6,
    }
}

fn plateau_fit(inp: &SfInput, rows: &[usize]) -> Option<Plateau> {
    let w: Vec<f64> = rows.iter().map(|&k| inp.w[k]).collect();
    let y: Vec<f64> = rows.iter().map(|&k| inp.y[k]).collect();
    let n = rows.len() as f64;
    let both = w.iter().any(|&x| x > 0.0) && w.iter().any(|&x| x < 0.0);
    // y = b + K w (the bias only with both signs).
    let mut cols = vec![w.clone()];
    if both {
        cols.push(vec![1.0; w.len()]);
    }
    let f = wls(&cols, &y, None)?;
    let var = f.sse / (n - cols.len() as f64).max(1.0);
    let k = f.coef[0];
    let mags: std::collections::BTreeSet<u64> =
        w.iter().map(|x| (x.abs() * 1e3).round() as u64).collect();
    let two_slope = if both && mags.len() >= 2 {
        two_slope_fit(&w, &y)
    } else {
        None
    };
    // The nonlinearity about the two-slope line where the asymmetry is
    // measured, so it is not counted twice.
    let nonlinearity_ppm = (mags.len() >= 3).then(|| match &two_slope {
        Some(g) => nonlinearity(&w, &g.resid, g.sse / (n - 3.0).max(1.0), k),
        None => nonlinearity(&w, &f.resid, var, k),
    });
    let temp_c = rows.iter().map(|&k| inp.ts[k]).sum::<f64>() / n;
    Some(Plateau {
        temp_c,
        sf_ppm: Est {
            value: (k - 1.0) * 1e6,
            se: f.se(0, var) * 1e6,
        },
        bias_dph: if both {
            Est {
                value: f.coef[1] * 3600.0,
                se: f.se(1, var) * 3600.0,
            }
        } else {
            Est {
                value: 0.0,
                se: 0.0,
            }
        },
        asymmetry_ppm: two_slope.as_ref().map(|g| asymmetry(g, n)),
        nonlinearity_ppm,
    })
}

/// Chi-square of a hinge (or line, `knee` None) fit to plateau points.
fn plateau_chi2(pts: &[Plateau], knee: Option<f64>) -> f64 {
    let mut cols = vec![
        vec![1.0; pts.len()],
        pts.iter().map(|p| p.temp_c - 20.0).collect::<Vec<f64>>(),
    ];
    if let Some(k) = knee {
        cols.push(pts.iter().map(|p| (p.temp_c - k).max(0.0)).collect());
    }
    let y: Vec<f64> = pts.iter().map(|p| p.sf_ppm.value).collect();
    let wts: Vec<f64> = pts
        .iter()
        .map(|p| 1.0 / p.sf_ppm.se.max(1e-6).powi(2))
        .collect();
    wls(&cols, &y, Some(&wts)).map_or(f64::INFINITY, |f| f.sse)
}

/// The knee test on the plateau points (sorted by temperature): line
/// against hinge, BIC with the points' known standard errors (chi-square);
/// the hinge needs a spare point. Returns the BIC of each and the knee
/// where the hinge wins, its interval where the chi-square stays within
/// the 95 % threshold of its minimum.
fn plateau_knee(pts: &[Plateau]) -> (Vec<f64>, Vec<Interval>) {
    let np = pts.len();
    let n = np as f64;
    let chi0 = plateau_chi2(pts, None);
    let mut bic = vec![chi0 + 2.0 * n.ln()];
    let mut knees = vec![];
    if np >= 5 {
        let (lo, hi) = (pts[0].temp_c, pts[np - 1].temp_c);
        let grid: Vec<f64> = (0..=((hi - lo) / 0.1) as usize)
            .map(|i| lo + 0.5 + 0.1 * i as f64)
            .filter(|t| *t < hi - 0.5)
            .collect();
        let chis: Vec<f64> = grid.iter().map(|&t| plateau_chi2(pts, Some(t))).collect();
        if let Some(i) = (0..grid.len()).min_by(|&a, &b| chis[a].total_cmp(&chis[b])) {
            bic.push(chis[i] + 4.0 * n.ln());
            if bic[1] < bic[0] {
                let inside: Vec<f64> = grid
                    .iter()
                    .zip(&chis)
                    .filter(|(_, c)| **c - chis[i] <= CHI2_1_95)
                    .map(|(t, _)| *t)
                    .collect();
                let (a, b) = (inside[0], inside[inside.len() - 1]);
                knees.push(Interval {
                    value: 0.5 * (a + b),
                    lo: a,
                    hi: b,
                });
            }
        }
    }
    (bic, knees)
}

/// Segments between plateaus: independent points, so the standard errors
/// add in quadrature.
fn plateau_segments(pts: &[Plateau]) -> Vec<Segment> {
    pts.windows(2)
        .map(|w| {
            let h = w[1].temp_c - w[0].temp_c;
            let k_t = (w[1].sf_ppm.value - w[0].sf_ppm.value) * 1e-6 / h;
            let se_t = w[0].sf_ppm.se.hypot(w[1].sf_ppm.se) * 1e-6 / h;
            let k0m1 = w[0].sf_ppm.value * 1e-6 - k_t * w[0].temp_c;
            let t0 = w[0].temp_c;
            let se0 = ((w[0].sf_ppm.se * 1e-6 * (1.0 + t0 / h)).powi(2)
                + (w[1].sf_ppm.se * 1e-6 * t0 / h).powi(2))
            .sqrt();
            Segment {
                from_c: w[0].temp_c,
                to_c: w[1].temp_c,
                k0: 1.0 + k0m1,
                k_t,
                k0_se: se0,
                k_t_se: se_t,
                k0_ppm: k0m1 * 1e6,
                k_t_ppm_per_c: k_t * 1e6,
            }
        })
        .collect()
}

/// The residual over 60 s means, each plateau's rows about its own line,
/// ppm; its noise floor; and the number of rows used.
fn plateau_residual(inp: &SfInput, groups: &[Vec<usize>]) -> (Est, Est, usize) {
    let mut err = vec![0.0; inp.t.len()];
    let mut used = 0;
    for (g, p) in groups
        .iter()
        .zip(groups.iter().map(|g| plateau_fit(inp, g)))
    {
        let Some(p) = p else { continue };
        for &k in g {
            err[k] =
                inp.y[k] - inp.w[k] * (1.0 + p.sf_ppm.value * 1e-6) - p.bias_dph.value / 3600.0;
            used += 1;
        }
    }
    let mut w_rot = inp.w.clone();
    for (k, w) in w_rot.iter_mut().enumerate() {
        if !groups.iter().any(|g| g.binary_search(&k).is_ok()) {
            *w = 0.0;
        }
    }
    let (rms, rms_se, _) = window_rms_ppm(&inp.t, &w_rot, &err, RESIDUAL_WINDOW_S);
    (
        Est {
            value: rms,
            se: rms_se,
        },
        noise_floor_ppm(&inp.t, &w_rot, &err),
        used,
    )
}

/// Inverse-variance mean of one figure over the plateaus that have it.
fn pooled(pts: &[Plateau], f: fn(&Plateau) -> Option<Est>) -> Option<Est> {
    let v: Vec<Est> = pts.iter().filter_map(f).collect();
    (!v.is_empty()).then(|| {
        let wsum: f64 = v.iter().map(|e| 1.0 / e.se.max(1e-9).powi(2)).sum();
        Est {
            value: v
                .iter()
                .map(|e| e.value / e.se.max(1e-9).powi(2))
                .sum::<f64>()
                / wsum,
            se: wsum.sqrt().recip(),
        }
    })
}

/// The fit of a multi-point run (plateaus from [`plateaus`]).
pub fn fit_multipoint(
    inp: &SfInput,
    groups: &[Vec<usize>],
) -> Result<(SfFit, Vec<Plateau>), SfFitError> {
    if groups.len() > MAX_NODES {
        return Err(SfFitError::TooManyPlateaus(groups.len()));
    }
    let mut pts: Vec<Plateau> = vec![];
    for g in groups {
        pts.push(plateau_fit(inp, g).ok_or(SfFitError::Plateau)?);
    }
    pts.sort_by(|a, b| a.temp_c.total_cmp(&b.temp_c));
    let np = pts.len();
    let (bic, knees) = plateau_knee(&pts);
    let nodes: Vec<f64> = pts.iter().map(|p| p.temp_c).collect();
    let sf: Vec<f64> = pts.iter().map(|p| p.sf_ppm.value).collect();
    let bias: Vec<f64> = pts.iter().map(|p| p.bias_dph.value).collect();
    let table = ScaleFactorTable::from_nodes(&nodes, &sf, &bias, 0.0);
    let (residual_ppm, noise_floor, used) = plateau_residual(inp, groups);
    // The knee test as the families' criterion: the line, or the hinge.
    let mut scored: Vec<Scored> = bic
        .iter()
        .enumerate()
        .map(|(k, &b)| Scored {
            model: Family::of(1, k),
            poly_degree: 1,
            knees: k,
            knees_c: knees.iter().take(k).map(|i| i.value).collect(),
            sensor_lag_s: 0.0,
            bic: b,
            delta_bic: 0.0,
        })
        .collect();
    let (_, families, margin) = choose(&mut scored);
    let range = [nodes[0], nodes[np - 1]];
    let warns = [
        warnings::span(range),
        warnings::residual(residual_ppm, noise_floor),
    ]
    .into_iter()
    .flatten()
    .collect();
    let notes = vec![
        "multi-point: the table interpolates linearly between the plateaus; a knee between two \
         plateaus is only bracketed"
            .to_owned(),
        "sensor lag not measurable on soaked plateaus: the table uses 0".to_owned(),
    ];
    Ok((
        SfFit {
            method: FitMethod::MultiPoint,
            // The table interpolates linearly between the plateaus.
            model: Family::Knees,
            degree: 0,
            knees,
            polynomial: None,
            segments: plateau_segments(&pts),
            table,
            sensor_lag_s: None,
            bias: None,
            asymmetry_ppm: pooled(&pts, |p| p.asymmetry_ppm),
            // Nonlinearity: the worst plateau.
            nonlinearity_ppm: pts
                .iter()
                .filter_map(|p| p.nonlinearity_ppm)
                .max_by(|a, b| a.value.total_cmp(&b.value)),
            bic,
            criteria: scored,
            families,
            criterion_margin: margin,
            noise_inflation: 1.0,
            residual_ppm,
            noise_floor_ppm: noise_floor,
            tabulation: Tabulation {
                nodes: table.n,
                spacing_c: nodes.windows(2).map(|w| w[1] - w[0]).collect(),
                tolerance_ppm: 0.0,
                max_error_ppm: firmware_error_ppm(&table, |t| table.eval(t).0),
            },
            range_c: range,
            rows_used: used,
            duration_s: inp.t.last().copied().unwrap_or(0.0)
                - inp.t.first().copied().unwrap_or(0.0),
            notes,
            warnings: warns,
            curve: None,
        },
        pts,
    ))
}
