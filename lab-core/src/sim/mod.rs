//! The lab's simulators, each producing the records a test rig would: the
//! FOG core closed around the simulated optics (fog_run.rs), an RLG in a
//! thermal chamber (chamber.rs), a dithered RLG through the firmware's
//! stripping (dither_run.rs, with the physics' prediction in
//! dither_theory.rs), the FOG scale-factor rig (scale_factor_rig.rs),
//! RLG fringes near lock-in (fringe.rs), a gyro model with the project's
//! noise (model_run.rs), records of known noise terms (noise_run.rs, and
//! by other algorithms independent_noise.rs) and the byte stream a board
//! sends (board_stream.rs). The generators written apart from these, for
//! the project's held-out benches, are instruments (instruments/), not
//! the user's tools.

pub mod board_stream;
pub mod chamber;
pub mod dither_run;
pub mod dither_theory;
pub mod fog_run;
pub mod fringe;
pub mod independent_noise;
pub mod model_run;
pub mod noise_run;
pub mod scale_factor_rig;
