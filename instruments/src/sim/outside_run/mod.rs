//! A fourth run generator, for discovery beyond the library (issue 32),
//! written apart from the project's (model_run.rs), the second
//! (heldout_run/) and the third (third_run/): its own random numbers
//! (rng.rs: PCG64, inverse-CDF normals), its own noise (noise.rs: flicker
//! as a sum of relaxation processes, random walk, Markov, RLG counts), its
//! own profiles (profiles.rs: a rate ladder, FOG chambers static and
//! turning, an RLG chamber and bench, sinusoidal swings with a noisy
//! acceleration column, a room) and thermal networks (thermal.rs: eased
//! air programs, RK4), and its own hidden terms (hidden.rs), each at 4 .. 9
//! times the run's white 1 s floor and computed from the true state while
//! the run file carries lagged, noisy, quantised sensors.
//!
//! Every case is two runs of the same gyro, A and B: the same noise
//! figures, hidden term and parameters; their own seeds, profile draws and
//! turn-on bias. A model found on A must predict B up to a bias.

pub mod hidden;
pub mod noise;
pub mod profiles;
pub mod rng;
pub mod thermal;

use gyro_lab_core::model::gyro_kind::GyroKind;
use hidden::Hidden;
use noise::{count, rate_noise, NoiseSpec};
use profiles::{build, Profile, State};
use rng::Rng;
use std::collections::BTreeMap;

/// What a case tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Category {
    /// A physical term outside the library.
    Physical,
    /// A one-off event outside the library.
    Event,
    /// Nothing hidden; coloured noise.
    Null,
    /// One library effect hidden.
    Library,
}

impl Category {
    pub fn name(self) -> &'static str {
        match self {
            Category::Physical => "physical",
            Category::Event => "event",
            Category::Null => "null",
            Category::Library => "library",
        }
    }
}

/// One run: the file's columns, the hidden term's contribution per row
/// and the noise's realised figures.
pub struct OutsideRun {
    pub t: Vec<f64>,
    pub w: Vec<f64>,
    pub rate: Vec<f64>,
    pub temp: Option<Vec<f64>>,
    pub mono: Option<(Vec<f64>, Vec<f64>)>,
    pub case: Option<Vec<f64>>,
    pub acc: Option<Vec<f64>>,
    /// The hidden term (or library effect) per row, deg/h.
    pub hidden_dph: Vec<f64>,
    pub bias_dph: f64,
    /// The white floor of 1 s means the terms are scaled against, deg/h
    /// (angle random walk and RLG counts, from the noise's figures).
    pub floor_dph: f64,
    /// Realised RMS of 1 s means, deg/h: the white part alone; all the
    /// noise (coloured and counts too, about its mean: measured minus the
    /// true output); the hidden term (about its mean).
    pub white_1s_dph: f64,
    pub noise_1s_dph: f64,
    pub hidden_1s_dph: f64,
    pub profile: String,
    /// The true state (for tests).
    pub state: State,
}

/// A case: two runs of one gyro with one hidden term.
pub struct OutsideCase {
    pub name: String,
    pub kind: &'static str,
    pub category: Category,
    pub gyro: GyroKind,
    pub hidden: Hidden,
    /// Names a right answer holds ("term" for a term outside the library),
    /// and names it may hold besides (a bias always where one is hidden;
    /// library effects that are an exact part of the term's expansion,
    /// e.g. bias_temperature in (T - t0)^2 with t0 != 20).
    pub expect: Vec<&'static str>,
    pub allow: Vec<&'static str>,
    /// The hidden term's coefficient and shape parameters.
    pub parameters: BTreeMap<String, f64>,
    /// The drawn multiple of the floor on run A.
    pub multiple: f64,
    pub noise: NoiseSpec,
    pub a: OutsideRun,
    pub b: OutsideRun,
}

/// 1 s window means of `x` over rows `t` (windows [k, k+1) s).
pub fn means_1s(t: &[f64], x: &[f64]) -> Vec<f64> {
    let mut out = vec![];
    let (mut key, mut s, mut c) = (i64::MIN, 0.0, 0.0);
    for (ti, xi) in t.iter().zip(x) {
        let k = ti.floor() as i64;
        if k != key && c > 0.0 {
            out.push(s / c);
            (s, c) = (0.0, 0.0);
        }
        key = k;
        s += xi;
        c += 1.0;
    }
    if c > 0.0 {
        out.push(s / c);
    }
    out
}

