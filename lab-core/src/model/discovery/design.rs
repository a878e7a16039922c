//! The windowed regression problem of discovery: the residual's window
//! means against the window means of each term's columns, both whitened by
//! the residual's noise model (noise_model.rs), so that a least-squares
//! fit is the generalised one; the joint fit of a set of terms at their
//! non-linear parameters, the search of those parameters, and the
//! criterion (BIC on the whitened problem).

use super::noise_model::Whitener;
use super::normal::normal_solve;
use super::projection::Projection;
use super::terms::{periodic_grid, without, Kind, Shape, Term};
use super::windows::Windows;
use crate::model::effects::{Effect, DPH};
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use crate::numerics::dot::sum_sq;
use crate::numerics::search::{golden, grid_then_golden};
use std::cell::{Cell, OnceCell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

/// A term's columns (window means) and fixed part, unwhitened.
pub struct Raw {
    pub cols: Vec<Vec<f64>>,
    pub offset: Option<Vec<f64>>,
}

/// The windowed, whitened problem.
pub struct Design<'a> {
    pub inp: &'a Inputs,
    pub win: &'a Windows,
    pub extent: Extent,
    /// Window means of the residual, deg/s.
    pub r: Vec<f64>,
    pub wh: Whitener,
    /// The whitened residual.
    pub y: Vec<f64>,
    /// Step times offered to the fit (from transients.rs).
    pub steps: Vec<f64>,
    /// Variance inflation for the correlation the noise model leaves in
    /// the whitened residual ([`inflation`]), at least 1.
    pub phi: f64,
    /// Least variance scale of the whitened residual the intervals take
    /// (1 on a short record: the white level its samples measure; 0
    /// otherwise).
    pub min_scale: f64,
    /// Whitened columns of the terms without a non-linear parameter.
    fixed: HashMap<String, Whitened>,
    /// Whitened columns of terms at the points of their parameter's grid,
    /// computed once (the searches come back to them at every step), and
    /// the bytes they hold (at most [`GRID_CACHE_BYTES`]).
    grid_cache: RefCell<HashMap<(String, u64), Rc<Whitened>>>,
    grid_bytes: Cell<usize>,
    /// Whitened columns of terms off their grid: the golden-section
    /// searches come back to the same points while the other terms hold
    /// still, and a selection fits the same set again and again (at most
    /// [`OFF_GRID_CACHE_BYTES`], emptied when full).
    off_grid: RefCell<HashMap<(String, u64), Rc<Whitened>>>,
    off_grid_bytes: Cell<usize>,
    /// What the noise model does not change, shared by every pass's design.
    shared: Rc<Unwhitened>,
}

/// What a run's designs share, whatever their noise model: the fixed
/// terms' window means (a shape's filtered derivatives cost the rows, so
/// a 10 Hz record would pay for them again at every pass), the searches'
/// grids, and the knee's sums.
struct Unwhitened {
    fixed: OnceCell<Vec<(Kind, Raw)>>,
    grids: RefCell<HashMap<String, (Vec<f64>, bool)>>,
    /// Per window, what the knee's column needs (made on its first use):
    /// see [`KneeSums`].
    knee: RefCell<Option<Option<Rc<KneeSums>>>>,
}

/// The scale-factor knee's column, w (T - knee)+ averaged over each
/// window, at any knee from sums made once: a window whose temperatures
/// lie all above the knee averages to mean(w T) - knee mean(w), one all
/// below to nothing, and only the few a knee falls inside are summed row by
/// row. Each search step costs the windows, not the rows (a 10 Hz record
/// costs what a 1 Hz one does).
struct KneeSums {
    w: Vec<f64>,
    wt: Vec<f64>,
    t_min: Vec<f64>,
    t_max: Vec<f64>,
    /// First row of each window, and one past the last window's.
    start: Vec<usize>,
}

impl KneeSums {
    fn new(inp: &Inputs, win: &Windows) -> Option<Self> {
        let temp = inp.temp.as_ref()?;
        let n = win.len();
        let mut s = Self {
            w: vec![0.0; n],
            wt: vec![0.0; n],
            t_min: vec![f64::INFINITY; n],
            t_max: vec![f64::NEG_INFINITY; n],
            start: vec![usize::MAX; n + 1],
        };
        for (row, &i) in win.idx.iter().enumerate() {
            s.w[i] += inp.w[row];
            s.wt[i] += inp.w[row] * temp[row];
            s.t_min[i] = s.t_min[i].min(temp[row]);
            s.t_max[i] = s.t_max[i].max(temp[row]);
            s.start[i] = s.start[i].min(row);
        }
        s.start[n] = win.idx.len();
        // Windows are contiguous runs of rows (time increases).
        (0..n).all(|i| s.start[i] < s.start[i + 1]).then_some(s)
    }

