//! A warning a calibration gives with its result: a short code scripts can
//! test for, and the sentence a person reads (the reports' verdicts and the
//! JSON's `warnings`). In the JSON the code is both `kind` (as it always
//! was) and `code` (as the record checks' warnings name it).

#[derive(Clone, Debug, PartialEq, Eq)]
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

impl serde::Serialize for Warning {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut m = s.serialize_struct("Warning", 3)?;
        m.serialize_field("kind", &self.kind)?;
        m.serialize_field("code", &self.kind)?;
        m.serialize_field("message", &self.message)?;
        m.end()
    }
}
