//! A mechanically dithered ring laser gyro (physics.md 2.1 and 2.4,
//! docs/rlg.md): the lock-in equation driven by the input rate plus the
//! dither, integrated finely through each crossing of the lock-in band and
//! analytically between crossings. It gives what the board sees: the
//! quadrature counter, the pickoff's zero crossings (the counter latched
//! there, the time, the direction) and the photodiode pair sampled just
//! after each latch; and the truth (the counts without the dither).
//!
//! Units: angles in degrees, time in s, `K_fr` = counts/4 fringes per degree.
//!
//! **Dither motion.** The block's dither angle (what the pickoff measures)
//! is `theta_d = -A(t) cos(Phi)`, `Phi = n pi` at the n-th turnaround. On
//! the half cycle from turnaround n to n+1 (length `h = 1/(2 f)`, fraction
//! `s`) the amplitude goes from `A_n` to `A_{n+1}` as
//! `A_n + (A_{n+1} - A_n)(1 - cos(pi s))/2`, so that
//! `theta_d = -sign (abar cos(pi s) - d cos^2(pi s)/2)` (abar the mean, d
//! the change of the two amplitudes): the rate is zero at each turnaround,
//! its slope there `(pi/h)^2 A_n`, and the angle is zero at `s = 1/2`
//! whatever the amplitudes (the pickoff's zero crossing).
//! `A_n = A (1 + noise z_n)`, `z_n` standard normal drawn at each
//! turnaround (the drive's random amplitude, which makes the fringe phase
//! at each crossing random); `A = Omega_d/(2 pi f_d)` is held (the drive
//! loop holds the pickoff's amplitude) while the frequency drifts slowly
//! with temperature: `f = f_d (1 + drift sin(2 pi t / period))`, held over
//! each half cycle.
//!
//! **Lock-in equation**, in fringes `F` (counts = floor(4 F)):
//! `dF/dt = K_fr (Omega + theta_d') - K_fr Omega_L sin(2 pi F + beta)`.
//! With `F = F_0 + K_fr (Theta + theta_d) + E` (Theta the input angle) the
//! lock-in error obeys `dE/dt = -K_fr Omega_L sin(2 pi F + beta)`.
//! - Where `|Omega_I| < W` (the crossing windows) E is integrated by RK4
//!   in steps of a fraction of a radian of fringe phase (and of the Fresnel
//!   time), the dither angle as a 9th-order Taylor polynomial over pieces
//!   of at most 0.19 half cycle (truncation below 1e-8);
//! - elsewhere the phase turns fast and the averaged equation holds. With
//!   `u = 2 pi F + beta`, `w = 2 pi K_fr Omega_I`, `a = 2 pi K_fr Omega_L`,
//!   `u = v + (a/w) cos v` gives `dv/dt = w - a^2/(2w)` plus terms
//!   oscillating with v, of order `a^2/w` and `a w'/w^2`, whose integrals
//!   are ripples of second order: the mean error drifts by
//!   `-K_fr Omega_L^2 / (2 Omega_I)` (Gauss-Legendre over the segment; the
//!   pulling that makes the beat `K sqrt(Omega_I^2 - Omega_L^2)`) and the
//!   ripple `(Omega_L/Omega_I) cos(v)/(2 pi)` is added where F is read.
//!   `W = max(C1 sqrt(Omega_dot/(2 pi K_fr)), C2 Omega_L)` puts the window
//!   edges where `w'/w^2 <= 1/C1^2` and `a/w <= 1/C2`.
//!
//! Checked against a brute-force RK4 of the plain equation over whole
//! records ([`BruteForce`], host-tests `rlg_dither`).

use core::f64::consts::PI;
use core::marker::PhantomData;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal, StandardUniform};
use rand_xoshiro::Xoshiro256PlusPlus;

mod brute_force;
mod motion;
mod trig;
mod windows;

pub use brute_force::BruteForce;
pub use motion::{DitherMotion, Half};
use trig::{frac, sin_cos_in, sin_small};
use windows::{find_windows, Windows};