/// RMS of `v` about its mean.
pub fn rms_about_mean(v: &[f64]) -> f64 {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt()
}

/// A case's recipe.
struct Recipe {
    kind: &'static str,
    category: Category,
    profile: Profile,
    hidden: Hidden,
    allow: &'static [&'static str],
    /// Extra coloured noise for nulls, as multiples of the floor: flicker
    /// (deg/h), random walk (deg/h/sqrt(h)), Markov (deg/h).
    coloured: (f64, f64, f64),
}

const fn recipe(
    kind: &'static str,
    category: Category,
    profile: Profile,
    hidden: Hidden,
    allow: &'static [&'static str],
) -> Recipe {
    Recipe {
        kind,
        category,
        profile,
        hidden,
        allow,
        coloured: (0.0, 0.0, 0.0),
    }
}

/// The kinds, in their order (shape parameters drawn per case).
fn recipes() -> Vec<Recipe> {
    use Category::*;
    use Profile::*;
    let t0 = Hidden::BiasTempQuadratic { t0_c: 0.0 };
    let sft0 = Hidden::SfTempQuadratic { t0_c: 0.0 };
    let mut v = vec![
        recipe("w2", Physical, Table, Hidden::W2, &[]),
        recipe("w3", Physical, Table, Hidden::W3, &[]),
        recipe("w_abs_w", Physical, Table, Hidden::WAbsW, &[]),
        recipe(
            "bias_temp_quadratic",
            Physical,
            ChamberStatic,
            t0,
            &["bias_temperature"],
        ),
        recipe(
            "sf_temp_quadratic",
            Physical,
            ChamberTurning,
            sft0,
            &["scale_factor_error", "scale_factor_temperature"],
        ),
        recipe(
            "coil_curvature",
            Physical,
            ChamberStatic,
            Hidden::CoilCurvature,
            &[],
        ),
        recipe(
            "sf_temp_rate",
            Physical,
            ChamberTurning,
            Hidden::SfTempRate,
            &[],
        ),
        recipe(
            "case_minus_mono",
            Physical,
            RlgChamber,
            Hidden::CaseMinusMono,
            &["case_temperature"],
        ),
        recipe("case_rate", Physical, RlgChamber, Hidden::CaseRate, &[]),
        recipe("abs_acc", Physical, Swings, Hidden::AbsAcc, &[]),
        recipe(
            "step",
            Event,
            RlgRoom,
            Hidden::Step {
                t0_s: 0.0,
                rise_s: 0.0,
            },
            &[],
        ),
        recipe(
            "periodic",
            Event,
            Room,
            Hidden::Periodic {
                period_s: 0.0,
                phase_rad: 0.0,
            },
            &[],
        ),
        recipe("ageing_ramp", Event, Room, Hidden::Ramp { t1_s: 0.0 }, &[]),
        recipe(
            "settling",
            Event,
            Table,
            Hidden::Settling {
                t1_s: 0.0,
                tau_s: 0.0,
            },
            &[],
        ),
        recipe("null_flicker", Null, Room, Hidden::None, &[]),
        recipe("null_random_walk", Null, Table, Hidden::None, &[]),
        recipe("null_markov", Null, RlgChamber, Hidden::None, &[]),
        recipe("null_mixed", Null, ChamberStatic, Hidden::None, &[]),
        recipe(
            "lib_scale_factor_error",
            Library,
            Table,
            Hidden::ScaleFactorError,
            &[],
        ),
        recipe(
            "lib_bias_temperature",
            Library,
            ChamberStatic,
            Hidden::BiasTemperature,
            &[],
        ),
        recipe(
            "lib_case_temperature",
            Library,
            RlgChamber,
            Hidden::CaseTemperature,
            &[],
        ),
    ];
    for r in &mut v {
        r.coloured = match r.kind {
            "null_flicker" => (0.25, 0.0, 0.0),
            "null_random_walk" => (0.0, 0.3, 0.0),
            "null_markov" => (0.0, 0.0, 0.4),
            "null_mixed" => (0.12, 0.12, 0.2),
            _ => (0.0, 0.0, 0.0),
        };
    }
    v
}

