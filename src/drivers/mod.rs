//! Drivers for external parts, generic over embedded-hal 1.0 traits (no
//! register access here: the board glue hands in its bus).

pub mod tmp117;
