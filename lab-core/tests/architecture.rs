//! The shape of the lab's library (lab-core/src), checked on the source
//! text:
//!
//! - no import cycle, neither among the top-level modules (commands, data,
//!   sim, ...) nor among files: an edge is any `use crate::..`, `use super::..`,
//!   `use self::..`, `use <child>::..` and any path written inline
//!   (`crate::a::b::f()`, `super::x::Y`), resolved to the file that defines
//!   the module it names (inline `mod tests { .. }` blocks belong to their
//!   file);
//! - no source file of the repository over 800 lines;
//! - the run-file column names (`Column::ALL`) appear in string literals
//!   only in data/run_file.rs;
//! - the domain modules (everything but commands/, data/ and error.rs)
//!   neither parse arguments (clap), print, nor touch files, paths, the
//!   environment or the process; the commands read their inputs but
//!   neither print nor write;
//! - the command line (lab/src) has no import cycle either;
//! - no `Result<_, String>`;
//! - the same cycle and size rules for the dsp crate (dsp/src), whose
//!   blocks must not import the config that composes them.

// The checks read the source with architecture/scan.rs.
#[path = "architecture/scan.rs"]
mod scan;

use scan::{
    expand_use, find_cycle, graph, has_word, result_args, show, sources, sources_in, strip,
    top_level, Source,
};
use std::collections::BTreeSet;
use std::path::Path;

const MAX_LINES: usize = 800;

/// No cycle among the files of a crate's sources (`what` names them in
/// the message), nor among its top-level modules where `modules`.
fn assert_acyclic(what: &str, files: &[Source], modules: bool) {
    let g = graph(files);
    if modules {
        if let Some(c) = find_cycle(&top_level(&g)) {
            panic!("{what}: cycle among top-level modules: {}", c.join(" -> "));
        }
    }
    if let Some(c) = find_cycle(&g) {
        let names: Vec<String> = c.iter().map(|m| show(m)).collect();
        panic!("{what}: cycle among files: {}", names.join(" -> "));
    }
}

/// The sources of a sibling crate's `src/`, found.
fn crate_sources(dir: &str) -> Vec<Source> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let files = sources_in(&root);
    assert!(files.len() > 10, "sources not found at {}", root.display());
    files
}

#[test]
fn no_import_cycles() {
    assert_acyclic("lab-core", &sources(), true);
}

/// The dsp crate: no cycle among its modules or files (its files' length
/// is the repository's rule, `no_file_over_800_lines`).
#[test]
fn dsp_has_no_import_cycles() {
    assert_acyclic("dsp", &crate_sources("../dsp/src"), true);
}

/// The command line: no cycle among its files.
#[test]
fn cli_has_no_import_cycles() {
    assert_acyclic("lab", &crate_sources("../lab/src"), false);
}

/// Every source file of the repository (Rust, Python, shell, the
/// scripts without an extension under .ci/), build outputs and the
/// version control's own files aside.
fn repository_sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() {
            if !matches!(name, "target" | ".git" | "runs" | ".venv" | "__pycache__") {
                repository_sources(&p, out);
            }
        } else if p
            .extension()
            .is_some_and(|x| x == "rs" || x == "py" || x == "sh")
            || p.parent()
                .is_some_and(|d| d.file_name().is_some_and(|n| n == ".ci"))
        {
            out.push(p);
        }
    }
}

#[test]
fn no_file_over_800_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = vec![];
    repository_sources(&root, &mut files);
    assert!(files.len() > 300, "{} sources found", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|p| {
            let n = std::fs::read_to_string(p).ok()?.lines().count();
            (n > MAX_LINES).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "over {MAX_LINES} lines: {long:?}");
}

#[test]
fn no_result_with_string_errors() {
    for f in sources() {
        let (s, _) = strip(&f.text);
        let flat: String = s.chars().filter(|c| !c.is_whitespace()).collect();
        for args in result_args(&flat) {
            assert!(
                args.last()
                    .is_none_or(|e| e != "String" && e != "std::string::String"),
                "{}: Result<{}>",
                f.rel,
                args.join(", ")
            );
        }
    }
}