/// The photodiode pair as the board's ADCs read it (codes): `A = offset +
/// amplitude sin(2 pi F)`, `B = offset + amplitude (1 + gain error)
/// cos(2 pi F + quadrature error)`, white noise, rounded and clipped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photodiodes {
    pub bits: u32,
    pub offset: [f64; 2],
    pub amplitude: f64,
    pub gain_error: f64,
    pub quadrature_error_rad: f64,
    pub noise_rms: f64,
}

impl Default for Photodiodes {
    /// 12-bit ADCs, 1 % gain mismatch, 0.6 degree of quadrature error,
    /// offsets 0.5 % of full scale off mid-scale, 2 codes of noise.
    fn default() -> Self {
        Self {
            bits: 12,
            offset: [2048.0 + 20.0, 2048.0 - 15.0],
            amplitude: 1600.0,
            gain_error: 0.01,
            quadrature_error_rad: 0.01,
            noise_rms: 2.0,
        }
    }
}

/// How finely the crossings are integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// Window edge at `w'/w^2 = 1/c1^2`.
    pub c1: f64,
    /// Window edge at `a/w = 1/c2`.
    pub c2: f64,
    /// RK4 step, radians of fringe phase.
    pub step_rad: f64,
    /// Sines and cosines outside the RK4 (window edges, the averaged
    /// drift, the ripple, the pieces' Taylor coefficients) in the inner
    /// loops' float by a polynomial, instead of libm's in f64: on the
    /// Cortex-M4 libm's sin and sinf both work in soft-float f64 (2000 to
    /// 4000 instructions a pair), which made the window search alone cost
    /// a million instructions per half cycle.
    pub fast_trig: bool,
}

impl Accuracy {
    /// The host's (against the brute force: 2e-4 of a crossing's error).
    pub const HOST: Accuracy = Accuracy {
        c1: 7.0,
        c2: 50.0,
        step_rad: 0.8,
        fast_trig: false,
    };
    /// Cheaper: f32 inside the windows and the polynomial sine, what a
    /// simulation on the Cortex-M4 needs (checked against the brute force
    /// by host-tests `rlg_dither`; the QEMU board now plays back a host
    /// recording instead).
    pub const QEMU: Accuracy = Accuracy {
        c1: 5.0,
        c2: 30.0,
        step_rad: 0.8,
        fast_trig: true,
    };
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DitherParams {
    /// Counts per degree (pulses per degree x 4 quadrature edges).
    pub counts_per_deg: f64,
    /// Lock-in rate Omega_L, deg/s, and the constant phase beta, rad.
    pub lock_in_dps: f64,
    pub beta_rad: f64,
    /// Peak dither rate Omega_d, deg/s, at the nominal frequency f_d, Hz.
    pub dither_dps: f64,
    pub dither_hz: f64,
    /// RMS of the dither amplitude at each turnaround, relative.
    pub noise_frac: f64,
    /// Slow drift of f_d (temperature): peak, relative, and period, s.
    pub fd_drift_frac: f64,
    pub fd_drift_period_s: f64,
    /// The pickoff comparator's delay: the counter is latched this long
    /// after the dither angle's zero crossing, s.
    pub pickoff_delay_s: f64,
    /// The photodiodes are sampled this long after the latch, s.
    pub adc_delay_s: f64,
    pub photodiodes: Photodiodes,
    pub accuracy: Accuracy,
    pub seed: u64,
}

impl Default for DitherParams {
    fn default() -> Self {
        Self {
            counts_per_deg: 8000.0,
            lock_in_dps: 0.05,
            beta_rad: 0.0,
            dither_dps: 150.0,
            dither_hz: 400.0,
            noise_frac: 0.05,
            fd_drift_frac: 0.0,
            fd_drift_period_s: 600.0,
            pickoff_delay_s: 200e-9,
            adc_delay_s: 250e-9,
            photodiodes: Photodiodes::default(),
            accuracy: Accuracy::HOST,
            seed: 1,
        }
    }
}

impl DitherParams {
    /// Fringes per degree.
    pub fn fringes_per_deg(&self) -> f64 {
        self.counts_per_deg / 4.0
    }
    /// Dither angle amplitude A, deg.
    pub fn amplitude_deg(&self) -> f64 {
        self.dither_dps / (2.0 * PI * self.dither_hz)
    }
    /// Rate slope at a turnaround, deg/s^2.
    pub fn omega_dot(&self) -> f64 {
        2.0 * PI * self.dither_hz * self.dither_dps
    }
    /// Killpatrick's random walk `Omega_L/sqrt(2 pi K Omega_d)`, K in
    /// fringes per unit angle (physics.md 2.4), deg/sqrt(s).
    pub fn killpatrick_arw_dps_rts(&self) -> f64 {
        self.lock_in_dps / (2.0 * PI * self.fringes_per_deg() * self.dither_dps).sqrt()
    }
    /// RMS of the fringe phase at a turnaround from the amplitude noise, rad.
    pub fn crossing_phase_rms_rad(&self) -> f64 {
        2.0 * PI * self.fringes_per_deg() * self.amplitude_deg() * self.noise_frac
    }
}

/// A pickoff zero crossing as the board latches it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Latch {
    /// When the counter was latched, s.
    pub t_s: f64,
    /// The encoder timer's latched count (16 bits), and the whole counts
    /// since start it stands for.
    pub counter: u16,
    pub counts: i64,
    /// The dither angle was rising through zero.
    pub rising: bool,
    /// Photodiode ADC codes `[A, B]` (A ~ sin, B ~ cos of the fringe
    /// phase), sampled `adc_delay_s` after the latch.
    pub photodiodes: [u16; 2],
    /// Truth at the latch: the counts without the dither (lock-in error
    /// included), continuous.
    pub truth_counts: f64,
}

