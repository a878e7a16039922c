//! What a capture that went through a lossy path (a pty, a damaging relay)
//! kept of the clean stream, found without the decoder under test: each of
//! the clean capture's frames is looked for, byte for byte and in order, in
//! the bytes the recorder received. A frame found is intact; one not found
//! never reached the recorder whole, whoever lost it.
//!
//! The recorder is then judged against that truth: it must report exactly
//! the frames not found as lost, keep every frame found, and write the rows
//! the clean capture's rows are (the angle of every row; every column of a
//! row whose frame and the one before arrived).

use anyhow::{bail, Context, Result};
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// Frame length on the wire (docs/frame.md).
pub const FRAME: usize = 86;

/// How far past the last frame found the next one is looked for: more than
/// any garbage the paths insert (the relay's burst is 300 bytes).
const LOOKAHEAD: usize = 16 * 1024;

/// The clean capture split into its frames (the file path writes whole
/// frames, one after another, from the first byte).
pub fn frames(clean: &[u8]) -> Result<Vec<&[u8]>> {
    if clean.is_empty() || !clean.len().is_multiple_of(FRAME) {
        bail!(
            "the clean capture is {} bytes, not a whole number of {FRAME}-byte frames",
            clean.len()
        );
    }
    let f: Vec<&[u8]> = clean.chunks_exact(FRAME).collect();
    if let Some(k) = f.iter().position(|f| f[..2] != [0xA5, 0x5A]) {
        bail!("the clean capture's frame {k} does not start with the sync word");
    }
    Ok(f)
}

/// For each clean frame, whether it is in `got` intact, in order.
pub fn intact(clean: &[&[u8]], got: &[u8]) -> Vec<bool> {
    let mut at = 0usize;
    clean
        .iter()
        .map(|f| {
            let end = got.len().min(at + LOOKAHEAD + FRAME);
            match got
                .get(at..end)
                .and_then(|w| w.windows(FRAME).position(|x| x == *f))
            {
                Some(p) => {
                    at += p + FRAME;
                    true
                }
                None => false,
            }
        })
        .collect()
}

/// A run file's header and data rows (its `#` comment differs by source).
struct RunFile {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl RunFile {
    fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header = lines
            .next()
            .with_context(|| format!("{}: no header", path.display()))?
            .split(',')
            .map(String::from)
            .collect();
        let rows = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        Ok(Self { header, rows })
    }

    fn col(&self, name: &str) -> Result<usize> {
        self.header
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("no column {name}"))
    }
}

/// The recorder's account of a capture against the truth.
pub struct Verdict {
    /// The recorder did exactly what the bytes it received allow.
    pub exact: bool,
    /// Clean frames the recorder never received whole (by sequence number).
    pub not_received: Vec<u64>,
    /// The first thing that differs, if any, in words a person can act on.
    pub first_difference: Option<String>,
}

