//! The units a user's file may carry its rates, temperatures and times
//! in, each converted on reading into the run file's own (deg/s, degC, s),
//! and what a column's name says of its unit (`gyro_z_rad_s`, `T[K]`):
//! a hint the plausibility checks (run_checks.rs) weigh.

use crate::error::LabError;
use std::fmt;
use std::str::FromStr;

/// deg/s per rad/s.
pub const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;
/// 0 degC in kelvin.
pub const ZERO_C_IN_K: f64 = 273.15;

/// The unit of a file's rate columns (`rate_dps`, `ref_rate_dps`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RateUnit {
    #[default]
    DegPerS,
    RadPerS,
    DegPerH,
}

impl RateUnit {
    pub const ALL: [RateUnit; 3] = [RateUnit::DegPerS, RateUnit::RadPerS, RateUnit::DegPerH];

    /// deg/s per unit.
    pub fn to_dps(self) -> f64 {
        match self {
            RateUnit::DegPerS => 1.0,
            RateUnit::RadPerS => DEG_PER_RAD,
            RateUnit::DegPerH => 1.0 / 3600.0,
        }
    }

    /// deg per unit of the angle it carries (angles and angular
    /// accelerations follow it: rad/s goes with rad and rad/s^2).
    pub fn angle_to_deg(self) -> f64 {
        match self {
            RateUnit::RadPerS => DEG_PER_RAD,
            _ => 1.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            RateUnit::DegPerS => "deg/s",
            RateUnit::RadPerS => "rad/s",
            RateUnit::DegPerH => "deg/h",
        }
    }
}

impl fmt::Display for RateUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RateUnit {
    type Err = LabError;
    fn from_str(s: &str) -> Result<Self, LabError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "deg/s" | "dps" | "degps" | "deg_s" => Ok(RateUnit::DegPerS),
            "rad/s" | "rps" | "radps" | "rad_s" => Ok(RateUnit::RadPerS),
            "deg/h" | "dph" | "degph" | "deg_h" => Ok(RateUnit::DegPerH),
            _ => Err(LabError::Usage(format!(
                "`{s}` is not a rate unit: deg/s, rad/s or deg/h"
            ))),
        }
    }
}

/// The unit of a file's temperature columns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TempUnit {
    #[default]
    Celsius,
    Kelvin,
    Fahrenheit,
}

impl TempUnit {
    /// degC of a reading.
    pub fn to_c(self, v: f64) -> f64 {
        match self {
            TempUnit::Celsius => v,
            TempUnit::Kelvin => v - ZERO_C_IN_K,
            TempUnit::Fahrenheit => (v - 32.0) * 5.0 / 9.0,
        }
    }

    /// degC per unit of a difference.
    pub fn scale(self) -> f64 {
        match self {
            TempUnit::Fahrenheit => 5.0 / 9.0,
            _ => 1.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TempUnit::Celsius => "C",
            TempUnit::Kelvin => "K",
            TempUnit::Fahrenheit => "F",
        }
    }
}

impl FromStr for TempUnit {
    type Err = LabError;
    fn from_str(s: &str) -> Result<Self, LabError> {
        match s.trim() {
            "C" | "c" | "degC" | "degc" | "celsius" => Ok(TempUnit::Celsius),
            "K" | "k" | "kelvin" => Ok(TempUnit::Kelvin),
            "F" | "f" | "degF" | "degf" | "fahrenheit" => Ok(TempUnit::Fahrenheit),
            _ => Err(LabError::Usage(format!(
                "`{s}` is not a temperature unit: C, K or F"
            ))),
        }
    }
}

/// The unit of a file's time column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeUnit {
    #[default]
    Seconds,
    Milliseconds,
    Microseconds,
}

impl TimeUnit {
    pub fn to_s(self) -> f64 {
        match self {
            TimeUnit::Seconds => 1.0,
            TimeUnit::Milliseconds => 1e-3,
            TimeUnit::Microseconds => 1e-6,
        }
    }
}

impl FromStr for TimeUnit {
    type Err = LabError;
    fn from_str(s: &str) -> Result<Self, LabError> {
        match s.trim() {
            "s" => Ok(TimeUnit::Seconds),
            "ms" => Ok(TimeUnit::Milliseconds),
            "us" => Ok(TimeUnit::Microseconds),
            _ => Err(LabError::Usage(format!(
                "`{s}` is not a time unit: s, ms or us"
            ))),
        }
    }
}

