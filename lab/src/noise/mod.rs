//! Noise analysis of rate records by the IEEE 952 Allan-variance method
//! (docs/noise.md): the analysis of one record (analysis.rs) from the
//! overlapping estimator (adev.rs), Greenhall's equivalent degrees of
//! freedom (edf.rs) and the noise-term fit (terms.rs).

pub mod adev;
pub mod analysis;
pub mod edf;
pub mod terms;
