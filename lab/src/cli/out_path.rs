//! What `--out` may name. One rule for every command: it never names a
//! file the command reads; an existing output is replaced only with
//! `--force`, and never by a file of another kind; a command whose `--out`
//! is a file refuses a folder and a name of the wrong kind, one whose
//! `--out` is a folder refuses a file and a file's name. Each refusal is
//! one sentence at the path, exit 2, before anything is computed or
//! written.

use gyro_lab_core::error::LabError;
use std::path::{Path, PathBuf};

/// The kinds of file the lab writes, as far as one can tell them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A CSV data file.
    Csv,
    /// A TOML file with `kind = "..."` (a coefficient set, a model).
    Toml(&'static str),
    /// An HTML report.
    Html,
    /// A raw capture.
    Binary,
    /// A JSON summary.
    Json,
}

impl FileKind {
    fn describe(self) -> String {
        match self {
            FileKind::Csv => "a CSV data file".into(),
            FileKind::Toml(k) => format!("a `{k}` TOML file"),
            FileKind::Html => "an HTML report".into(),
            FileKind::Binary => "a raw capture".into(),
            FileKind::Json => "a JSON file".into(),
        }
    }

    fn extensions(self) -> &'static [&'static str] {
        match self {
            FileKind::Csv => &["csv", "tsv", "txt"],
            FileKind::Toml(_) => &["toml"],
            FileKind::Html => &["html", "htm"],
            FileKind::Binary => &["bin"],
            FileKind::Json => &["json"],
        }
    }
}

/// What an existing file is: its kind where one can tell, else a word.
fn sniff(path: &Path) -> Result<FileKind, LabError> {
    let mut head = vec![0u8; 4096];
    let n = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
        .map_err(|e| LabError::input(path, format!("cannot be read ({e})")))?;
    let head = &head[..n];
    if head.contains(&0) {
        return Ok(FileKind::Binary);
    }
    let text = String::from_utf8_lossy(head);
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with("<!DOCTYPE html") || t.starts_with("<html") {
        return Ok(FileKind::Html);
    }
    if t.starts_with('{') {
        return Ok(FileKind::Json);
    }
    let lines: Vec<&str> = t
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .collect();
    let kind = lines.iter().find_map(|l| {
        let v = l.strip_prefix("kind")?.trim_start().strip_prefix('=')?;
        Some(v.trim().trim_matches('"').to_owned())
    });
    if let Some(k) = kind {
        return Ok(FileKind::Toml(match k.as_str() {
            "rlg_thermal" => "rlg_thermal",
            "fog_scale_factor" => "fog_scale_factor",
            "gyro_model" => "gyro_model",
            _ => "unknown",
        }));
    }
    // The first line that is not a comment: a header row is a CSV's.
    match lines.first() {
        Some(l) if !l.contains([',', ';', '\t']) && l.contains('=') => {
            Ok(FileKind::Toml("unknown"))
        }
        _ => Ok(FileKind::Csv),
    }
}

/// Whether `a` and `b` are one file (the same inode, whatever the names).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::MetadataExt;
                x.dev() == y.dev() && x.ino() == y.ino()
            }
            #[cfg(not(unix))]
            {
                let _ = (x, y);
                std::fs::canonicalize(a).ok() == std::fs::canonicalize(b).ok()
            }
        }
        _ => false,
    }
}

/// An output file the command writes: refused where it is an input, or
/// exists without `force`, or exists as another kind.
fn check_one(
    out: &Path,
    kind: FileKind,
    inputs: &[(&str, &Path)],
    force: bool,
) -> Result<(), LabError> {
    for (flag, input) in inputs {
        if same_file(out, input) {
            return Err(LabError::input(
                out,
                format!(
                    "this is the file {flag} reads: the output would replace its input; write it elsewhere"
                ),
            ));
        }
    }
    if out.is_dir() {
        return Err(LabError::input(
            out,
            format!("is a folder, where {} is to be written", kind.describe()),
        ));
    }
    if !out.exists() {
        return Ok(());
    }
    let found = sniff(out)?;
    if found != kind {
        return Err(LabError::input(
            out,
            format!(
                "exists and is {}, not {}: not replaced{}",
                found.describe(),
                kind.describe(),
                if force { ", even with --force" } else { "" }
            ),
        ));
    }
    if !force {
        return Err(LabError::input(out, "exists: --force replaces it"));
    }
    Ok(())
}