/// The lower-case tokens of a column name (`Gyro_Z[rad/s]` -> gyro, z,
/// rad, s): what a unit written into a name is read from.
fn tokens(name: &str) -> Vec<String> {
    name.split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|t| !t.is_empty())
        .map(str::to_ascii_lowercase)
        .collect()
}

/// The rate unit a column's name states, if it states one: `rad` (or
/// `rads`, `radps`, `rps`) is rad/s; `dph`, `degph` or `deg` followed by
/// `h`/`hr` is deg/h; `dps`, `degps` or `deg` followed by `s`/`sec` is
/// deg/s. A name that says nothing is None.
pub fn rate_unit_of_name(name: &str) -> Option<RateUnit> {
    let t = tokens(name);
    for (i, w) in t.iter().enumerate() {
        let next = t.get(i + 1).map(String::as_str);
        match w.as_str() {
            "rad" | "rads" | "radps" | "radpersec" | "rps" => return Some(RateUnit::RadPerS),
            "dph" | "degph" | "degperh" => return Some(RateUnit::DegPerH),
            "dps" | "degps" | "degpersec" => return Some(RateUnit::DegPerS),
            "deg" | "degs" => match next {
                Some("h" | "hr" | "hour") => return Some(RateUnit::DegPerH),
                Some("s" | "sec") => return Some(RateUnit::DegPerS),
                _ => {}
            },
            _ => {}
        }
    }
    None
}

/// The temperature unit a column's name states, if it states one: a
/// token `k` or `kelvin` (`T[K]`, `temp_k`), or `c`, `degc`, `celsius`.
pub fn temp_unit_of_name(name: &str) -> Option<TempUnit> {
    let t = tokens(name);
    if t.iter().any(|w| w == "kelvin" || w == "k") {
        return Some(TempUnit::Kelvin);
    }
    if t.iter()
        .any(|w| w == "c" || w == "degc" || w == "celsius" || w == "degreesc")
    {
        return Some(TempUnit::Celsius);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_convert_to_the_run_files() {
        assert!((RateUnit::RadPerS.to_dps() - 57.29577951308232).abs() < 1e-12);
        assert_eq!(RateUnit::DegPerH.to_dps() * 3600.0, 1.0);
        assert_eq!(TempUnit::Kelvin.to_c(293.15), 20.0);
        assert!((TempUnit::Fahrenheit.to_c(68.0) - 20.0).abs() < 1e-12);
        for (s, u) in [
            ("deg/s", RateUnit::DegPerS),
            ("rad/s", RateUnit::RadPerS),
            ("dph", RateUnit::DegPerH),
        ] {
            assert_eq!(s.parse::<RateUnit>().unwrap(), u);
        }
        assert!("mph".parse::<RateUnit>().is_err());
        assert_eq!("K".parse::<TempUnit>().unwrap(), TempUnit::Kelvin);
        assert_eq!("ms".parse::<TimeUnit>().unwrap().to_s(), 1e-3);
    }

    #[test]
    fn a_name_states_its_unit_or_nothing() {
        assert_eq!(rate_unit_of_name("gyro_z_rad_s"), Some(RateUnit::RadPerS));
        assert_eq!(rate_unit_of_name("Gyro Z [rad/s]"), Some(RateUnit::RadPerS));
        assert_eq!(rate_unit_of_name("omega_dph"), Some(RateUnit::DegPerH));
        assert_eq!(rate_unit_of_name("rate (deg/h)"), Some(RateUnit::DegPerH));
        assert_eq!(rate_unit_of_name("omega_dps"), Some(RateUnit::DegPerS));
        assert_eq!(rate_unit_of_name("gyro_z"), None);
        // "radiator" or "radius" are not "rad".
        assert_eq!(rate_unit_of_name("radiator_temp"), None);
        assert_eq!(temp_unit_of_name("T[K]"), Some(TempUnit::Kelvin));
        assert_eq!(temp_unit_of_name("temp_k"), Some(TempUnit::Kelvin));
        assert_eq!(temp_unit_of_name("heat_c"), Some(TempUnit::Celsius));
        assert_eq!(temp_unit_of_name("temperature"), None);
        assert_eq!(temp_unit_of_name("kp_gain"), None);
    }
}
