//! The lab's HTML reports: one self-contained file (inline CSS, inline SVG
//! plots drawn by plotters, no scripts, nothing fetched), so it reads the
//! same offline and in any browser. Every subcommand that writes a report
//! builds it here (document.rs, plot.rs, text.rs, verdict.rs; annotated.rs:
//! plots with the legend beside the data and labelled marks); the commands
//! write the file.

pub mod annotated;
pub mod document;
pub mod plot;
pub mod text;
pub mod verdict;
