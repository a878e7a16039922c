//! Reading lab/src as text for the architecture checks: the files, their
//! text without comments and literals, the paths each names, and the
//! import graph among files and among top-level modules.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source file: its path under src/ ("model/effects.rs") and text.
pub struct Source {
    pub rel: String,
    pub text: String,
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

pub fn sources() -> Vec<Source> {
    sources_in(&src_dir())
}

/// The `.rs` files below `root` (another crate's `src`, e.g. the dsp's).
pub fn sources_in(root: &Path) -> Vec<Source> {
    let root = root.to_path_buf();
    let mut files = vec![];
    rust_files(&root, &mut files);
    files.sort();
    files
        .iter()
        .map(|p| Source {
            rel: p
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/"),
            text: std::fs::read_to_string(p).unwrap(),
        })
        .collect()
}

/// The module path of a file: lib.rs is the crate root, main.rs the
/// binary (a root of its own, reaching the library as `gyro_lab::`).
pub fn module_of(rel: &str) -> Vec<String> {
    if rel == "lib.rs" {
        return vec![];
    }
    if rel == "main.rs" {
        return vec!["<main>".into()];
    }
    let mut segs: Vec<String> = rel.split('/').map(str::to_owned).collect();
    let last = segs.pop().unwrap();
    if last != "mod.rs" {
        segs.push(last.trim_end_matches(".rs").to_owned());
    }
    segs
}

/// The text with comments, string and character literals blanked out
/// (newlines kept, so line counts and positions hold); the literals
/// themselves are returned apart.
pub fn strip(text: &str) -> (String, Vec<String>) {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut lits = vec![];
    let mut i = 0;
    let blank = |ch: char| if ch == '\n' { '\n' } else { ' ' };
    while i < c.len() {
        // Line comment.
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
            continue;
        }
        // Block comment (nested).
        if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
            continue;
        }
        // Raw string r"..", r#".."#, br"..".
        let ident_before = i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_');
        if !ident_before && (c[i] == 'r' || (c[i] == 'b' && c.get(i + 1) == Some(&'r'))) {
            let mut j = if c[i] == 'b' { i + 2 } else { i + 1 };
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) == Some(&'"') {
                let mut lit = String::new();
                j += 1;
                'raw: while j < c.len() {
                    if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                        j += 1 + hashes;
                        break 'raw;
                    }
                    lit.push(c[j]);
                    j += 1;
                }
                for &ch in &c[i..j.min(c.len())] {
                    out.push(blank(ch));
                }
                lits.push(lit);
                i = j;
                continue;
            }
        }
        // String.
        if c[i] == '"' {
            let mut lit = String::new();
            out.push(' ');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' && i + 1 < c.len() {
                    lit.push(c[i]);
                    lit.push(c[i + 1]);
                    out.push(blank(c[i]));
                    out.push(blank(c[i + 1]));
                    i += 2;
                    continue;
                }
                lit.push(c[i]);
                out.push(blank(c[i]));
                i += 1;
            }
            out.push(' ');
            i += 1;
            lits.push(lit);
            continue;
        }
        // Character literal ('x', '\n', '\''), not a lifetime ('a).
        if c[i] == '\'' {
            let end = if c.get(i + 1) == Some(&'\\') {
                (i + 2..c.len()).find(|&k| c[k] == '\'')
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            if let Some(e) = end {
                for _ in i..=e {
                    out.push(' ');
                }
                i = e + 1;
                continue;
            }
        }
        out.push(c[i]);
        i += 1;
    }
    (out, lits)
}

/// A use tree without whitespace and without renames (`x as y` -> `x`).
pub fn without_renames(tree: &str) -> String {
    let mut toks: Vec<String> = vec![];
    let mut word = String::new();
    for ch in tree.chars() {
        if ch.is_alphanumeric() || ch == '_' {
            word.push(ch);
            continue;
        }
        if !word.is_empty() {
            toks.push(std::mem::take(&mut word));
        }
        if !ch.is_whitespace() {
            toks.push(ch.to_string());
        }
    }
    if !word.is_empty() {
        toks.push(word);
    }
    let mut out = String::new();
    let mut k = 0;
    while k < toks.len() {
        if toks[k] == "as" {
            k += 2;
            continue;
        }
        out.push_str(&toks[k]);
        k += 1;
    }
    out
}