/// Judges a record (`dir`: raw.bin, fog.csv, rlg.csv; `json`: its JSON
/// line) against the clean capture `clean_bin` and its run files in
/// `clean_dir`.
pub fn judge(
    clean_bin: &Path,
    clean_dir: &Path,
    dir: &Path,
    json: &serde_json::Value,
) -> Result<Verdict> {
    let clean_bytes = std::fs::read(clean_bin)?;
    let clean = frames(&clean_bytes)?;
    let got = std::fs::read(dir.join("raw.bin"))?;
    let ok = intact(&clean, &got);
    let (cf, cr) = (
        RunFile::read(&clean_dir.join("fog.csv"))?,
        RunFile::read(&clean_dir.join("rlg.csv"))?,
    );
    let (rf, rr) = (
        RunFile::read(&dir.join("fog.csv"))?,
        RunFile::read(&dir.join("rlg.csv"))?,
    );
    if cf.rows.len() != clean.len() || cr.rows.len() != clean.len() {
        bail!(
            "the clean run files have {} and {} rows for {} frames",
            cf.rows.len(),
            cr.rows.len(),
            clean.len()
        );
    }
    let seq_col = cf.col("seq")?;
    let angle_col = cf.col("angle_deg")?;
    let seq = |r: &Vec<String>| r.get(seq_col).and_then(|s| s.parse::<u64>().ok());
    let clean_seq: Vec<u64> = cf
        .rows
        .iter()
        .map(|r| seq(r).context("a clean row without its sequence number"))
        .collect::<Result<_>>()?;
    let index: HashMap<u64, usize> = clean_seq.iter().enumerate().map(|(i, &s)| (s, i)).collect();
    let not_received: Vec<u64> = clean_seq
        .iter()
        .zip(&ok)
        .filter(|(_, &k)| !k)
        .map(|(&s, _)| s)
        .collect();
    let mut diffs: Vec<String> = vec![];
    // What the recorder can know was lost: the frames missing between the
    // first and the last it received (a loss at either end has no
    // neighbour to show it).
    let (first, last) = (ok.iter().position(|&k| k), ok.iter().rposition(|&k| k));
    let expected_lost: BTreeSet<u64> = match (first, last) {
        (Some(a), Some(b)) => (a..=b).filter(|&i| !ok[i]).map(|i| clean_seq[i]).collect(),
        _ => BTreeSet::new(),
    };
    let reported_lost: BTreeSet<u64> = json["lost_frames"]
        .as_array()
        .into_iter()
        .flatten()
        .flat_map(|g| {
            let a = g["after_seq"].as_u64().unwrap_or(0);
            let b = g["before_seq"].as_u64().unwrap_or(0);
            a + 1..b
        })
        .collect();
    if reported_lost != expected_lost {
        let extra: Vec<_> = reported_lost.difference(&expected_lost).collect();
        let missed: Vec<_> = expected_lost.difference(&reported_lost).collect();
        diffs.push(format!(
            "lost frames reported {extra:?} that arrived intact, not reported {missed:?} that did not"
        ));
    }
    let kept = ok.iter().filter(|&&k| k).count() as u64;
    if json["frames"].as_u64() != Some(kept) {
        diffs.push(format!(
            "{} frames kept where {kept} arrived intact",
            json["frames"]
        ));
    }
    if rf.header != cf.header || rr.header != cr.header {
        diffs.push("the run files' headers differ".into());
    }
    if rf.rows.len() != rr.rows.len() {
        diffs.push(format!(
            "{} FOG rows but {} RLG rows",
            rf.rows.len(),
            rr.rows.len()
        ));
    }
    for (k, (row, rlg)) in rf.rows.iter().zip(&rr.rows).enumerate() {
        let Some(i) = seq(row).and_then(|s| index.get(&s).copied()) else {
            diffs.push(format!(
                "FOG row {k}: a sequence number the board never sent"
            ));
            break;
        };
        let s = clean_seq[i];
        // Angles are cumulative: every row's equals the clean one's.
        if row.get(angle_col) != cf.rows[i].get(angle_col) {
            diffs.push(format!(
                "frame seq {s}: angle_deg {} against {}",
                row.get(angle_col).map_or("-", String::as_str),
                cf.rows[i][angle_col]
            ));
            break;
        }
        // A row right after a gap spans it (its rates differ on purpose).
        if i > 0 && !ok[i - 1] {
            continue;
        }
        let d = first_cell_difference(&cf.header, row, &cf.rows[i])
            .or_else(|| first_cell_difference(&cr.header, rlg, &cr.rows[i]));
        if let Some(d) = d {
            diffs.push(format!("frame seq {s}: {d}"));
            break;
        }
    }
    Ok(Verdict {
        exact: diffs.is_empty(),
        not_received,
        first_difference: diffs.into_iter().next(),
    })
}