    fn column(&self, inp: &Inputs, win: &Windows, knee: f64) -> Vec<f64> {
        let temp = inp.temp.as_deref().unwrap_or(&[]);
        (0..win.len())
            .map(|i| {
                let sum = if self.t_min[i] >= knee {
                    self.wt[i] - knee * self.w[i]
                } else if self.t_max[i] <= knee {
                    0.0
                } else {
                    (self.start[i]..self.start[i + 1])
                        .map(|r| inp.w[r] * (temp[r] - knee).max(0.0))
                        .sum()
                };
                1e-6 * sum / win.count[i]
            })
            .collect()
    }
}

/// Grid points whitened together.
const WHITEN_TERMS: usize = 8;

/// Memory the whitened columns off the grid may take.
const OFF_GRID_CACHE_BYTES: usize = 32 << 20;

/// Bytes a term's whitened columns take.
fn bytes_of(w: &Whitened) -> usize {
    8 * (w.0.iter().map(Vec::len).sum::<usize>() + w.1.as_ref().map_or(0, Vec::len))
}

/// Memory the grid's whitened columns may take.
const GRID_CACHE_BYTES: usize = 96 << 20;

/// Golden-section steps of a search: after the grid, the bracket shrinks
/// to 0.618^20 (7e-5) of two grid steps; the local refinement after
/// every addition goes to 0.618^30 (5e-7) of its bracket (a lock-in rate
/// is set to a few ppm by a strong signal).
const GOLDEN_STEPS: usize = 20;
const REFINE_STEPS: usize = 30;

/// A term's whitened columns, held or computed.
enum WRef<'a> {
    Held(&'a Whitened),
    Shared(Rc<Whitened>),
}

impl WRef<'_> {
    fn get(&self) -> &Whitened {
        match self {
            WRef::Held(w) => w,
            WRef::Shared(w) => w,
        }
    }
}

/// A term's whitened columns, and its whitened derivative column when it
/// has a non-linear parameter.
type Whitened = (Vec<Vec<f64>>, Option<Vec<f64>>);

/// A joint fit: coefficients (in the terms' order, their columns in
/// turn) and the whitened residual and its sum of squares.
#[derive(Clone, Debug)]
pub struct Fit {
    pub coef: Vec<f64>,
    pub resid: Vec<f64>,
    pub sse: f64,
}

fn key(k: Kind) -> String {
    format!("{k:?}")
}

impl<'a> Design<'a> {
    pub fn new(
        inp: &'a Inputs,
        win: &'a Windows,
        extent: Extent,
        r: Vec<f64>,
        wh: Whitener,
        steps: Vec<f64>,
    ) -> Self {
        let shared = Rc::new(Unwhitened {
            fixed: OnceCell::new(),
            grids: RefCell::new(HashMap::new()),
            knee: RefCell::new(None),
        });
        let mut d = Self::whitened_with(inp, win, extent, r, wh, steps, shared);
        let mut kinds = vec![Kind::Constant];
        kinds.extend(
            Effect::ALL
                .into_iter()
                .filter(|e| e.nonlinear_param().is_none() && e.available(inp))
                .map(Kind::Effect),
        );
        kinds.extend(
            Shape::ALL
                .into_iter()
                .filter(|s| s.available(inp))
                .map(Kind::Shape),
        );
        let fixed = kinds.iter().map(|k| (*k, d.raw(&Term::of(*k)))).collect();
        let _ = d.shared.fixed.set(fixed);
        d.whiten_fixed();
        d
    }

    /// The same run's problem under another noise model (and steps): the
    /// fixed terms' window means, the grids and the knee's sums are
    /// reused, only the whitening is new.
    pub fn renoised(&self, wh: Whitener, steps: Vec<f64>) -> Self {
        let mut d = Self::whitened_with(
            self.inp,
            self.win,
            self.extent,
            self.r.clone(),
            wh,
            steps,
            self.shared.clone(),
        );
        d.whiten_fixed();
        d
    }

