//! The host side of the board's output frames (docs/frame.md), one decoder
//! for every path: `cargo xtask qemu` and `gyro-lab record` both read frames
//! through [`Decoder`] and write run files through [`rows`].
//!
//! - [`decode`]: bytes in any chunks -> frames; resynchronises after
//!   garbage, counts CRC failures, locates lost frames by sequence number,
//!   unwraps the closure counter into the time base and turns the
//!   cumulative angle words back into each frame's increments (a lost frame
//!   loses no angle: the next one's increment spans the gap);
//! - [`summary`]: what a record held (frames, errors, lost frames, faults);
//! - [`rows`]: the FOG and RLG run-file rows;
//! - [`recorder`]: a record on disk as bytes arrive (raw capture, rows
//!   flushed every half second), merged with a [`reference`].

pub mod decode;
pub mod recorder;
pub mod reference;
pub mod rows;
pub mod scales;
pub mod summary;

pub use decode::{Decoded, Decoder, StreamError};
pub use recorder::{RecordError, Recorder};
pub use reference::{RateLog, Reference};
pub use scales::Scales;
pub use summary::Summary;