#[test]
fn run_file_columns_are_named_in_run_file_rs_only() {
    let names: Vec<&str> = gyro_lab_core::data::run_file::Column::ALL
        .iter()
        .map(|c| c.name())
        .collect();
    let mut found = vec![];
    for f in sources() {
        if f.rel == "data/run_file.rs" {
            continue;
        }
        let (_, literals) = strip(&f.text);
        for lit in &literals {
            for n in names.iter().filter(|n| has_word(lit, n)) {
                found.push(format!("{}: `{n}` in \"{lit}\"", f.rel));
            }
        }
    }
    assert!(found.is_empty(), "run-file columns spelled out: {found:#?}");
}

/// Files of the domains: all but the commands (commands/), the data files
/// (data/) and the error type.
fn is_domain(rel: &str) -> bool {
    !(rel.starts_with("commands/") || rel.starts_with("data/") || rel == "error.rs")
}

/// The commands read their inputs (a file, or a model's text) but neither
/// parse arguments, print, nor write: the CLI and Python do that.
#[test]
fn commands_neither_print_nor_write() {
    let files = sources();
    let commands: Vec<_> = files
        .iter()
        .filter(|f| f.rel.starts_with("commands/"))
        .collect();
    assert!(commands.len() > 10, "{} command files", commands.len());
    for f in commands {
        let (s, _) = strip(&f.text);
        let code = s.split("#[cfg(test)]").next().unwrap_or("");
        let flat: String = code.chars().filter(|c| !c.is_whitespace()).collect();
        for w in [
            "clap",
            "indicatif",
            "print",
            "println",
            "eprint",
            "eprintln",
        ] {
            assert!(!has_word(code, w), "{}: `{w}` in a command", f.rel);
        }
        for p in [
            "fs::write",
            "File::create",
            "atomic::write",
            "std::process",
            "std::env",
        ] {
            assert!(!flat.contains(p), "{}: `{p}` in a command", f.rel);
        }
    }
}

#[test]
fn domains_neither_parse_arguments_nor_print_nor_touch_files() {
    for f in sources().iter().filter(|f| is_domain(&f.rel)) {
        let (s, _) = strip(&f.text);
        // Unit tests may say what they find.
        let code = s.split("#[cfg(test)]").next().unwrap_or("");
        let flat: String = code.chars().filter(|c| !c.is_whitespace()).collect();
        for w in [
            "clap",
            "indicatif",
            "print",
            "println",
            "eprint",
            "eprintln",
            "Path",
            "PathBuf",
            "File",
        ] {
            assert!(!has_word(code, w), "{}: `{w}` in a domain module", f.rel);
        }
        for p in ["std::fs", "std::path", "std::env", "std::process"] {
            assert!(!flat.contains(p), "{}: `{p}` in a domain module", f.rel);
        }
    }
}

// The checker on small synthetic trees: it must see what it is meant to.

fn src(files: &[(&str, &str)]) -> Vec<Source> {
    files
        .iter()
        .map(|(r, t)| Source {
            rel: (*r).into(),
            text: (*t).into(),
        })
        .collect()
}

fn m(s: &str) -> Vec<String> {
    s.split("::").map(str::to_owned).collect()
}

#[test]
fn checker_finds_a_cycle_through_an_inline_path() {
    let files = src(&[
        ("lib.rs", "pub mod a;\npub mod b;\n"),
        ("a/mod.rs", "pub mod x;\n"),
        ("a/x.rs", "use crate::b::Y;\npub fn g() {}\n"),
        ("b.rs", "pub struct Y;\nfn f() { crate::a::x::g(); }\n"),
    ]);
    let g = graph(&files);
    assert!(g[&m("a::x")].contains(&m("b")), "{g:?}");
    assert!(g[&m("b")].contains(&m("a::x")), "{g:?}");
    let c = find_cycle(&g).expect("file cycle");
    assert!(c.contains(&m("b")) && c.contains(&m("a::x")), "{c:?}");
    let t = top_level(&g);
    assert!(find_cycle(&t).is_some(), "{t:?}");
}