/// A command whose `--out` is a file of `kind`, with `beside` written next
/// to it (the report). `command` names the command in the messages.
pub fn file(
    command: &str,
    out: &Path,
    kind: FileKind,
    beside: &[(PathBuf, FileKind)],
    inputs: &[(&str, &Path)],
    force: bool,
) -> Result<(), LabError> {
    if out.is_dir() {
        let e = kind.extensions()[0];
        return Err(LabError::input(
            out,
            format!(
                "is a folder; `--out` of {command} is a file ({}), e.g. {}",
                kind.describe(),
                out.join(format!("out.{e}")).display()
            ),
        ));
    }
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !ext
        .as_deref()
        .is_some_and(|e| kind.extensions().contains(&e))
    {
        return Err(LabError::input(
            out,
            format!(
                "`--out` of {command} is {}: name it *.{}",
                kind.describe(),
                kind.extensions()[0]
            ),
        ));
    }
    check_one(out, kind, inputs, force)?;
    for (p, k) in beside {
        check_one(p, *k, inputs, force)?;
    }
    Ok(())
}

/// A command whose `--out` is a folder it writes `files` in ([`make`]
/// makes it once there is something to write).
pub fn folder(
    command: &str,
    out: &Path,
    files: &[(&str, FileKind)],
    inputs: &[(&str, &Path)],
    force: bool,
) -> Result<(), LabError> {
    let names: Vec<&str> = files.iter().map(|f| f.0).collect();
    let what = format!("a folder (it writes {} in it)", names.join(", "));
    if out.exists() && !out.is_dir() {
        return Err(LabError::input(
            out,
            format!("is a file; `--out` of {command} is {what}"),
        ));
    }
    let looks_like_file = out.extension().is_some_and(|e| {
        matches!(
            e.to_string_lossy().to_ascii_lowercase().as_str(),
            "toml" | "csv" | "tsv" | "html" | "htm" | "json" | "txt" | "bin"
        )
    });
    if !out.exists() && looks_like_file {
        return Err(LabError::input(
            out,
            format!("looks like a file's name; `--out` of {command} is {what}"),
        ));
    }
    for (name, kind) in files {
        check_one(&out.join(name), *kind, inputs, force)?;
    }
    Ok(())
}

/// Makes an output folder (with its parents).
pub fn make(out: &Path) -> Result<(), LabError> {
    std::fs::create_dir_all(out)
        .map_err(|e| LabError::input(out, format!("cannot make the folder: {e}")))
}

/// The path of the report written beside `out` (`c.toml` -> `c.html`).
pub fn report_beside(out: &Path) -> PathBuf {
    out.with_extension("html")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("gyro-lab-out-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn an_output_never_replaces_an_input_or_an_unasked_file() {
        let d = scratch("file");
        let run = d.join("c.csv");
        std::fs::write(&run, "time,gyro\n0,1\n").unwrap();
        let toml = FileKind::Toml("fog_scale_factor");
        let input = [("--data", run.as_path())];
        // The input named as the output, by any name.
        let e = file("fit", &run, FileKind::Csv, &[], &input, true).unwrap_err();
        assert!(e.to_string().contains("--data reads"), "{e}");
        // A TOML output named .csv; a folder; a folder's file.
        assert!(file("fit", &d.join("x.csv"), toml, &[], &input, false).is_err());
        assert!(file("fit", &d, toml, &[], &input, false)
            .unwrap_err()
            .to_string()
            .contains("is a folder"));
        let out = d.join("sf.toml");
        assert!(file("fit", &out, toml, &[], &input, false).is_ok());
        std::fs::write(&out, "kind = \"fog_scale_factor\"\n").unwrap();
        assert!(file("fit", &out, toml, &[], &input, false)
            .unwrap_err()
            .to_string()
            .contains("--force"));
        assert!(file("fit", &out, toml, &[], &input, true).is_ok());
        // Another kind of file under the name: not even with --force.
        std::fs::write(&out, "time,gyro\n").unwrap();
        assert!(file("fit", &out, toml, &[], &input, true)
            .unwrap_err()
            .to_string()
            .contains("not replaced"));
        // A folder command refuses a file and a file's name.
        assert!(folder(
            "discover",
            &run,
            &[("model.toml", FileKind::Toml("gyro_model"))],
            &input,
            false
        )
        .is_err());
        let named = d.join("mymodel.toml");
        assert!(folder(
            "discover",
            &named,
            &[("model.toml", FileKind::Toml("gyro_model"))],
            &input,
            false
        )
        .is_err());
        assert!(!named.exists());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