    fn whitened_with(
        inp: &'a Inputs,
        win: &'a Windows,
        extent: Extent,
        r: Vec<f64>,
        wh: Whitener,
        steps: Vec<f64>,
        shared: Rc<Unwhitened>,
    ) -> Self {
        Self {
            inp,
            win,
            extent,
            r,
            wh,
            y: vec![],
            steps,
            phi: 1.0,
            min_scale: 0.0,
            fixed: HashMap::new(),
            grid_cache: RefCell::new(HashMap::new()),
            grid_bytes: Cell::new(0),
            off_grid: RefCell::new(HashMap::new()),
            off_grid_bytes: Cell::new(0),
            shared,
        }
    }

    /// The residual and every fixed column whitened together.
    fn whiten_fixed(&mut self) {
        let shared = self.shared.clone();
        let fixed = shared.fixed.get().map_or(&[][..], Vec::as_slice);
        let mut all: Vec<&[f64]> = vec![&self.r];
        for (_, raw) in fixed {
            all.extend(raw.cols.iter().map(Vec::as_slice));
            all.extend(raw.offset.as_deref());
        }
        let mut w = self.wh.whiten_many(&all).into_iter();
        self.y = w.next().unwrap_or_default();
        for (k, raw) in fixed {
            let cols = w.by_ref().take(raw.cols.len()).collect();
            let offset = raw.offset.as_ref().and_then(|_| w.next());
            self.fixed.insert(key(*k), (cols, offset));
        }
    }

    /// Windows used by the fit.
    pub fn n(&self) -> f64 {
        self.wh.used() as f64
    }

    /// A term's columns and fixed part as window means (deg/s per unit).
    pub fn raw(&self, t: &Term) -> Raw {
        match t.kind {
            Kind::Constant => Raw {
                cols: vec![vec![DPH; self.win.len()]],
                offset: None,
            },
            Kind::Step => Raw {
                cols: vec![self
                    .win
                    .t
                    .iter()
                    .map(|&w| if w >= t.x { DPH } else { 0.0 })
                    .collect()],
                offset: None,
            },
            Kind::Shape(s) => Raw {
                cols: vec![self.win.mean(&s.column(self.inp))],
                offset: None,
            },
            Kind::Periodic => {
                let om = std::f64::consts::TAU / t.x.max(1e-9);
                Raw {
                    cols: vec![
                        self.win.t.iter().map(|&w| DPH * (om * w).sin()).collect(),
                        self.win.t.iter().map(|&w| DPH * (om * w).cos()).collect(),
                    ],
                    offset: None,
                }
            }
            Kind::Decay => Raw {
                cols: vec![self
                    .win
                    .t
                    .iter()
                    .map(|&w| DPH * (-w / t.x.max(1e-9)).exp())
                    .collect()],
                offset: None,
            },
            Kind::Effect(Effect::WarmUp) => Raw {
                // Smooth over a window (tau >= 2 min): its value at the
                // window's mean time.
                cols: vec![self
                    .win
                    .t
                    .iter()
                    .map(|&w| DPH * (1.0 - (-w / t.x.max(1e-9)).exp()))
                    .collect()],
                offset: None,
            },
            Kind::Effect(Effect::ScaleFactorKnee) if self.knee_sums().is_some() => Raw {
                cols: vec![self
                    .knee_sums()
                    .map_or_else(Vec::new, |k| k.column(self.inp, self.win, t.x))],
                offset: None,
            },
            Kind::Effect(e) => {
                let b = e.basis(self.inp, t.x);
                Raw {
                    cols: b.cols.iter().map(|c| self.win.mean(c)).collect(),
                    offset: b.offset.map(|o| self.win.mean(&o)),
                }
            }
        }
    }

    /// The knee's sums, made on first use (None without a temperature).
    fn knee_sums(&self) -> Option<Rc<KneeSums>> {
        let knee = &self.shared.knee;
        if knee.borrow().is_none() {
            let k = KneeSums::new(self.inp, self.win).map(Rc::new);
            *knee.borrow_mut() = Some(k);
        }
        knee.borrow().clone().flatten()
    }

    fn whiten_raw(&self, raw: &Raw) -> (Vec<Vec<f64>>, Option<Vec<f64>>) {
        let mut all: Vec<&[f64]> = raw.cols.iter().map(Vec::as_slice).collect();
        all.extend(raw.offset.as_deref());
        let mut w = self.wh.whiten_many(&all);
        let offset = raw.offset.as_ref().and_then(|_| w.pop());
        (w, offset)
    }

