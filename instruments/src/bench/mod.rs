//! Discovery scored on the independent generators' records: the held-out
//! set (discover_heldout.rs) and the cases beyond the library
//! (discover_outside.rs).

pub mod discover_heldout;
pub mod discover_outside;
