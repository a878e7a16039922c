//! The proof that no interrupt handler of a release image can panic, read
//! from the image itself: the call graph of its disassembly
//! (`arm-none-eabi-objdump -d`), every direct branch to another function an
//! edge, walked from each handler in the vector table. A handler that
//! reaches a panic function (anything of `core::panicking`, the failed
//! `unwrap`/`expect`/index checks, the panic handler `rust_begin_unwind`)
//! fails with the path; one that reaches an indirect call cannot be proven
//! and fails too, naming where.
//!
//! What the source cannot show, the image does: a division the optimiser
//! could not prove non-zero, a bounds check it kept, a panic inside a
//! crate's inlined code. The entry (`Reset`: start-up, then the idle loop)
//! is not a handler and is allowed to panic: docs/fixed-point.md says where
//! and why.

use anyhow::{bail, Context, Result};
use std::collections::{BTreeMap, HashMap, VecDeque};
use std::path::Path;
use std::process::Command;

/// A function of the image: its name, its direct callees (by start
/// address) and its first indirect branch, if any.
#[derive(Debug, Default)]
struct Function {
    name: String,
    calls: Vec<u64>,
    indirect: Option<String>,
}

/// The call graph: functions by start address.
#[derive(Debug, Default)]
pub struct CallGraph {
    functions: BTreeMap<u64, Function>,
}

/// Branches whose target is an address (`b`, `bl`, `blx <imm>`, conditional
/// and narrow/wide forms, `cbz`/`cbnz`); `bic`, `bfi`, `bfc` are not.
fn is_direct_branch(mnemonic: &str) -> bool {
    const CONDS: [&str; 15] = [
        "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt",
    ];
    let m = mnemonic
        .strip_suffix(".n")
        .or_else(|| mnemonic.strip_suffix(".w"))
        .unwrap_or(mnemonic);
    match m {
        "b" | "bl" | "blx" | "cbz" | "cbnz" => true,
        _ => m
            .strip_prefix('b')
            .is_some_and(|c| CONDS.contains(&c) || c == "le" || c == "al"),
    }
}

/// A branch through a register or a load into the PC that is not a return.
fn indirect(mnemonic: &str, operands: &str) -> bool {
    let m = mnemonic
        .strip_suffix(".n")
        .or_else(|| mnemonic.strip_suffix(".w"))
        .unwrap_or(mnemonic);
    let op = operands.split_whitespace().next().unwrap_or("");
    if m.starts_with("blx") || m.starts_with("bx") {
        // `bx lr` is a return; `blx <address>` a direct call.
        return op != "lr" && !op.chars().next().is_some_and(|c| c.is_ascii_hexdigit());
    }
    (m.starts_with("ldr") || m.starts_with("mov")) && op.trim_end_matches(',') == "pc"
}

