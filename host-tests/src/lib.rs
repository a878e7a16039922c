//! Shared helpers for the host tests live in tests/common; this crate has no library code.