    /// A term's whitened columns and fixed part: held, kept from an
    /// earlier call, or computed and kept.
    fn whitened(&self, t: &Term) -> WRef<'_> {
        if let Some(w) = self.fixed.get(&key(t.kind)) {
            return WRef::Held(w);
        }
        let k = (key(t.kind), t.x.to_bits());
        if let Some(w) = self.grid_cache.borrow().get(&k) {
            return WRef::Shared(w.clone());
        }
        if let Some(w) = self.off_grid.borrow().get(&k) {
            return WRef::Shared(w.clone());
        }
        let w = Rc::new(self.whiten_raw(&self.raw(t)));
        let bytes = bytes_of(&w);
        if self.off_grid_bytes.get() + bytes > OFF_GRID_CACHE_BYTES {
            self.off_grid.borrow_mut().clear();
            self.off_grid_bytes.set(0);
        }
        self.off_grid_bytes.set(self.off_grid_bytes.get() + bytes);
        self.off_grid.borrow_mut().insert(k, w.clone());
        WRef::Shared(w)
    }

    /// [`Self::whitened`] at a point of the term's grid: on the first, the
    /// whole grid is whitened at once and kept while memory allows.
    fn whitened_on_grid(&self, t: &Term) -> WRef<'_> {
        let k = (key(t.kind), t.x.to_bits());
        if let Some(w) = self.grid_cache.borrow().get(&k) {
            return WRef::Shared(w.clone());
        }
        self.fill_grid(t.kind);
        if let Some(w) = self.grid_cache.borrow().get(&k) {
            return WRef::Shared(w.clone());
        }
        self.whitened(t)
    }

    /// Whitens the grid points of `kind` not yet kept, all together, and
    /// keeps them if they fit in [`GRID_CACHE_BYTES`].
    fn fill_grid(&self, kind: Kind) {
        let (grid, _) = self.grid(&Term::of(kind));
        let missing: Vec<Term> = grid
            .iter()
            .map(|&x| Term { kind, x })
            .filter(|t| {
                !self
                    .grid_cache
                    .borrow()
                    .contains_key(&(key(kind), t.x.to_bits()))
            })
            .collect();
        let Some(first) = missing.first() else {
            return;
        };
        let r0 = self.raw(first);
        let per = 8
            * (r0.cols.iter().map(Vec::len).sum::<usize>()
                + r0.offset.as_ref().map_or(0, Vec::len));
        let bytes = per * missing.len();
        if self.grid_bytes.get() + bytes > GRID_CACHE_BYTES {
            return;
        }
        // A few points at a time: their raw columns are transient.
        for chunk in missing.chunks(WHITEN_TERMS) {
            let raws: Vec<Raw> = chunk.iter().map(|t| self.raw(t)).collect();
            let mut all: Vec<&[f64]> = vec![];
            for raw in &raws {
                all.extend(raw.cols.iter().map(Vec::as_slice));
                all.extend(raw.offset.as_deref());
            }
            let mut w = self.wh.whiten_many(&all).into_iter();
            let mut cache = self.grid_cache.borrow_mut();
            for (t, raw) in chunk.iter().zip(&raws) {
                let cols = w.by_ref().take(raw.cols.len()).collect();
                let offset = raw.offset.as_ref().and_then(|_| w.next());
                cache.insert((key(kind), t.x.to_bits()), Rc::new((cols, offset)));
            }
        }
        self.grid_bytes.set(self.grid_bytes.get() + bytes);
    }

    /// The fixed part of the searches of `terms[j]`'s parameter.
    fn projection_without(&self, terms: &[Term], j: usize) -> Option<Projection> {
        let (cols, y) = self.whitened_problem(&without(terms, j));
        Projection::new(cols, y)
    }

    /// The whitened sum of squares of `proj`'s terms with `t` added.
    fn sse_adding(&self, proj: &Projection, w: &WRef) -> f64 {
        let (cols, off) = w.get();
        proj.sse_with(cols, off.as_deref())
    }

    /// The raw (unwhitened) columns of `terms` and the residual's window
    /// means less their fixed parts.
    pub fn raw_problem(&self, terms: &[Term]) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut y = self.r.clone();
        let mut cols = vec![];
        for t in terms {
            let raw = self.raw(t);
            if let Some(o) = raw.offset {
                for (a, b) in y.iter_mut().zip(o) {
                    *a -= b;
                }
            }
            cols.extend(raw.cols);
        }
        (cols, y)
    }

    /// The whitened columns of `terms` and the whitened residual less
    /// their fixed parts.
    pub fn whitened_problem(&self, terms: &[Term]) -> (Vec<Vec<f64>>, Vec<f64>) {
        let (ws, y) = self.whitened_terms(terms);
        let cols = ws.iter().flat_map(|w| w.get().0.iter().cloned()).collect();
        (cols, y)
    }

    /// The whitened columns of `terms` (held, not copied) and the whitened
    /// residual less their fixed parts.
    fn whitened_terms(&self, terms: &[Term]) -> (Vec<WRef<'_>>, Vec<f64>) {
        let mut y = self.y.clone();
        let ws: Vec<WRef> = terms.iter().map(|t| self.whitened(t)).collect();
        for w in &ws {
            if let Some(o) = &w.get().1 {
                for (a, b) in y.iter_mut().zip(o) {
                    *a -= b;
                }
            }
        }
        (ws, y)
    }

    /// Joint least-squares fit of `terms` on the whitened problem; None
    /// when their columns are degenerate.
    pub fn fit(&self, terms: &[Term]) -> Option<Fit> {
        let (ws, y) = self.whitened_terms(terms);
        let cols: Vec<&[f64]> = ws
            .iter()
            .flat_map(|w| w.get().0.iter().map(Vec::as_slice))
            .collect();
        let coef = if cols.is_empty() {
            vec![]
        } else {
            normal_solve(&cols, &y)?
        };
        let mut resid = y;
        for (c, b) in cols.iter().zip(&coef) {
            for (r, v) in resid.iter_mut().zip(c.iter()) {
                *r -= b * v;
            }
        }
        let sse = sum_sq(&resid);
        Some(Fit { coef, resid, sse })
    }

    /// Whitened sum of squares of a joint fit (infinite when degenerate).
    pub fn sse(&self, terms: &[Term]) -> f64 {
        self.fit(terms).map_or(f64::INFINITY, |f| f.sse)
    }

    /// The criterion of a fit with `dof` free parameters: BIC of the
    /// whitened problem, n ln(SSE/n)/phi + dof ln n.
    pub fn criterion(&self, sse: f64, dof: usize) -> f64 {
        let n = self.n().max(2.0);
        n * (sse.max(1e-300) / n).ln() / self.phi.max(1.0) + dof as f64 * n.ln()
    }

    /// The criterion of the joint fit of `terms`.
    pub fn criterion_of(&self, terms: &[Term]) -> f64 {
        let dof = terms.iter().map(|t| t.kind.dof()).sum();
        self.criterion(self.sse(terms), dof)
    }

    /// Search grid of a term's non-linear parameter: an effect's, or the
    /// steps offered.
    fn grid(&self, t: &Term) -> (Vec<f64>, bool) {
        match t.kind {
            Kind::Effect(e) => {
                // An effect's grid reads the rows: made once per run.
                let k = key(t.kind);
                if let Some(g) = self.shared.grids.borrow().get(&k) {
                    return g.clone();
                }
                let g = (e.search_grid(self.inp), e.search_log());
                self.shared.grids.borrow_mut().insert(k, g.clone());
                g
            }
            Kind::Periodic => {
                let n = self.win.t.len();
                let span = if n > 1 {
                    self.win.t[n - 1] - self.win.t[0]
                } else {
                    0.0
                };
                (periodic_grid(span), true)
            }
            _ => (vec![], false),
        }
    }

    /// Best non-linear parameter of `terms[j]` with the others held: grid
    /// then golden section (in ln x for positive, decade-spanning ones).
    pub fn optimize(&self, terms: &mut [Term], j: usize) {
        self.optimize_with(terms, j, true);
    }

    /// Whether `t` has a parameter to search.
    pub fn searched(&self, t: &Term) -> bool {
        !self.grid(t).0.is_empty()
    }

    /// [`Self::optimize`] on the grid alone (its whitened columns are
    /// kept: a screening of many candidates costs their products only).
    pub fn optimize_on_grid(&self, terms: &mut [Term], j: usize) {
        self.optimize_with(terms, j, false);
    }

    fn optimize_with(&self, terms: &mut [Term], j: usize, golden_too: bool) {
        let (grid, log) = self.grid(&terms[j]);
        if grid.is_empty() {
            return;
        }
        let Some(proj) = self.projection_without(terms, j) else {
            return;
        };
        let on_grid: Vec<u64> = grid.iter().map(|x| x.to_bits()).collect();
        let mut t = terms[j];
        let cost = |v: f64| {
            t.x = if log { v.exp() } else { v };
            // The grid's points exactly (ln then exp may not round-trip).
            if let Some(i) = on_grid
                .iter()
                .position(|b| (f64::from_bits(*b) - t.x).abs() <= 1e-12 * t.x.abs().max(1.0))
            {
                t.x = f64::from_bits(on_grid[i]);
                return self.sse_adding(&proj, &self.whitened_on_grid(&t));
            }
            self.sse_adding(&proj, &self.whitened(&t))
        };
        let g: Vec<f64> = if log {
            grid.iter().map(|x| x.ln()).collect()
        } else {
            grid.clone()
        };
        let (v, _) = grid_then_golden(cost, &g, if golden_too { GOLDEN_STEPS } else { 0 });
        terms[j].x = if log { v.exp() } else { v };
        if let Some(x) = grid
            .iter()
            .find(|x| (*x - terms[j].x).abs() <= 1e-12 * x.abs().max(1.0))
        {
            terms[j].x = *x;
        }
    }

    /// Local re-fit of `terms[j]`'s non-linear parameter around its value.
    pub fn refine(&self, terms: &mut [Term], j: usize) {
        let (grid, log) = self.grid(&terms[j]);
        if grid.is_empty() {
            return;
        }
        let (lo, hi) = grid
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| {
                (a.0.min(x), a.1.max(x))
            });
        let x0 = terms[j].x.clamp(lo, hi);
        let (a, b) = if log {
            ((x0.ln() - 0.3).max(lo.ln()), (x0.ln() + 0.3).min(hi.ln()))
        } else {
            ((x0 - 1.0).max(lo), (x0 + 1.0).min(hi))
        };
        let Some(proj) = self.projection_without(terms, j) else {
            return;
        };
        let mut t = terms[j];
        let (v, _) = golden(
            |v: f64| {
                t.x = if log { v.exp() } else { v };
                self.sse_adding(&proj, &self.whitened(&t))
            },
            a,
            b,
            REFINE_STEPS,
        );
        terms[j].x = if log { v.exp() } else { v };
    }

    /// A term's part at coefficients `coef` (its own columns'), whitened.
    pub fn whitened_part(&self, t: &Term, coef: &[f64]) -> Vec<f64> {
        let raw = self.raw(t);
        let mut p = raw.offset.unwrap_or_else(|| vec![0.0; self.win.len()]);
        for (c, b) in raw.cols.iter().zip(coef) {
            for (a, v) in p.iter_mut().zip(c) {
                *a += b * v;
            }
        }
        self.wh.whiten(&p)
    }

    /// Each term's part of a fit, in window means of deg/s (unwhitened):
    /// its columns times its coefficients plus its fixed part.
    pub fn parts(&self, terms: &[Term], coef: &[f64]) -> Vec<Vec<f64>> {
        let mut col = 0;
        terms
            .iter()
            .map(|t| {
                let raw = self.raw(t);
                let mut p = raw.offset.unwrap_or_else(|| vec![0.0; self.win.len()]);
                for c in &raw.cols {
                    let b = coef.get(col).copied().unwrap_or(0.0);
                    for (a, v) in p.iter_mut().zip(c) {
                        *a += b * v;
                    }
                    col += 1;
                }
                p
            })
            .collect()
    }
}

/// Variance inflation of a whitened residual `r` (windows left out are
/// zeros, dropped) for the correlation its noise model did not capture:
/// the largest batch-means ratio over blocks of 8, 16, 32 ... windows up
/// to a sixteenth of the record (the variance of block means times the
/// block length, over the residual's variance: 1 for white innovations),
/// within 1 .. 100.
pub fn inflation(r: &[f64], keep: &[bool]) -> f64 {
    let x: Vec<f64> = r
        .iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(v, _)| *v)
        .collect();
    let n = x.len();
    let var = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (v.len() - 1).max(1) as f64
    };
    if n < 32 {
        return 1.0;
    }
    let v1 = var(&x);
    // NaN or zero variance: no inflation to estimate.
    if v1.is_nan() || v1 <= 0.0 {
        return 1.0;
    }
    let mut phi: f64 = 1.0;
    let mut l = 8;
    while l * 16 <= n {
        let means: Vec<f64> = x
            .chunks_exact(l)
            .map(|c| c.iter().sum::<f64>() / l as f64)
            .collect();
        phi = phi.max(var(&means) * l as f64 / v1);
        l *= 2;
    }
    phi.clamp(1.0, 100.0)
}