/// Draws the shape parameters a recipe leaves open, for a record of `span` s.
fn draw_shape(h: Hidden, span: f64, rng: &mut Rng) -> Hidden {
    let t0 = |rng: &mut Rng| {
        // A reference temperature well away from the library's 20 degC.
        if rng.index(2) == 0 {
            rng.uniform(28.0, 42.0)
        } else {
            rng.uniform(-5.0, 10.0)
        }
    };
    match h {
        Hidden::BiasTempQuadratic { .. } => Hidden::BiasTempQuadratic { t0_c: t0(rng) },
        Hidden::SfTempQuadratic { .. } => Hidden::SfTempQuadratic { t0_c: t0(rng) },
        Hidden::Step { .. } => Hidden::Step {
            t0_s: span * rng.uniform(0.3, 0.7),
            rise_s: rng.uniform(1.0, 4.0),
        },
        Hidden::Periodic { .. } => Hidden::Periodic {
            period_s: rng.uniform(1200.0, 3600.0),
            phase_rad: rng.uniform(0.0, 2.0 * std::f64::consts::PI),
        },
        Hidden::Ramp { .. } => Hidden::Ramp {
            t1_s: span * rng.uniform(0.2, 0.6),
        },
        Hidden::Settling { .. } => Hidden::Settling {
            t1_s: span * rng.uniform(0.1, 0.4),
            tau_s: rng.uniform(600.0, 3600.0),
        },
        h => h,
    }
}

/// The gyro's noise: a navigation FOG or RLG, with small flicker, and a
/// null's coloured noise on top.
fn draw_noise(rlg: bool, coloured: (f64, f64, f64), rng: &mut Rng) -> NoiseSpec {
    let mut n = if rlg {
        NoiseSpec {
            arw_dpsh: rng.uniform(0.0015, 0.004),
            count_arcsec: rng.uniform(0.3, 1.0),
            ..Default::default()
        }
    } else {
        NoiseSpec {
            arw_dpsh: rng.uniform(0.002, 0.006),
            ..Default::default()
        }
    };
    let f = n.floor_1s_dph();
    n.flicker_dph = f * rng.uniform(0.02, 0.05);
    let (fl, rw, mk) = coloured;
    if fl > 0.0 {
        n.flicker_dph = f * fl * rng.uniform(0.6, 1.0);
    }
    n.rrw_dphsh = f * rw * rng.uniform(0.6, 1.0);
    if mk > 0.0 {
        n.markov_dph = f * mk * rng.uniform(0.6, 1.0);
        n.markov_s = rng.uniform(300.0, 3000.0);
    }
    n
}

/// A run on the true state `st` with `hidden` at coefficient `k`, its
/// noise from `rng`.
fn render(
    st: State,
    hidden: Hidden,
    k: f64,
    nz: &NoiseSpec,
    bias_dph: f64,
    rng: &mut Rng,
) -> OutsideRun {
    let n = st.t.len();
    let hidden_dph: Vec<f64> = hidden.shape(&st).iter().map(|s| k * s).collect();
    let (noise, white) = rate_noise(nz, n, st.dt, rng);
    let truth: Vec<f64> = (0..n)
        .map(|i| st.w[i] + (bias_dph + hidden_dph[i]) / 3600.0)
        .collect();
    let analog: Vec<f64> = truth.iter().zip(&noise).map(|(a, b)| a + b).collect();
    let rate = count(&analog, st.dt, nz.count_arcsec, rng);
    let realised: Vec<f64> = rate
        .iter()
        .zip(&truth)
        .map(|(r, x)| (r - x) * 3600.0)
        .collect();
    let white_dph: Vec<f64> = white.iter().map(|x| x * 3600.0).collect();
    let rms = |x: &[f64]| rms_about_mean(&means_1s(&st.t, x));
    OutsideRun {
        t: st.t.clone(),
        w: st.w.clone(),
        temp: st.coil_sensor.clone(),
        mono: st.mono_sensors.clone(),
        case: st.case_sensor.clone(),
        acc: st.acc_column.clone(),
        floor_dph: nz.floor_1s_dph(),
        white_1s_dph: rms(&white_dph),
        noise_1s_dph: rms(&realised),
        hidden_1s_dph: rms(&hidden_dph),
        hidden_dph,
        bias_dph,
        rate,
        profile: st.describe.clone(),
        state: st,
    }
}

