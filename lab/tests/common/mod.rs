//! What the end-to-end tests share: running the built `gyro-lab`, a scratch
//! directory, the JSON line. (Each test crate uses its own subset.)
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// Runs gyro-lab: (exit status, stdout, stderr).
pub fn lab(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gyro-lab"))
        .args(args)
        .output()
        .expect("run gyro-lab");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs gyro-lab, which must succeed (else the test fails with its
/// stderr): its stdout.
pub fn lab_ok(args: &[&str]) -> String {
    let (code, stdout, err) = lab(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    stdout
}

/// A scratch directory of this test process, `gyro-lab-<name>-<pid>`.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gyro-lab-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The JSON object on the last line of stdout. A key written twice in one
/// object fails the test: a reader would keep one of the two silently.
pub fn json(stdout: &str) -> serde_json::Value {
    let line = stdout.lines().last().unwrap();
    serde_json::from_str::<UniqueKeys>(line).unwrap();
    serde_json::from_str(line).unwrap()
}

/// Any JSON value, deserialised only to check that no object repeats a key.
struct UniqueKeys;

impl<'de> serde::Deserialize<'de> for UniqueKeys {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueKeysVisitor)
    }
}

struct UniqueKeysVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueKeysVisitor {
    type Value = UniqueKeys;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_i64<E>(self, _: i64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_u64<E>(self, _: u64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_f64<E>(self, _: f64) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_str<E>(self, _: &str) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_unit<E>(self) -> Result<UniqueKeys, E> {
        Ok(UniqueKeys)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> Result<UniqueKeys, A::Error> {
        while a.next_element::<UniqueKeys>()?.is_some() {}
        Ok(UniqueKeys)
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut a: A) -> Result<UniqueKeys, A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(k) = a.next_key::<String>()? {
            assert!(
                seen.insert(k.clone()),
                "the JSON writes the key `{k}` twice"
            );
            a.next_value::<UniqueKeys>()?;
        }
        Ok(UniqueKeys)
    }
}