impl CallGraph {
    /// Parses `objdump -d -C --no-show-raw-insn` output; `sizes`: each
    /// function's size by start address, from the symbol table. Bytes past
    /// a function's size are the linker's padding (0xd4d4, which objdump
    /// shows as `bmi.n` to some address), not code.
    pub fn parse(disassembly: &str, sizes: &HashMap<u64, u64>) -> Result<Self> {
        let mut g = CallGraph::default();
        let mut current: Option<u64> = None;
        let mut targets: Vec<(u64, u64)> = vec![];
        for line in disassembly.lines() {
            // "08000188 <Reset>:"
            if let Some((addr, rest)) = line.split_once(" <") {
                if let (Ok(a), Some(name)) = (
                    u64::from_str_radix(addr.trim(), 16),
                    rest.strip_suffix(">:"),
                ) {
                    g.functions.insert(
                        a,
                        Function {
                            name: name.to_string(),
                            ..Default::default()
                        },
                    );
                    current = Some(a);
                    continue;
                }
            }
            // " 80001e0:\tpush\t{r4, r5, r6, r7, lr}"
            let Some(f) = current else { continue };
            let mut cols = line.split('\t');
            let (Some(addr), Some(mnemonic)) = (cols.next(), cols.next()) else {
                continue;
            };
            let Some(Ok(at)) = addr
                .trim()
                .strip_suffix(':')
                .map(|a| u64::from_str_radix(a, 16))
            else {
                continue;
            };
            if sizes.get(&f).is_some_and(|&n| n > 0 && at >= f + n) {
                continue;
            }
            let operands = cols.next().unwrap_or("");
            let mnemonic = mnemonic.trim();
            let target = operands
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|w| !w.is_empty())
                .find_map(|w| u64::from_str_radix(w, 16).ok());
            if let (true, Some(t)) = (is_direct_branch(mnemonic), target) {
                targets.push((f, t));
            } else if indirect(mnemonic, operands) {
                let fun = g.functions.get_mut(&f).context("function")?;
                fun.indirect
                    .get_or_insert_with(|| format!("{} {}", mnemonic, operands.trim()));
            }
        }
        if g.functions.is_empty() {
            bail!("no function in the disassembly");
        }
        // A branch into another function (a call, a tail call, a jump to
        // a cold panic stub) is an edge to the function holding the target.
        for (from, t) in targets {
            let Some((&to, _)) = g.functions.range(..=t).next_back() else {
                continue;
            };
            if to != from {
                let fun = g.functions.get_mut(&from).context("function")?;
                if !fun.calls.contains(&to) {
                    fun.calls.push(to);
                }
            }
        }
        Ok(g)
    }

    fn name(&self, a: u64) -> &str {
        self.functions.get(&a).map_or("?", |f| f.name.as_str())
    }

    /// The function holding address `a`.
    fn holding(&self, a: u64) -> Option<u64> {
        self.functions.range(..=a).next_back().map(|(&s, _)| s)
    }

    /// From `start`, the shortest path to a panic function, or to a
    /// function with an indirect branch (which the proof cannot follow).
    pub fn panic_path(&self, start: u64) -> Option<String> {
        let mut prev: HashMap<u64, u64> = HashMap::new();
        let mut queue = VecDeque::from([start]);
        prev.insert(start, start);
        while let Some(f) = queue.pop_front() {
            let fun = &self.functions[&f];
            let why = if is_panic(&fun.name) {
                Some("a panic function".to_string())
            } else {
                fun.indirect
                    .as_ref()
                    .map(|i| format!("an indirect branch ({i}) the proof cannot follow"))
            };
            if let Some(why) = why {
                let mut path = vec![f];
                let mut at = f;
                while at != start {
                    at = prev[&at];
                    path.push(at);
                }
                let names: Vec<&str> = path.iter().rev().map(|&a| self.name(a)).collect();
                return Some(format!("{} ({why})", names.join(" -> ")));
            }
            for &c in &fun.calls {
                if let std::collections::hash_map::Entry::Vacant(e) = prev.entry(c) {
                    e.insert(f);
                    queue.push_back(c);
                }
            }
        }
        None
    }
}

/// The panic machinery of core and the panic handler.
fn is_panic(name: &str) -> bool {
    [
        "core::panicking::",
        "rust_begin_unwind",
        "unwrap_failed",
        "expect_failed",
        "panic_bounds_check",
        "_index_len_fail",
        "index_order_fail",
        "slice_error_fail",
        "panic_fmt",
    ]
    .iter()
    .any(|p| name.contains(p))
}

/// Each function symbol's size by its start address (Thumb bit cleared).
fn sizes(elf: &[u8]) -> Result<HashMap<u64, u64>> {
    use object::{Object, ObjectSymbol, SymbolKind};
    let file = object::File::parse(elf)?;
    // Aliases share an address (`DefaultHandler` of size 0 beside
    // `DefaultHandler_`): the largest size is the function's.
    let mut sizes = HashMap::new();
    for s in file.symbols().filter(|s| s.kind() == SymbolKind::Text) {
        let n = sizes.entry(s.address() & !1).or_insert(0);
        *n = s.size().max(*n);
    }
    Ok(sizes)
}

/// The entries of the image's vector table (all but the initial stack
/// pointer; vector 1 is `Reset`), as (vector number, start address), each
/// once.
fn vectors(elf: &[u8]) -> Result<Vec<(usize, u64)>> {
    use object::{Object, ObjectSection};
    let file = object::File::parse(elf)?;
    let table = file
        .section_by_name(".vector_table")
        .context("no .vector_table section")?
        .data()?;
    let mut seen = std::collections::BTreeSet::new();
    Ok(table
        .chunks_exact(4)
        .enumerate()
        .skip(1)
        .map(|(n, w)| {
            (
                n,
                (u32::from_le_bytes([w[0], w[1], w[2], w[3]]) & !1) as u64,
            )
        })
        .filter(|&(_, a)| a != 0 && seen.insert(a))
        .collect())
}