#[test]
fn checker_finds_a_cycle_through_super_and_groups() {
    // mod.rs re-exports a child that imports mod.rs back.
    let files = src(&[
        ("lib.rs", "pub mod a;\n"),
        (
            "a/mod.rs",
            "pub mod x;\npub mod y;\npub use x::X;\npub struct Z;\n",
        ),
        ("a/x.rs", "use super::{y::Y, Z};\npub struct X;\n"),
        ("a/y.rs", "pub struct Y;\n"),
    ]);
    let g = graph(&files);
    assert!(g[&m("a")].contains(&m("a::x")), "{g:?}");
    assert!(g[&m("a::x")].contains(&m("a::y")), "{g:?}");
    assert!(g[&m("a::x")].contains(&m("a")), "{g:?}");
    assert!(find_cycle(&g).is_some());
    // One level: no cycle among top-level modules.
    assert!(find_cycle(&top_level(&g)).is_none());
}

#[test]
fn checker_ignores_tests_modules_comments_and_strings() {
    let files = src(&[
        ("lib.rs", "pub mod a;\npub mod b;\n"),
        (
            "a.rs",
            "use crate::b::f;\n// crate::b is fine; so is \"crate::b\" below\n\
             pub fn g() { let _ = \"use crate::a::h;\"; f(); }\n\
             #[cfg(test)]\nmod tests {\n    use super::*;\n    #[test]\n    fn t() { g(); }\n}\n",
        ),
        (
            "b.rs",
            "/* crate::a::g() would close a cycle */\npub fn f() -> char { '{' }\n\
             mod inner { use super::super::b::f as _; }\n",
        ),
    ]);
    let g = graph(&files);
    assert_eq!(g[&m("a")], BTreeSet::from([m("b")]), "{g:?}");
    assert!(g[&m("b")].is_empty(), "{g:?}");
    assert!(find_cycle(&g).is_none());
}

#[test]
fn checker_follows_inline_paths_through_child_modules() {
    // mod.rs calls into its child, which imports mod.rs back.
    let files = src(&[
        ("lib.rs", "pub mod a;\n"),
        (
            "a/mod.rs",
            "pub mod r;\npub fn names() {}\nfn run() { r::draw(); }\n",
        ),
        (
            "a/r.rs",
            "use super::names;\npub fn draw() { names(); Vec::<u8>::new(); }\n",
        ),
    ]);
    let g = graph(&files);
    assert!(g[&m("a")].contains(&m("a::r")), "{g:?}");
    assert!(g[&m("a::r")].contains(&m("a")), "{g:?}");
    assert!(find_cycle(&g).is_some());
}

#[test]
fn checker_reads_main_through_the_library_name() {
    let files = src(&[
        ("lib.rs", "pub mod cli;\n"),
        ("cli.rs", "pub fn run() {}\n"),
        ("main.rs", "use gyro_lab::cli;\nfn main() { cli::run(); }\n"),
    ]);
    let g = graph(&files);
    assert!(g[&vec!["<main>".to_owned()]].contains(&m("cli")), "{g:?}");
}

#[test]
fn checker_reads_result_types() {
    let flat = "fnf()->Result<(Vec<f64>,Option<u8>),String>{}fng()->Result<u8,LabError>";
    let a = result_args(flat);
    assert_eq!(
        a[0],
        vec!["(Vec<f64>,Option<u8>)".to_owned(), "String".to_owned()]
    );
    assert_eq!(a[1], vec!["u8".to_owned(), "LabError".to_owned()]);
}

/// The graph, for a reader: `cargo test --test architecture --
/// --ignored --nocapture print_graph`.
#[test]
#[ignore]
fn print_graph() {
    let g = graph(&sources());
    for (a, bs) in top_level(&g) {
        println!("{a} -> {bs:?}");
    }
    for (a, bs) in &g {
        let v: Vec<String> = bs.iter().map(|m| show(m)).collect();
        println!("  {} -> {}", show(a), v.join(", "));
    }
}

#[test]
fn checker_expands_use_trees() {
    let p = expand_use(" crate::{a::{b, c as d}, e::self, f::*}");
    let want: Vec<Vec<String>> = ["crate::a::b", "crate::a::c", "crate::e", "crate::f"]
        .iter()
        .map(|s| m(s))
        .collect();
    assert_eq!(p, want);
}