fn first_cell_difference(header: &[String], got: &[String], want: &[String]) -> Option<String> {
    if got.len() != want.len() {
        return Some(format!("{} cells against {}", got.len(), want.len()));
    }
    header
        .iter()
        .zip(got.iter().zip(want))
        .find(|(_, (a, b))| a != b)
        .map(|(h, (a, b))| format!("{h} {a} against {b}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream(n: usize) -> Vec<u8> {
        (0..n)
            .flat_map(|k| {
                let mut f = vec![0u8; FRAME];
                f[0] = 0xA5;
                f[1] = 0x5A;
                f[4] = k as u8;
                f[5] = (k >> 8) as u8;
                f[20] = (k * 7) as u8;
                f
            })
            .collect()
    }

    /// Frames dropped, damaged and separated by garbage are found exactly:
    /// the truth the recorder is judged by.
    #[test]
    fn intact_frames_are_found_in_order_through_damage() {
        let clean = stream(50);
        let frames = super::frames(&clean).unwrap();
        let mut got = vec![];
        for (k, f) in frames.iter().enumerate() {
            match k {
                3 => continue,
                7 => {
                    let mut g = f.to_vec();
                    g[30] ^= 4;
                    got.extend(g);
                }
                11 => {
                    got.extend([0xA5, 0x5A, 4, 82, 9, 9]);
                    got.extend(*f);
                }
                20 => got.extend(&f[..40]),
                _ => got.extend(*f),
            }
        }
        let ok = intact(&frames, &got);
        let lost: Vec<usize> = (0..50).filter(|&k| !ok[k]).collect();
        assert_eq!(lost, vec![3, 7, 20]);
        assert!(intact(&frames, &clean).iter().all(|&k| k));
        assert!(super::frames(&clean[1..]).is_err());
    }

    /// The judge passes a record that lost what its bytes lack and says so
    /// exactly, and names the first frame whose words differ.
    #[test]
    fn the_judge_names_the_first_difference() {
        let dir = std::env::temp_dir().join(format!("xtask-judge-{}", std::process::id()));
        let (clean_dir, rec) = (dir.join("clean"), dir.join("rec"));
        std::fs::create_dir_all(&clean_dir).unwrap();
        std::fs::create_dir_all(&rec).unwrap();
        let n = 10;
        let clean = stream(n);
        std::fs::write(dir.join("clean.bin"), &clean).unwrap();
        let fog = |k: usize, dc: usize| format!("{k},{dc},{}", k as f64 * 0.5);
        let write = |d: &Path, ks: &[usize], dc_at: Option<usize>| {
            let rows: Vec<String> = ks
                .iter()
                .map(|&k| fog(k, if Some(k) == dc_at { 7 } else { 100 + k }))
                .collect();
            std::fs::write(
                d.join("fog.csv"),
                format!("# c\nseq,dc_lsb,angle_deg\n{}\n", rows.join("\n")),
            )
            .unwrap();
            let rlg: Vec<String> = ks.iter().map(|k| format!("{k}")).collect();
            std::fs::write(d.join("rlg.csv"), format!("n\n{}\n", rlg.join("\n"))).unwrap();
        };
        let all: Vec<usize> = (0..n).collect();
        write(&clean_dir, &all, None);
        // Frame 4 lost on the way: the row after it spans the gap.
        let kept: Vec<usize> = all.iter().copied().filter(|&k| k != 4).collect();
        let mut got = clean.clone();
        got.drain(4 * FRAME..5 * FRAME);
        std::fs::write(rec.join("raw.bin"), &got).unwrap();
        write(&rec, &kept, Some(5));
        let json = serde_json::json!({
            "frames": 9,
            "lost_frames": [{"after_seq": 3, "before_seq": 5, "frames": 1}]
        });
        let v = judge(&dir.join("clean.bin"), &clean_dir, &rec, &json).unwrap();
        assert!(v.exact, "{:?}", v.first_difference);
        assert_eq!(v.not_received, vec![4]);
        // A row whose words differ where nothing was lost is named.
        write(&rec, &kept, Some(7));
        let v = judge(&dir.join("clean.bin"), &clean_dir, &rec, &json).unwrap();
        assert!(!v.exact);
        assert_eq!(
            v.first_difference.as_deref(),
            Some("frame seq 7: dc_lsb 7 against 107")
        );
        // A loss the recorder did not report is named.
        write(&rec, &kept, None);
        let silent = serde_json::json!({"frames": 9, "lost_frames": []});
        let v = judge(&dir.join("clean.bin"), &clean_dir, &rec, &silent).unwrap();
        assert!(v.first_difference.unwrap().contains("not reported [4]"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
