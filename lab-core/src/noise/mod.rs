//! Noise analysis of rate records by the IEEE 952 Allan-variance method
//! (docs/noise.md): the analysis of one record (analysis.rs) from the
//! overlapping estimator (adev.rs), Greenhall's equivalent degrees of
//! freedom (edf.rs), the IEEE 952 terms (terms.rs) fitted to the curve
//! (fit.rs, nnls.rs, model.rs), records with lost samples made uniform
//! (gaps.rs), the fit's goodness and honest intervals
//! (uncertainty.rs), the conventional readings (readings.rs), and what the
//! record must be for all that to mean something (record_checks.rs).

pub mod adev;
pub mod analysis;
pub mod edf;
pub mod fit;
pub mod gaps;
pub mod model;
pub mod nnls;
pub mod profile;
pub mod readings;
pub mod record_checks;
pub mod terms;
pub mod uncertainty;