/// What the proof found in one image.
pub struct Proof {
    /// Each handler with the panic path it reaches (None: proven free).
    pub handlers: Vec<(String, Option<String>)>,
    /// The entry's (start-up, then the idle loop): allowed to panic
    /// (docs/panics.md), shown for the record.
    pub entry: Option<String>,
    /// The idle loop's alone (RTIC's `idle`), if the image has one.
    pub idle: Option<Option<String>>,
}

/// The proof on one image.
pub fn check(elf: &Path) -> Result<Proof> {
    let out = Command::new("arm-none-eabi-objdump")
        .args(["-d", "-C", "--no-show-raw-insn"])
        .arg(elf)
        .output()
        .context("running arm-none-eabi-objdump (Debian: binutils-arm-none-eabi)")?;
    if !out.status.success() {
        bail!(
            "arm-none-eabi-objdump failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let bytes = std::fs::read(elf)?;
    let g = CallGraph::parse(&String::from_utf8_lossy(&out.stdout), &sizes(&bytes)?)?;
    let idle = g
        .functions
        .iter()
        .find(|(_, f)| f.name.ends_with("::app::idle"))
        .map(|(&a, _)| g.panic_path(a));
    let mut proof = Proof {
        handlers: vec![],
        entry: None,
        idle,
    };
    for (n, a) in vectors(&bytes)? {
        let f = g
            .holding(a)
            .with_context(|| format!("no function at vector {n}'s address {a:#x}"))?;
        if n == 1 {
            proof.entry = g.panic_path(f);
        } else {
            proof
                .handlers
                .push((g.name(f).to_string(), g.panic_path(f)));
        }
    }
    Ok(proof)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shape of objdump's output, with a handler that reaches a panic
    /// through a helper and a conditional branch to a cold stub, one that
    /// only returns (and is followed by padding that reads as a branch),
    /// and one with a call through a register.
    const DIS: &str = "
08000100 <ISR_A>:
 8000100:\tpush\t{r7, lr}
 8000102:\tbic.w\tr0, r0, #1
 8000106:\tbl\t8000200 <helper>
 800010a:\tpop\t{r7, pc}

08000110 <ISR_B>:
 8000110:\tcmp\tr0, #0
 8000112:\tbeq.w\t8000114 <ISR_B+0x4>
 8000114:\tbx\tlr
 8000116:\tbmi.n\t8000300 <core::panicking::panic_const::panic_const_div_by_zero>

08000120 <ISR_C>:
 8000120:\tblx\tr3
 8000122:\tbx\tlr

08000200 <helper>:
 8000200:\tcbz\tr1, 8000208 <helper+0x8>
 8000202:\tudiv\tr0, r0, r1
 8000206:\tbx\tlr
 8000208:\tbeq.w\t8000300 <core::panicking::panic_const::panic_const_div_by_zero>

08000300 <core::panicking::panic_const::panic_const_div_by_zero>:
 8000300:\tbl\t8000400 <__rustc::rust_begin_unwind>

08000400 <__rustc::rust_begin_unwind>:
 8000400:\tb.n\t8000400 <__rustc::rust_begin_unwind>
";

    #[test]
    fn paths_to_panics_and_indirect_calls_are_found() {
        // ISR_B's last two bytes are padding past its size.
        let sizes = HashMap::from([(0x8000110, 6)]);
        let g = CallGraph::parse(DIS, &sizes).unwrap();
        assert_eq!(
            g.panic_path(0x8000100).unwrap(),
            "ISR_A -> helper -> core::panicking::panic_const::panic_const_div_by_zero \
             (a panic function)"
        );
        assert_eq!(g.panic_path(0x8000110), None);
        assert!(g
            .panic_path(0x8000120)
            .unwrap()
            .contains("indirect branch (blx r3)"));
    }
}
