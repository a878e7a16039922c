//! A warning a calibration gives with its result: a short code scripts can
//! test for, and the sentence a person reads (the reports' verdicts and the
//! JSON's `warnings`).

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Warning {
    pub kind: String,
    pub message: String,
}

impl Warning {
    pub fn new(kind: &str, message: String) -> Self {
        Self {
            kind: kind.to_owned(),
            message,
        }
    }
}