/// The state at the end of an [`DitheredRlg::advance`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reading {
    pub t_s: f64,
    /// The encoder timer's counter, and the whole counts since start.
    pub counter: u16,
    pub counts: i64,
    /// The counts without the dither (lock-in error included), continuous.
    pub truth_counts: f64,
    /// The dither's part of the counts, continuous.
    pub dither_counts: f64,
    /// The lock-in error alone, counts.
    pub lockin_counts: f64,
}

/// Gauss-Legendre, 8 nodes on [-1, 1].
const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Longest fine piece, half-cycle fraction (pi times it: 0.6 rad, where the
/// 9th-order Taylor polynomial of the dither angle is exact to 1e-9).
const MAX_PIECE: f64 = 0.19;
const TAYLOR: usize = 10;

/// The dithered RLG; `F` is the float of the inner loops (f64 on the host,
/// f32 under QEMU), the bookkeeping is f64. Time is kept as the current
/// half cycle's start and the time since it (`x`): at hundreds of seconds
/// a global time's rounding would be a thousand times a window's fine edge.
pub struct DitheredRlg<F = f64> {
    pub p: DitherParams,
    k_fr: f64,
    kappa: f64,
    w_rate: f64,
    w_fresnel: f64,
    motion: DitherMotion,
    cur: Half,
    latch_done: bool,
    /// Fine intervals of `cur` for the rate they were found at.
    windows: Windows,
    /// Time since `cur.t0`, s.
    x: f64,
    /// K_fr times the input angle, fringes, at `t_anchor`, and its rate
    /// (fringes/s) over the present `advance`; the initial fringe fraction.
    psi_anchor: f64,
    t_anchor: f64,
    kr: f64,
    f0: f64,
    /// Lock-in error, fringes: the actual value inside a window, the mean
    /// (ripple removed) outside.
    e: f64,
    fine: bool,
    pd_rng: Xoshiro256PlusPlus,
    _f: PhantomData<F>,
}

impl<F: Float> DitheredRlg<F> {
    pub fn new(p: DitherParams) -> Self {
        let k_fr = p.fringes_per_deg();
        let motion = DitherMotion::new(&p);
        let mut pd_rng = Xoshiro256PlusPlus::seed_from_u64(p.seed ^ 0x5EED_F00D_CAFE);
        let f0: f64 = StandardUniform.sample(&mut pd_rng);
        // Omega_dot at the largest amplitude the noise draws (4 sigma).
        let od = p.omega_dot() * (1.0 + 4.0 * p.noise_frac) * (1.0 + p.fd_drift_frac).powi(2);
        let w_rate =
            (p.accuracy.c1 * (od / (2.0 * PI * k_fr)).sqrt()).max(p.accuracy.c2 * p.lock_in_dps);
        let cur = motion.current();
        Self {
            p,
            k_fr,
            kappa: k_fr * p.lock_in_dps,
            w_rate,
            w_fresnel: (2.0 * PI * k_fr * od).sqrt(),
            x: -cur.t0,
            cur,
            motion,
            latch_done: false,
            windows: Windows::default(),
            psi_anchor: 0.0,
            t_anchor: 0.0,
            kr: 0.0,
            f0,
            // Starts with the actual error zero (as the brute force does).
            e: 0.0,
            fine: true,
            pd_rng,
            _f: PhantomData,
        }
    }

    /// Time, s.
    pub fn time(&self) -> f64 {
        self.cur.t0 + self.x
    }

    /// Window half-width in rate, deg/s.
    pub fn window_dps(&self) -> f64 {
        self.w_rate
    }

    /// Advances to `t_end` (s) with the input rate `rate_dps` held;
    /// `on_latch` gets each pickoff zero crossing on the way.
    pub fn advance(
        &mut self,
        t_end: f64,
        rate_dps: f64,
        mut on_latch: impl FnMut(&Latch),
    ) -> Reading {
        self.psi_anchor = self.psi(self.x);
        self.t_anchor = self.time();
        self.kr = self.k_fr * rate_dps;
        loop {
            if self.x >= self.cur.h {
                self.x -= self.cur.h;
                self.cur = self.motion.next_half();
                self.latch_done = false;
                self.windows.valid = false;
            }
            let hc = self.cur;
            // Local times: rounding stays at the half cycle's scale.
            let x_end = t_end - hc.t0;
            if self.x >= x_end {
                break;
            }
            if !self.windows.valid || self.windows.rate != rate_dps {
                self.windows = find_windows::<F>(
                    &hc,
                    rate_dps,
                    self.w_rate,
                    self.p.lock_in_dps > 0.0,
                    self.p.accuracy.fast_trig,
                );
            }
            // Nudged by 1e-9 of a half cycle (1e-12 s): a boundary reached
            // up to rounding counts as passed, so every segment moves on.
            let (in_fine, s_next) = self.windows.at(self.x / hc.h + 1e-9);
            let x_latch = 0.5 * hc.h + self.p.pickoff_delay_s;
            let mut x_seg = (s_next * hc.h).min(hc.h).min(x_end);
            if !self.latch_done && x_latch > self.x {
                x_seg = x_seg.min(x_latch);
            }
            if x_seg <= self.x {
                // Only at the half cycle's end (rounding): roll over.
                self.x = hc.h;
                continue;
            }
            if in_fine {
                if !self.fine {
                    self.e = self.to_actual(&hc, self.x, rate_dps, self.e);
                    self.fine = true;
                }
                self.fine_to(&hc, x_seg, rate_dps);
            } else {
                if self.fine {
                    self.e = self.to_mean(&hc, self.x, rate_dps, self.e);
                    self.fine = false;
                }
                self.e += self.outer_drift(&hc, self.x, x_seg, rate_dps);
            }
            self.x = x_seg;
            if !self.latch_done && self.x >= x_latch {
                self.latch_done = true;
                let l = self.latch(&hc, rate_dps);
                on_latch(&l);
            }
        }
        let hc = self.cur;
        // The reading at t_end exactly (x may differ from it by rounding).
        let x = t_end - hc.t0;
        let psi = self.psi(x);
        let e = self.actual_error(&hc, x, rate_dps);
        let dither = self.k_fr * hc.theta_x(x);
        let fr = self.f0 + psi + dither + e;
        let counts = (4.0 * fr).floor() as i64;
        Reading {
            t_s: t_end,
            counter: counts as u16,
            counts,
            truth_counts: 4.0 * (self.f0 + psi + e),
            dither_counts: 4.0 * dither,
            lockin_counts: 4.0 * e,
        }
    }

    /// K_fr times the input angle at local time x (within the present
    /// `advance`), fringes.
    fn psi(&self, x: f64) -> f64 {
        self.psi_anchor + self.kr * ((self.cur.t0 - self.t_anchor) + x)
    }

    /// The actual error at x (adds the ripple outside the windows).
    fn actual_error(&self, hc: &Half, x: f64, rate: f64) -> f64 {
        if self.fine {
            self.e
        } else {
            self.to_actual(hc, x, rate, self.e)
        }
    }

    /// Total fringes at local time x for an error e.
    fn fringes(&self, hc: &Half, x: f64, e: f64) -> f64 {
        self.f0 + self.psi(x) + self.k_fr * hc.theta_x(x) + e
    }

    /// The near-identity transform's coefficients at x: `u = v + r1 cos v
    /// + r2 sin v`, `r1 = a/w`, `r2 = a w'/w^3` (the second removes the
    /// `a w'/w^2` term from the averaged equation).
    fn ripple(&self, hc: &Half, x: f64, rate: f64) -> (f64, f64) {
        let s = (x / hc.h).clamp(0.0, 1.0);
        let (d_rate, d_accel) = if self.p.accuracy.fast_trig {
            let (sn, cs) = sin_cos_in::<F>(PI * s, true);
            let k = PI / hc.h;
            (
                hc.sign * k * sn * (hc.abar() - hc.d() * cs),
                hc.sign * k * k * (cs * (hc.abar() - hc.d() * cs) + hc.d() * sn * sn),
            )
        } else {
            (hc.rate(s), hc.accel(s))
        };
        let om = rate + d_rate;
        let r1 = self.p.lock_in_dps / om;
        let r2 = r1 * d_accel / (2.0 * PI * self.k_fr * om * om);
        (r1, r2)
    }

    /// Mean error -> actual.
    fn to_actual(&self, hc: &Half, x: f64, rate: f64, e_mean: f64) -> f64 {
        if self.kappa == 0.0 {
            return e_mean;
        }
        let (r1, r2) = self.ripple(hc, x, rate);
        if !(r1.abs() < 1.0 && r2.abs() < 1.0) {
            // Not where the transform holds (never at a window's edge).
            return e_mean;
        }
        let v = 2.0 * PI * frac(self.fringes(hc, x, e_mean)) + self.p.beta_rad;
        let (sv, cv) = sin_cos_in::<F>(v, self.p.accuracy.fast_trig);
        e_mean + (r1 * cv + r2 * sv) / (2.0 * PI)
    }

    /// Actual error -> mean: solves `v = u - r1 cos v - r2 sin v` by iteration.
    fn to_mean(&self, hc: &Half, x: f64, rate: f64, e: f64) -> f64 {
        if self.kappa == 0.0 {
            return e;
        }
        let (r1, r2) = self.ripple(hc, x, rate);
        if !(r1.abs() < 1.0 && r2.abs() < 1.0) {
            return e;
        }
        let u = 2.0 * PI * frac(self.fringes(hc, x, e)) + self.p.beta_rad;
        let mut v = u;
        let fast = self.p.accuracy.fast_trig;
        for _ in 0..4 {
            let (sv, cv) = sin_cos_in::<F>(v, fast);
            v = u - r1 * cv - r2 * sv;
        }
        let (sv, cv) = sin_cos_in::<F>(v, fast);
        e - (r1 * cv + r2 * sv) / (2.0 * PI)
    }

    /// Drift of the mean error over local times [xa, xb] outside the
    /// windows: `-K_fr Omega_L^2/2 * integral dt/Omega_I` (two 8-node
    /// Gauss-Legendre panels).
    fn outer_drift(&self, hc: &Half, xa: f64, xb: f64, rate: f64) -> f64 {
        if self.kappa == 0.0 || xb <= xa {
            return 0.0;
        }
        let c = |x: f64| F::from(x).unwrap_or(F::zero());
        let (h, x0) = (c(hc.h), c(xa));
        let (abar, d, sign, om) = (c(hc.abar()), c(hc.d()), c(hc.sign), c(rate));
        let pi = c(PI);
        let half_pi = c(0.5 * PI);
        let fast = self.p.accuracy.fast_trig;
        let inv = |dx: F| {
            let s = (x0 + dx) / h;
            let (sn, cs) = if fast {
                (sin_small(pi * s), sin_small(pi * s + half_pi))
            } else {
                (pi * s).sin_cos()
            };
            let oi = om + sign * pi / h * sn * (abar - d * cs);
            if oi.abs() > F::epsilon() {
                F::one() / oi
            } else {
                F::zero()
            }
        };
        let half = 0.25 * (xb - xa);
        let mut sum = F::zero();
        for panel in 0..2 {
            let mid = (2 * panel + 1) as f64 * half;
            for k in 0..4 {
                let w = c(GL_W[k]);
                sum = sum + w * (inv(c(mid + half * GL_X[k])) + inv(c(mid - half * GL_X[k])));
            }
        }
        let integral = sum.to_f64().unwrap_or(0.0) * half;
        -0.5 * self.k_fr * self.p.lock_in_dps * self.p.lock_in_dps * integral
    }

    /// RK4 of E from the current local time to `xb` (inside one half
    /// cycle), in pieces of at most MAX_PIECE.
    fn fine_to(&mut self, hc: &Half, xb: f64, rate: f64) {
        let x_max = MAX_PIECE * hc.h;
        while self.x < xb {
            let x_b = if xb - self.x > x_max {
                self.x + x_max
            } else {
                xb
            };
            let f_ref = frac(self.fringes(hc, self.x, self.e));
            self.e += self.piece(hc, self.x / hc.h, x_b - self.x, f_ref, rate);
            self.x = x_b;
        }
    }

    /// One fine piece starting at fraction `sa`, `dur` seconds long, from
    /// fringe fraction `f_ref`: returns the change of E.
    fn piece(&self, hc: &Half, sa: f64, dur: f64, f_ref: f64, rate: f64) -> f64 {
        // Taylor coefficients of theta_d(sa + y) - theta_d(sa), y = x/h:
        // theta_d = -sign (abar cos(pi s) - (d/4) cos(2 pi s) - d/4).
        let mut coef = [0.0f64; TAYLOR];
        let (abar, d) = (hc.abar(), hc.d());
        let fast = self.p.accuracy.fast_trig;
        let (s1, c1) = sin_cos_in::<F>(PI * sa, fast);
        let (s2, c2) = sin_cos_in::<F>(2.0 * PI * sa, fast);
        let mut fact = 1.0;
        let (mut p1, mut p2) = (1.0, 1.0);
        for (k, ck) in coef.iter_mut().enumerate().skip(1) {
            fact *= k as f64;
            p1 *= PI;
            p2 *= 2.0 * PI;
            // cos(x + k pi/2): cos, -sin, -cos, sin.
            let cyc = |c: f64, s: f64| match k % 4 {
                0 => c,
                1 => -s,
                2 => -c,
                _ => s,
            };
            *ck = -hc.sign * (abar * p1 * cyc(c1, s1) - 0.25 * d * p2 * cyc(c2, s2)) / fact;
        }
        let c = |x: f64| F::from(x).unwrap_or(F::zero());
        let cf: [F; TAYLOR] = core::array::from_fn(|k| c(coef[k] * self.k_fr));
        let dcf: [F; TAYLOR] = core::array::from_fn(|k| {
            if k + 1 < TAYLOR {
                c(coef[k + 1] * self.k_fr * (k + 1) as f64)
            } else {
                F::zero()
            }
        });
        let poly = |a: &[F; TAYLOR], y: F| {
            let mut acc = F::zero();
            for k in (0..TAYLOR).rev() {
                acc = acc * y + a[k];
            }
            acc
        };
        let h = c(hc.h);
        let inv_h = F::one() / h;
        let kr = c(self.k_fr * rate);
        let kappa = c(self.kappa);
        let beta = c(self.p.beta_rad);
        let two_pi = c(2.0 * PI);
        let f_ref = c(f_ref);
        let rhs = |x: F, e: F| {
            // Fringes relative to an integer: the phase stays small.
            let z = f_ref + kr * x + poly(&cf, x * inv_h) + e;
            let z = z - z.round();
            -kappa * sin_small(two_pi * z + beta)
        };
        let wf = c(self.w_fresnel + 2.0 * PI * self.kappa);
        let step = c(self.p.accuracy.step_rad);
        let dur = c(dur);
        let (mut x, mut e) = (F::zero(), F::zero());
        let half = c(0.5);
        let sixth = c(1.0 / 6.0);
        while x < dur {
            // Fringe rate (rad/s) at x: 2 pi (K_fr Omega + d/dx of the polynomial).
            let w = (two_pi * (kr + poly(&dcf, x * inv_h) * inv_h)).abs();
            let mut dx = step / (w + wf);
            if x + c(1.5) * dx >= dur {
                dx = dur - x;
            }
            let k1 = rhs(x, e);
            let k2 = rhs(x + half * dx, e + half * dx * k1);
            let k3 = rhs(x + half * dx, e + half * dx * k2);
            let k4 = rhs(x + dx, e + dx * k3);
            e = e + dx * sixth * (k1 + c(2.0) * (k2 + k3) + k4);
            x = x + dx;
        }
        e.to_f64().unwrap_or(0.0)
    }

    /// The latch at the current time (the zero crossing plus the pickoff's delay).
    fn latch(&mut self, hc: &Half, rate: f64) -> Latch {
        let x = self.x;
        let psi = self.psi(x);
        let e = self.actual_error(hc, x, rate);
        let fr = self.fringes(hc, x, e);
        let counts = (4.0 * fr).floor() as i64;
        // The photodiodes a little later: the dither and input angle move
        // on (exactly), the lock-in error by its rate.
        let xa = x + self.p.adc_delay_s;
        let de = -self.kappa * (2.0 * PI * frac(fr) + self.p.beta_rad).sin() * self.p.adc_delay_s;
        let fr_adc =
            self.f0 + psi + self.k_fr * (rate * self.p.adc_delay_s + hc.theta_x(xa)) + e + de;
        Latch {
            t_s: hc.t0 + x,
            counter: counts as u16,
            counts,
            rising: hc.sign > 0.0,
            photodiodes: self.photodiodes(fr_adc),
            truth_counts: 4.0 * (self.f0 + psi + e),
        }
    }

    fn photodiodes(&mut self, fringes: f64) -> [u16; 2] {
        let pd = self.p.photodiodes;
        let ph = 2.0 * PI * frac(fringes);
        let full = ((1u32 << pd.bits.min(16)) - 1) as f64;
        let code = |x: f64, rng: &mut Xoshiro256PlusPlus| {
            let z: f64 = StandardNormal.sample(rng);
            (x + pd.noise_rms * z).round().clamp(0.0, full) as u16
        };
        let a = code(pd.offset[0] + pd.amplitude * ph.sin(), &mut self.pd_rng);
        let b = code(
            pd.offset[1]
                + pd.amplitude * (1.0 + pd.gain_error) * (ph + pd.quadrature_error_rad).cos(),
            &mut self.pd_rng,
        );
        [a, b]
    }
}