/// Expands a use tree ("crate::{a::b, c::{d, e}}") into its paths.
pub fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn split_top(s: &str) -> Vec<&str> {
        let (mut depth, mut start, mut parts) = (0, 0, vec![]);
        for (i, ch) in s.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts
    }
    fn expand(t: &str) -> Vec<Vec<String>> {
        if t.is_empty() {
            return vec![];
        }
        let segs = |s: &str| -> Vec<String> {
            s.split("::")
                .filter(|x| !x.is_empty() && *x != "*")
                .map(str::to_owned)
                .collect()
        };
        let Some(open) = t.find('{') else {
            return vec![segs(t)];
        };
        let prefix = segs(&t[..open]);
        let inner = &t[open + 1..t.rfind('}').unwrap_or(t.len())];
        let mut out = vec![];
        for part in split_top(inner) {
            for p in expand(part) {
                // `self` inside a group names the prefix itself.
                let mut full = prefix.clone();
                full.extend(p.into_iter().filter(|s| s != "self"));
                out.push(full);
            }
        }
        out
    }
    expand(&without_renames(tree))
}

/// Every path a file names (in `use` and inline, two segments or more),
/// with the module (file or inline) it is named from.
pub fn named_paths(stripped: &str, file_module: &[String]) -> Vec<(Vec<String>, Vec<String>)> {
    let c: Vec<char> = stripped.chars().collect();
    let is_id = |ch: char| ch.is_alphanumeric() || ch == '_';
    let word_at = |i: usize| -> Option<String> {
        if i > 0 && is_id(c[i - 1]) {
            return None;
        }
        let mut j = i;
        while j < c.len() && is_id(c[j]) {
            j += 1;
        }
        (j > i).then(|| c[i..j].iter().collect())
    };
    // Inline modules: (name, brace depth inside it).
    let mut stack: Vec<(String, i32)> = vec![];
    let mut depth = 0;
    let mut pending_mod: Option<String> = None;
    let mut out = vec![];
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch == '{' {
            depth += 1;
            if let Some(m) = pending_mod.take() {
                stack.push((m, depth));
            }
            i += 1;
            continue;
        }
        if ch == '}' {
            if stack.last().is_some_and(|s| s.1 == depth) {
                stack.pop();
            }
            depth -= 1;
            i += 1;
            continue;
        }
        if ch == ';' {
            pending_mod = None;
        }
        let Some(w) = word_at(i) else {
            i += 1;
            continue;
        };
        let here: Vec<String> = file_module
            .iter()
            .cloned()
            .chain(stack.iter().map(|s| s.0.clone()))
            .collect();
        if w == "mod" {
            let mut j = i + 3;
            while j < c.len() && c[j].is_whitespace() {
                j += 1;
            }
            if let Some(name) = word_at(j) {
                pending_mod = Some(name);
            }
            i += 3;
            continue;
        }
        if w == "use" {
            let end = (i..c.len()).find(|&k| c[k] == ';').unwrap_or(c.len());
            let tree: String = c[i + 3..end].iter().collect();
            for p in expand_use(&tree) {
                out.push((here.clone(), p));
            }
            i = end;
            continue;
        }
        // Any path written inline: `crate::a::f()`, `super::x::Y`, and
        // `child::f()` through a child module (resolved in `graph`; paths
        // through types or other crates lead nowhere there).
        let mut j = i;
        let mut segs = vec![];
        while let Some(s) = word_at(j) {
            j += s.chars().count();
            segs.push(s);
            if c.get(j) == Some(&':') && c.get(j + 1) == Some(&':') {
                j += 2;
            } else {
                break;
            }
        }
        if segs.len() > 1 {
            out.push((here.clone(), segs));
        }
        i = j.max(i + 1);
    }
    out
}

