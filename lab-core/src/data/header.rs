//! A data file's header row, read through the user's mapping of their
//! column names onto ours (`--columns rate_dps=gyro_z`). A lookup is by
//! our name; what is missing is said all at once, with the columns the
//! file has and the `--columns` that would map the likely ones.

use super::read_spec::ReadSpec;
use super::source::Origin;
use crate::error::LabError;

/// Words that name the same quantity in the headers people write: a
/// missing column of ours is guessed among the file's by them.
const SYNONYMS: [&[&str]; 5] = [
    &[
        "t",
        "time",
        "timestamp",
        "sec",
        "secs",
        "seconds",
        "elapsed",
        "ts",
    ],
    &[
        "rate", "gyro", "gyr", "omega", "w", "wz", "gz", "gx", "gy", "angular", "velocity",
        "gyroz", "gyrox", "gyroy", "zaxis", "xaxis", "yaxis",
    ],
    &["temp", "temperature", "tmp", "therm", "thermistor"],
    &[
        "ref",
        "reference",
        "table",
        "truth",
        "true",
        "cmd",
        "commanded",
    ],
    &["case", "housing", "mono", "monoblock", "coil", "a", "b"],
];

fn tokens(name: &str) -> Vec<String> {
    name.split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|t| !t.is_empty())
        .map(str::to_ascii_lowercase)
        .collect()
}

/// How much `theirs` looks like `ours`: the synonym groups both touch,
/// each once, and a shared word; none where one names a reference (or a
/// sensor's place) and the other does not.
fn likeness(ours: &str, theirs: &str) -> usize {
    let (a, b) = (tokens(ours), tokens(theirs));
    let hit = |g: &[&str], ts: &[String]| ts.iter().any(|t| g.contains(&t.as_str()));
    for g in &SYNONYMS[3..] {
        if hit(g, &a) != hit(g, &b) {
            return 0;
        }
    }
    SYNONYMS.iter().filter(|g| hit(g, &a) && hit(g, &b)).count()
        + usize::from(a.iter().any(|t| t.len() > 1 && b.contains(t)))
}

/// The header's names, and where each of ours is.
pub struct Header {
    names: Vec<String>,
    spec: ReadSpec,
}

impl Header {
    pub fn new(names: Vec<String>, spec: &ReadSpec) -> Self {
        Self {
            names,
            spec: spec.clone(),
        }
    }

    pub fn len(&self) -> usize {
        self.names.len()
    }

    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The names as the file has them.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The field index of our column `ours`.
    pub fn find(&self, ours: &str) -> Option<usize> {
        let theirs = self.spec.theirs(ours);
        self.names.iter().position(|h| h == theirs)
    }

    /// Our column as the file names it.
    pub fn shown<'a>(&'a self, ours: &'a str) -> &'a str {
        self.spec.theirs(ours)
    }

    /// The field indices of all of `cols`, or one error at the header's
    /// line naming every one missing, the columns found, and a mapping.
    pub fn require(
        &self,
        origin: &Origin,
        line: u64,
        cols: &[&str],
    ) -> Result<Vec<usize>, LabError> {
        let missing: Vec<&str> = cols
            .iter()
            .copied()
            .filter(|c| self.find(c).is_none())
            .collect();
        if missing.is_empty() {
            return Ok(cols.iter().filter_map(|c| self.find(c)).collect());
        }
        Err(origin.header(line, self.missing_message(&missing, origin)))
    }

    fn missing_message(&self, missing: &[&str], origin: &Origin) -> String {
        let list: Vec<String> = missing
            .iter()
            .map(|c| {
                if self.spec.is_mapped(c) {
                    format!(
                        "`{}` (given for {c} by {})",
                        self.spec.theirs(c),
                        match origin {
                            Origin::File(_) => "--columns",
                            Origin::Memory(_) => "columns=",
                        }
                    )
                } else {
                    format!("`{c}`")
                }
            })
            .collect();
        let found: Vec<String> = self.names.iter().map(|n| format!("`{n}`")).collect();
        // The likeliest unused column of the file for each missing one.
        let used: Vec<usize> = self
            .names
            .iter()
            .enumerate()
            .filter(|(_, n)| {
                !self.spec.rename.iter().any(|(_, t)| t == *n) && !missing.contains(&n.as_str())
            })
            .map(|(i, _)| i)
            .collect();
        let mut taken = vec![];
        let mut map = vec![];
        for c in missing.iter().filter(|c| !self.spec.is_mapped(c)) {
            let best = used
                .iter()
                .filter(|i| !taken.contains(*i))
                .map(|&i| (likeness(c, &self.names[i]), i))
                .filter(|(s, _)| *s > 0)
                .max_by_key(|(s, i)| (*s, usize::MAX - i));
            if let Some((_, i)) = best {
                taken.push(i);
                map.push(format!("{c}={}", self.names[i]));
            }
        }
        // In memory the mapping is the caller's `columns=` argument.
        let given = match origin {
            Origin::File(_) => "the file has",
            Origin::Memory(_) => "the columns given are",
        };
        let map_as = |m: &[String]| match origin {
            Origin::File(_) => format!("--columns {}", m.join(",")),
            Origin::Memory(_) => {
                let pairs: Vec<String> = m
                    .iter()
                    .map(|p| {
                        let (a, b) = p.split_once('=').unwrap_or((p, p));
                        format!("'{a}': '{b}'")
                    })
                    .collect();
                format!("columns={{{}}}", pairs.join(", "))
            }
        };
        let hint = if map.is_empty() {
            format!(
                "; map yours onto them with {}",
                map_as(&["ours=theirs".to_owned()])
            )
        } else {
            format!("; map yours onto them with {}", map_as(&map))
        };
        format!(
            "missing column{} {}; {given} {}{hint}",
            if missing.len() == 1 { "" } else { "s" },
            list.join(", "),
            if found.is_empty() {
                "none".to_owned()
            } else {
                found.join(", ")
            }
        )
    }
}

/// Where a table's columns are in its source, for errors about a column
/// as a whole: the file (or the caller's name), the header's line, and per column read (ours) its
/// field and the name the file gives it.
#[derive(Clone, Debug, Default)]
pub struct Places {
    pub origin: Origin,
    pub header_line: u64,
    pub fields: Vec<(String, usize, String)>,
}

impl Places {
    /// The name the file gives our column `ours` (ours where not read).
    pub fn shown(&self, ours: &str) -> String {
        self.fields
            .iter()
            .find(|f| f.0 == ours)
            .map_or_else(|| ours.to_owned(), |f| f.2.clone())
    }

    /// An error about our column `ours` as a whole, at its header cell.
    pub fn column_error(&self, ours: &str, msg: impl Into<String>) -> LabError {
        let f = self.fields.iter().find(|f| f.0 == ours);
        self.origin.column(
            self.header_line,
            f.map_or(0, |f| f.1),
            &f.map_or_else(|| ours.to_owned(), |f| f.2.clone()),
            msg,
        )
    }
}