/// One case of recipe `r` from `seed`.
fn make(r: &Recipe, seed: u64, replicate: usize) -> OutsideCase {
    let mut g = Rng::new(seed, 1);
    let nz = draw_noise(r.profile.is_rlg(), r.coloured, &mut g);
    let floor = nz.floor_1s_dph();
    let (span, _) = r.profile.size();
    let hidden = draw_shape(r.hidden, span, &mut g);
    let multiple = g.uniform(4.0, 9.0);
    let sign = if g.index(2) == 0 { 1.0 } else { -1.0 };
    let null = r.category == Category::Null;
    let (bias_a, bias_b) = if null {
        (0.0, 0.0)
    } else {
        let a = g.either_sign(1.0, 5.0) * floor;
        (a, a + g.either_sign(0.5, 3.0) * floor)
    };
    // The shape on A sets the coefficient; B keeps it.
    let mut ra = Rng::new(seed, 2);
    let mut rb = Rng::new(seed, 3);
    let sa = build(r.profile, &mut ra);
    let sb = build(r.profile, &mut rb);
    let k = if null {
        0.0
    } else {
        let s = rms_about_mean(&means_1s(&sa.t, &hidden.shape(&sa)));
        sign * multiple * floor / s.max(1e-300)
    };
    let a = render(sa, hidden, k, &nz, bias_a, &mut ra);
    let b = render(sb, hidden, k, &nz, bias_b, &mut rb);
    let mut parameters = hidden.shape_parameters();
    if !null {
        parameters.insert(hidden.coefficient().to_owned(), k);
    }
    let expect: Vec<&'static str> = match hidden {
        Hidden::None => vec![],
        Hidden::ScaleFactorError => vec!["scale_factor_error"],
        Hidden::BiasTemperature => vec!["bias_temperature"],
        Hidden::CaseTemperature => vec!["case_temperature"],
        _ => vec!["term"],
    };
    let mut allow: Vec<&'static str> = r.allow.to_vec();
    if !null {
        allow.insert(0, "bias");
    }
    OutsideCase {
        name: format!("{}-{}", r.kind, replicate + 1),
        kind: r.kind,
        category: r.category,
        gyro: if r.profile.is_rlg() {
            GyroKind::Rlg
        } else {
            GyroKind::Fog
        },
        hidden,
        expect,
        allow,
        parameters,
        multiple: if null { 0.0 } else { multiple },
        noise: nz,
        a,
        b,
    }
}

/// The kinds' names, in the set's order.
pub fn kinds() -> Vec<&'static str> {
    recipes().iter().map(|r| r.kind).collect()
}

/// The set: `per_kind` cases of each kind (21 kinds), built on all cores.
pub fn outside_set(seed: u64, per_kind: usize) -> Vec<OutsideCase> {
    let rs = recipes();
    let jobs: Vec<(usize, usize)> = (0..per_kind)
        .flat_map(|rep| (0..rs.len()).map(move |i| (rep, i)))
        .collect();
    let threads = std::thread::available_parallelism().map_or(1, |p| p.get());
    let mut out: Vec<Option<OutsideCase>> = (0..jobs.len()).map(|_| None).collect();
    std::thread::scope(|sc| {
        let hs: Vec<_> = (0..threads)
            .map(|w| {
                let (rs, jobs) = (&rs, &jobs);
                sc.spawn(move || {
                    (w..jobs.len())
                        .step_by(threads)
                        .map(|j| {
                            let (rep, i) = jobs[j];
                            let s = seed
                                .wrapping_mul(0x9FB2_1C65_1E98_DF25)
                                .wrapping_add((rep * 1000 + i) as u64 * 0x2545_F491);
                            (j, make(&rs[i], s, rep))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in hs {
            for (j, c) in h.join().unwrap_or_default() {
                out[j] = Some(c);
            }
        }
    });
    out.into_iter().flatten().collect()
}

/// One case by kind name (tests).
pub fn one_case(kind: &str, seed: u64) -> Option<OutsideCase> {
    recipes()
        .iter()
        .find(|r| r.kind == kind)
        .map(|r| make(r, seed, 0))
}