/// The import graph of a set of files: file module -> the file modules it
/// names. Paths to items resolve to the deepest module of the path that
/// exists (a file or an inline module, which counts as its file).
pub fn graph(files: &[Source]) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let file_mods: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&f.rel)).collect();
    // Inline modules, mapped to their file.
    let mut owner: BTreeMap<Vec<String>, Vec<String>> =
        file_mods.iter().map(|m| (m.clone(), m.clone())).collect();
    let mut parsed = vec![];
    for f in files {
        let m = module_of(&f.rel);
        let (stripped, _) = strip(&f.text);
        let paths = named_paths(&stripped, &m);
        for (here, _) in &paths {
            owner.entry(here.clone()).or_insert_with(|| m.clone());
        }
        // Inline modules declared without uses inside are not needed: a
        // path into them resolves to their file anyway.
        parsed.push((m, paths));
    }
    let mut g: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (m, paths) in parsed {
        g.entry(m.clone()).or_default();
        for (here, p) in paths {
            let mut base: Vec<String> = match p[0].as_str() {
                "crate" | "gyro_lab" => vec![],
                "self" => here.clone(),
                "super" => here.clone(),
                _ => {
                    // A relative path through a child module of `here`.
                    let mut child = here.clone();
                    child.push(p[0].clone());
                    if !owner.contains_key(&child) {
                        continue;
                    }
                    here.clone()
                }
            };
            let mut rest = &p[..];
            match p[0].as_str() {
                "crate" | "gyro_lab" | "self" => rest = &p[1..],
                "super" => {
                    while rest.first().is_some_and(|s| s == "super") {
                        base.pop();
                        rest = &rest[1..];
                    }
                }
                _ => {}
            }
            if m == vec!["<main>".to_owned()] && p[0] != "gyro_lab" {
                continue;
            }
            for s in rest {
                let mut next = base.clone();
                next.push(s.clone());
                if owner.contains_key(&next) {
                    base = next;
                } else {
                    break;
                }
            }
            let target = owner.get(&base).cloned().unwrap_or(base);
            if target != m {
                g.entry(m.clone()).or_default().insert(target);
            }
        }
    }
    g
}

/// The same graph at the granularity of top-level modules.
pub fn top_level(
    g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
) -> BTreeMap<String, BTreeSet<String>> {
    let top = |m: &Vec<String>| m.first().cloned().unwrap_or_else(|| "<root>".into());
    let mut t: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, bs) in g {
        let ta = top(a);
        t.entry(ta.clone()).or_default();
        for b in bs {
            let tb = top(b);
            if tb != ta {
                t.entry(ta.clone()).or_default().insert(tb);
            }
        }
    }
    t
}

/// One cycle of the graph, if there is one.
pub fn find_cycle<N: Ord + Clone>(g: &BTreeMap<N, BTreeSet<N>>) -> Option<Vec<N>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit<N: Ord + Clone>(
        n: &N,
        g: &BTreeMap<N, BTreeSet<N>>,
        mark: &mut BTreeMap<N, Mark>,
        path: &mut Vec<N>,
    ) -> Option<Vec<N>> {
        mark.insert(n.clone(), Mark::Open);
        path.push(n.clone());
        for m in g.get(n).into_iter().flatten() {
            match mark.get(m).copied().unwrap_or(Mark::New) {
                Mark::Open => {
                    let from = path.iter().position(|x| x == m).unwrap();
                    let mut cyc = path[from..].to_vec();
                    cyc.push(m.clone());
                    return Some(cyc);
                }
                Mark::New => {
                    if let Some(c) = visit(m, g, mark, path) {
                        return Some(c);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        mark.insert(n.clone(), Mark::Done);
        None
    }
    let mut mark = BTreeMap::new();
    for n in g.keys() {
        if mark.get(n).copied().unwrap_or(Mark::New) == Mark::New {
            if let Some(c) = visit(n, g, &mut mark, &mut vec![]) {
                return Some(c);
            }
        }
    }
    None
}

pub fn show(m: &[String]) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

/// The generic arguments of every `Result<..>` written in `flat` (the
/// text without whitespace).
pub fn result_args(flat: &str) -> Vec<Vec<String>> {
    let c: Vec<char> = flat.chars().collect();
    let mut out = vec![];
    let mut from = 0;
    while let Some(k) = flat[from..].find("Result<") {
        let start = flat[..from + k].chars().count() + "Result<".len();
        let (mut depth, mut arg, mut args) = (1, String::new(), vec![]);
        let mut i = start;
        while i < c.len() && depth > 0 {
            match c[i] {
                '<' | '(' | '[' => depth += 1,
                '>' if i > 0 && c[i - 1] == '-' => {}
                '>' | ')' | ']' => depth -= 1,
                ',' if depth == 1 => {
                    args.push(std::mem::take(&mut arg));
                    i += 1;
                    continue;
                }
                _ => {}
            }
            if depth > 0 {
                arg.push(c[i]);
            }
            i += 1;
        }
        args.push(arg);
        out.push(args);
        from += k + "Result<".len();
    }
    out
}

/// Whether `word` stands in `text` as a whole identifier.
pub fn has_word(text: &str, word: &str) -> bool {
    let is_id = |c: char| c.is_alphanumeric() || c == '_';
    text.match_indices(word).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + word.len()..].chars().next();
        !before.is_some_and(is_id) && !after.is_some_and(is_id)
    })
}
