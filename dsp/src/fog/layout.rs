//! The sample layout of one closure and the compiled copy of the closure
//! that runs it. Config chooses the [`Kernel`] once; `FogLoop::process` is
//! the one place that maps it to sizes.

/// Most half periods per closure (6.25 kHz closure at tau = 5 us is 32).
pub const MAX_HALF: usize = 64;
/// Most ADC samples per half period.
pub const MAX_SAMPLES_PER_HALF: usize = 16;

/// The compiled copies of the closure: the reference instruments' layouts
/// (16 or 32 half periods of 4 samples, 1 skipped, no DAC latency) with the
/// sizes as constants (divisions become shifts, loops unroll), and any
/// layout with runtime sizes, without or with one closure of DAC latency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Half16,
    Half32,
    Any,
    AnyLatency1,
}

impl Kernel {
    pub fn for_layout(n_half: usize, samples_per_half: usize, skip: usize, latency: u32) -> Self {
        match (n_half, samples_per_half, skip, latency) {
            (16, 4, 1, 0) => Kernel::Half16,
            (32, 4, 1, 0) => Kernel::Half32,
            (_, _, _, 0) => Kernel::Any,
            _ => Kernel::AnyLatency1,
        }
    }
}
