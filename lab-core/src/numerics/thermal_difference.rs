//! The RLG monoblock temperature difference dT = T_a - T_b and its filtered
//! gradient, formed as the firmware forms them (rlg/thermal.rs): dT clamped
//! to +-32 degC; the gradient from the first-order filtered differentiator
//! (time constant `GRAD_TAU_S`, first slope 0, slope clamped to +-8 degC/s).
//! The thermal calibration fits on them and discovery's thermal effects are
//! built from them, so both use this one copy.

use gyro_sp::rlg::thermal::GRAD_TAU_S;

/// dT = a - b and its filtered gradient, one value per row of `t`.
pub fn dt_and_gradient(t: &[f64], a: &[f64], b: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = t.len();
    let mut dts: Vec<f64> = Vec::with_capacity(n);
    let mut grads = Vec::with_capacity(n);
    let mut grad = 0.0;
    for k in 0..n {
        let dtk = (a[k] - b[k]).clamp(-32.0, 32.0);
        if k > 0 {
            let h = t[k] - t[k - 1];
            let slope = ((dtk - dts[k - 1]) / h).clamp(-8.0, 8.0);
            grad += h / (GRAD_TAU_S + h) * (slope - grad);
        }
        dts.push(dtk);
        grads.push(grad);
    }
    (dts, grads)
}
