//! The hw board's sampling timing from one timebase (docs/timing.md): the
//! register values of the two sampling timers, and the window of sampling
//! phases in which the kept ADC samples see settled light. Plain integers and
//! `const fn`, no PAC types, so the values are unit-tested on the host;
//! `sampling::configure_timers` writes them.
//!
//! TIM1 (advanced timer, APB2 timer clock) is the master. Its update requests
//! one DAC word per half period (DMA); its compare 1, `phase_ticks` after each
//! update, sets OC1REF ("active on match": set once and held), which is its
//! trigger output (MMS = OC1REF). TIM2 (APB1 timer clock) is the slave in
//! trigger mode on ITR0, which on TIM2 is TIM1_TRGO (RM0090, "TIMx internal
//! trigger connection"): OC1REF's one rising edge starts it, and from then on
//! its updates (its TRGO) trigger the ADC, `samples_per_half` per half period.
//! Both counters are preset to their auto-reload value, so each counts its
//! first update one tick after it starts: TIM1's first update requests DAC word
//! 0 and TIM2's first update is ADC sample 0. Both timer clocks come from the
//! one PLL and both periods are the same time, so the phase set at the start
//! holds for the whole run; no instruction timing enters it.

/// Timer kernel clocks of the hw board (168 MHz core, APB2 84 MHz, APB1 42 MHz:
/// a timer on a divided APB runs at twice its bus clock), Hz.
pub const TIM1_CLK_HZ: u32 = 168_000_000;
pub const TIM2_CLK_HZ: u32 = 84_000_000;

/// TIMx_CR2.MMS, master mode selection: what drives TRGO.
pub mod mms {
    /// The update event.
    pub const UPDATE: u8 = 0b010;
    /// The channel 1 reference output OC1REF.
    pub const OC1REF: u8 = 0b100;
}

/// TIMx_SMCR.SMS, slave mode selection.
pub mod sms {
    /// Trigger mode: TRGI's rising edge starts the counter (sets CEN) and
    /// nothing else; later edges are ignored while it runs.
    pub const TRIGGER: u8 = 0b110;
}

/// TIMx_SMCR.TS, trigger selection: ITR0, which on TIM2 is TIM1_TRGO.
pub const TS_ITR0: u8 = 0b000;

/// TIMx_CCMR1.OC1M, output compare 1 mode.
pub mod oc1m {
    /// OC1REF forced low: where the set-up starts, so the only edge is the match.
    pub const FORCE_INACTIVE: u8 = 0b100;
    /// OC1REF set high on a match, and held.
    pub const ACTIVE_ON_MATCH: u8 = 0b001;
}

/// What the sampling must do, in the timers' terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimingSpec {
    /// TIM1's and TIM2's kernel clocks, Hz.
    pub tim1_clk_hz: u32,
    pub tim2_clk_hz: u32,
    /// Half periods per second: DAC words, one per TIM1 update.
    pub half_period_hz: u32,
    /// ADC samples per half period: TIM2 updates per TIM1 update.
    pub samples_per_half: u32,
    /// TIM1 counter ticks from a DAC word's update to the compare that starts
    /// TIM2: the sampling phase.
    pub phase_ticks: u32,
}

/// TIM1, the master: DAC pacing and the phase compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MasterRegs {
    pub psc: u16,
    pub arr: u16,
    /// Counter preset before the start (ARR: first update one tick after CEN).
    pub cnt: u16,
    /// Compare 1: the phase, TIM1 ticks after each update.
    pub ccr1: u16,
    pub oc1m: u8,
    pub mms: u8,
    /// DIER.UDE: a DMA request (one DAC word) per update.
    pub ude: bool,
}

/// TIM2, the slave: the ADC's trigger (32-bit counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlaveRegs {
    pub psc: u16,
    pub arr: u32,
    /// Counter preset before the start (ARR: first update, ADC sample 0, one
    /// tick after the trigger starts it).
    pub cnt: u32,
    pub mms: u8,
    pub sms: u8,
    pub ts: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimerRegs {
    pub tim1: MasterRegs,
    pub tim2: SlaveRegs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingError {
    /// TIM1's clock is not a whole multiple of the half-period rate that fits
    /// the 16-bit prescaler and counter.
    Tim1Rate,
    /// The same for TIM2 and the ADC rate.
    Tim2Rate,
    /// The phase compare is not inside the counter's period: it must be below
    /// ARR, since the counter starts at ARR.
    Phase,
}

/// TIM1's and TIM2's register values for `s` (RM0090: update rate =
/// f_clk / ((PSC + 1)(ARR + 1)); each prescaler is the smallest that lets its
/// counter hold the period, so the phase steps by the finest tick).
pub const fn timer_regs(s: &TimingSpec) -> Result<TimerRegs, TimingError> {
    let Some((psc1, arr1)) = divide(s.tim1_clk_hz, s.half_period_hz as u64, 0xFFFF) else {
        return Err(TimingError::Tim1Rate);
    };
    // Both divide their clocks exactly, so samples_per_half TIM2 periods are
    // exactly one TIM1 period (the clocks themselves are one PLL's).
    let adc_hz = s.half_period_hz as u64 * s.samples_per_half as u64;
    let Some((psc2, arr2)) = divide(s.tim2_clk_hz, adc_hz, u32::MAX) else {
        return Err(TimingError::Tim2Rate);
    };
    if s.phase_ticks >= arr1 {
        return Err(TimingError::Phase);
    }
    Ok(TimerRegs {
        tim1: MasterRegs {
            psc: psc1,
            arr: arr1 as u16,
            cnt: arr1 as u16,
            ccr1: s.phase_ticks as u16,
            oc1m: oc1m::ACTIVE_ON_MATCH,
            mms: mms::OC1REF,
            ude: true,
        },
        tim2: SlaveRegs {
            psc: psc2,
            arr: arr2,
            cnt: arr2,
            mms: mms::UPDATE,
            sms: sms::TRIGGER,
            ts: TS_ITR0,
        },
    })
}

/// (PSC, ARR) for `rate_hz` from `clk_hz`: the smallest prescaler whose
/// counter period (ARR + 1 ticks, at least 2: ARR = 0 stops the counter) fits
/// `arr_max`. None unless the clock is a whole multiple of the rate.
const fn divide(clk_hz: u32, rate_hz: u64, arr_max: u32) -> Option<(u16, u32)> {
    if rate_hz == 0 || !(clk_hz as u64).is_multiple_of(rate_hz) {
        return None;
    }
    let ticks = clk_hz as u64 / rate_hz;
    let mut psc: u64 = 0;
    while psc <= 0xFFFF {
        let div = psc + 1;
        if ticks.is_multiple_of(div) && ticks / div >= 2 && ticks / div - 1 <= arr_max as u64 {
            return Some((psc as u16, (ticks / div - 1) as u32));
        }
        psc += 1;
    }
    None
}

/// `ticks` of a counter at `clk_hz` (after its prescaler), in ns, rounded.
pub const fn ticks_to_ns(ticks: u32, clk_hz: u32) -> u32 {
    ((ticks as u64 * 1_000_000_000 + clk_hz as u64 / 2) / clk_hz as u64) as u32
}

/// `ns` in ticks of a counter at `clk_hz`, rounded.
pub const fn ns_to_ticks(ns: u32, clk_hz: u32) -> u32 {
    ((ns as u64 * clk_hz as u64 + 500_000_000) / 1_000_000_000) as u32
}

/// The chain from a DAC word's update to the ADC's hold instant, as the
/// default sampling phase is derived from it (docs/timing.md), ns. These are
/// the board's estimates, to be replaced by measured values when the phase is
/// trimmed; the host test builds the simulated front end from the same numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chain {
    /// TIM1 update -> DMA2 stream 5 has written the word into SPI1's data
    /// register (arbitration behind the ADC's stream 0 included).
    pub dma_ns: u32,
    /// SPI1 shifts the 16-bit word out.
    pub spi_word_ns: u32,
    /// The word's last bit -> the DAC's output starts to move.
    pub dac_latch_ns: u32,
    /// The DAC and the modulator driver slew across the DAC's whole 16-bit range
    /// in this time (a slew rate: a step of c codes takes c/65 536 of it).
    pub dac_full_scale_slew_ns: u32,
    /// The largest DAC step, codes: a 2*pi reset (codes per turn).
    pub max_step_codes: u32,
    /// Modulator -> detector (Y junction, coupler, pigtail). The coil's transit
    /// is not in it: both waves see an edge at once, by the eigenfrequency.
    pub fibre_ns: u32,
    /// The detector's and the anti-alias filter's time constants.
    pub detector_tau_ns: u32,
    pub filter_tau_ns: u32,
    /// Electrical crosstalk of the drive's slew into the detector's input, LSB
    /// (16-bit scale), with the step's sign while the drive slews.
    pub crosstalk_lsb: u32,
    /// After the light stops sweeping, time constants of the slower pole until
    /// the kept samples may follow: the crosstalk is the part that does not
    /// cancel between the half periods' signs, and 1 LSB of it left in a kept
    /// sample is 2.5 deg/h of bias (docs/timing.md); e^-8 of 20 LSB is 0.017
    /// deg/h. The light's own transient is the same in both signs but at 2*pi
    /// resets; the host test's sweep shows it within 0.3 ppm well before.
    pub settle_time_constants: u32,
    /// TIM1's compare -> the ADC's hold instant: TIM2's trigger
    /// resynchronisation and first tick, the ADC's trigger latency and its
    /// sampling time.
    pub adc_aperture_ns: u32,
}

/// SPI1's clock (PCLK2 / 4) and the DAC word, bits.
pub const SPI_HZ: u32 = 21_000_000;
pub const DAC_WORD_BITS: u32 = 16;
/// The ADC's clock (PCLK2 / 4), its trigger latency and its sampling time, cycles.
pub const ADCCLK_HZ: u32 = 21_000_000;
pub const ADC_TRIGGER_LATENCY_CYCLES: u32 = 2;
pub const ADC_SAMPLE_CYCLES: u32 = 3;

/// The hw board's chain.
pub const BOARD_CHAIN: Chain = Chain {
    dma_ns: 60,
    spi_word_ns: ticks_to_ns(DAC_WORD_BITS, SPI_HZ),
    dac_latch_ns: 40,
    dac_full_scale_slew_ns: 500,
    max_step_codes: 49_152,
    fibre_ns: 20,
    detector_tau_ns: 150,
    filter_tau_ns: 50,
    crosstalk_lsb: 20,
    settle_time_constants: 8,
    // Two TIM2 ticks of resynchronisation and its first tick, then the ADC.
    adc_aperture_ns: ticks_to_ns(3, TIM2_CLK_HZ)
        + ticks_to_ns(ADC_TRIGGER_LATENCY_CYCLES + ADC_SAMPLE_CYCLES, ADCCLK_HZ),
};

impl Chain {
    /// Update -> the DAC's output starts to move, ns.
    pub const fn dac_delay_ns(&self) -> u32 {
        self.dma_ns + self.spi_word_ns + self.dac_latch_ns
    }

    /// Update -> the light starts to sweep at the detector, ns.
    pub const fn light_delay_ns(&self) -> u32 {
        self.dac_delay_ns() + self.fibre_ns
    }

    /// The longest sweep (a 2*pi reset's step), ns.
    pub const fn max_sweep_ns(&self) -> u32 {
        (self.max_step_codes as u64 * self.dac_full_scale_slew_ns as u64 / 65_536) as u32
    }

    /// Update -> the light has settled at the ADC's input after any edge, ns.
    pub const fn settled_ns(&self) -> u32 {
        let slow = if self.detector_tau_ns > self.filter_tau_ns {
            self.detector_tau_ns
        } else {
            self.filter_tau_ns
        };
        self.light_delay_ns() + self.max_sweep_ns() + self.settle_time_constants * slow
    }

    /// The sampling phases (TIM1 compare after the update, ns) whose kept
    /// samples see settled light, `[lo, hi]`: the first kept sample (after
    /// `skip` of `samples_per_half`) holds after the light has settled, the last
    /// before the next edge disturbs the input (its crosstalk, at the next
    /// word's DAC delay). None if there is no such phase.
    pub const fn phase_window_ns(
        &self,
        half_period_ns: u32,
        samples_per_half: u32,
        skip: u32,
    ) -> Option<(u32, u32)> {
        if samples_per_half == 0 || skip >= samples_per_half {
            return None;
        }
        let ts = half_period_ns / samples_per_half;
        let first = self.settled_ns() as i64 - (skip * ts) as i64 - self.adc_aperture_ns as i64;
        let last = (half_period_ns + self.dac_delay_ns()) as i64
            - ((samples_per_half - 1) * ts) as i64
            - self.adc_aperture_ns as i64;
        let lo = if first < 0 { 0 } else { first };
        if last < lo || last >= half_period_ns as i64 {
            return None;
        }
        Some((lo as u32, last as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{
        fog_params, SAMPLES_PER_HALF, SAMPLING_PHASE_TICKS, SAMPLING_TIMERS, TIM1_TICKS_PER_HALF,
    };

    fn board(phase_ticks: u32) -> TimingSpec {
        TimingSpec {
            tim1_clk_hz: TIM1_CLK_HZ,
            tim2_clk_hz: TIM2_CLK_HZ,
            half_period_hz: 200_000,
            samples_per_half: 4,
            phase_ticks,
        }
    }

    /// Update rate of a counter, RM0090: f_clk / ((PSC + 1)(ARR + 1)).
    fn update_hz(clk: u32, psc: u16, arr: u32) -> f64 {
        clk as f64 / ((psc as f64 + 1.0) * (arr as f64 + 1.0))
    }

    #[test]
    fn board_rates_from_the_datasheet_formula() {
        let r = timer_regs(&board(233)).unwrap();
        assert_eq!((r.tim1.psc, r.tim1.arr), (0, 839));
        assert_eq!((r.tim2.psc, r.tim2.arr), (0, 104));
        assert_eq!(
            update_hz(TIM1_CLK_HZ, r.tim1.psc, r.tim1.arr as u32),
            200_000.0
        );
        assert_eq!(update_hz(TIM2_CLK_HZ, r.tim2.psc, r.tim2.arr), 800_000.0);
        // The layout's rates: 12.5 kHz closures of 16 half periods of 4 samples.
        let p = fog_params(1);
        let half_hz = 1.0 / p.tau_s;
        assert!((update_hz(TIM1_CLK_HZ, r.tim1.psc, r.tim1.arr as u32) - half_hz).abs() < 1e-6);
        assert_eq!(TIM1_TICKS_PER_HALF, r.tim1.arr as u32 + 1);
    }

    #[test]
    fn modes_are_the_master_slave_link() {
        let r = timer_regs(&board(233)).unwrap();
        // TIM1: TRGO = OC1REF (MMS 100), set on the compare and held (OC1M 001),
        // a DMA request per update.
        assert_eq!((r.tim1.mms, r.tim1.oc1m, r.tim1.ude), (0b100, 0b001, true));
        // TIM2: trigger mode (SMS 110) on ITR0 = TIM1_TRGO (TS 000); TRGO = update
        // (MMS 010), the ADC's external trigger.
        assert_eq!((r.tim2.sms, r.tim2.ts, r.tim2.mms), (0b110, 0b000, 0b010));
        assert_eq!((r.tim1.cnt, r.tim1.ccr1), (839, 233));
        assert_eq!(r.tim2.cnt, 104);
    }

    /// The first few closures' updates and ADC triggers as the counters make
    /// them from the register values: every half period's first sample is the
    /// same phase after its update, and its samples are a quarter period apart.
    #[test]
    fn phase_is_the_same_in_every_half_period() {
        for phase in [0, 1, 233, 500, 838] {
            let r = timer_regs(&board(phase)).unwrap();
            // Times in TIM1 ticks (168 MHz = 2 x TIM2's 84 MHz), from CEN.
            let m = r.tim1;
            let tim1_period = (m.psc as u64 + 1) * (m.arr as u64 + 1);
            let first_update = (m.arr - m.cnt) as u64 + 1;
            let first_match = first_update + m.ccr1 as u64 * (m.psc as u64 + 1);
            let s = r.tim2;
            let ratio = (TIM1_CLK_HZ / TIM2_CLK_HZ) as u64;
            let tim2_period = (s.psc as u64 + 1) * (s.arr as u64 + 1) * ratio;
            let first_trigger = first_match + (s.arr - s.cnt) as u64 * ratio + ratio;
            for j in 0..64u64 {
                let update = first_update + j * tim1_period;
                for i in 0..4u64 {
                    let trigger = first_trigger + (4 * j + i) * tim2_period;
                    // Ticks after the update: the phase, one TIM2 tick of
                    // counting, and i sample periods.
                    assert_eq!(trigger - update, phase as u64 + ratio + i * 210);
                }
            }
        }
    }

    #[test]
    fn phase_in_ns() {
        // 1e9 / 168e6 = 5.952 ns a tick.
        assert_eq!(ticks_to_ns(1, TIM1_CLK_HZ), 6);
        assert_eq!(ticks_to_ns(233, TIM1_CLK_HZ), 1387); // 1386.90
        assert_eq!(ticks_to_ns(840, TIM1_CLK_HZ), 5000);
        assert_eq!(ns_to_ticks(5000, TIM1_CLK_HZ), 840);
        assert_eq!(ns_to_ticks(1385, TIM1_CLK_HZ), 233); // 232.68
                                                         // The SPI word: 16 bits at 21 MHz, 761.9 ns.
        assert_eq!(BOARD_CHAIN.spi_word_ns, 762);
    }

    #[test]
    fn impossible_timings_are_refused() {
        let ok = board(0);
        assert_eq!(
            timer_regs(&TimingSpec {
                phase_ticks: 839,
                ..ok
            }),
            Err(TimingError::Phase)
        );
        // 168 MHz / 330 kHz = 509.1 ticks.
        assert_eq!(
            timer_regs(&TimingSpec {
                half_period_hz: 330_000,
                ..ok
            }),
            Err(TimingError::Tim1Rate)
        );
        // 84 MHz / (200 kHz x 11) = 38.2 ticks.
        assert_eq!(
            timer_regs(&TimingSpec {
                samples_per_half: 11,
                ..ok
            }),
            Err(TimingError::Tim2Rate)
        );
        assert_eq!(
            timer_regs(&TimingSpec {
                samples_per_half: 0,
                ..ok
            }),
            Err(TimingError::Tim2Rate)
        );
        // 3 samples divide it (140 ticks): accepted, 3 x 140 / 84 MHz = 5 us.
        let r = timer_regs(&TimingSpec {
            samples_per_half: 3,
            ..ok
        })
        .unwrap();
        assert_eq!(r.tim2.arr, 139);
    }

    #[test]
    fn a_slow_rate_needs_a_prescaler() {
        // 1 kHz from 168 MHz: 168 000 ticks do not fit 16 bits; PSC = 2 gives
        // 56 000 (the smallest prescaler that divides and fits).
        let r = timer_regs(&TimingSpec {
            half_period_hz: 1_000,
            ..board(100)
        })
        .unwrap();
        assert_eq!((r.tim1.psc, r.tim1.arr), (2, 55_999));
        assert_eq!(
            update_hz(TIM1_CLK_HZ, r.tim1.psc, r.tim1.arr as u32),
            1_000.0
        );
        // TIM2 is 32-bit: no prescaler for 4 kHz.
        assert_eq!((r.tim2.psc, r.tim2.arr), (0, 20_999));
    }

    /// The chain's window against its formula, and the configured phase in it.
    #[test]
    fn default_phase_inside_the_chains_window() {
        let c = BOARD_CHAIN;
        // 60 + 762 + 40 + 20 = 882 ns to the light's sweep; a reset's step of
        // 49 152 codes slews in 375 ns; 8 x 150 ns to settle: 2 457 ns.
        assert_eq!(c.light_delay_ns(), 882);
        assert_eq!(c.max_sweep_ns(), 375);
        assert_eq!(c.settled_ns(), 2_457);
        // 3 x 11.9 ns + 5 / 21 MHz = 36 + 238 ns.
        assert_eq!(c.adc_aperture_ns, 274);
        // First kept sample: 2 457 - 1 250 - 274 = 933; last: 5 000 + 862 -
        // 3 750 - 274 = 1 838.
        let (lo, hi) = c.phase_window_ns(5_000, 4, 1).unwrap();
        assert_eq!((lo, hi), (933, 1_838));
        let phase_ns = ticks_to_ns(SAMPLING_PHASE_TICKS, TIM1_CLK_HZ);
        assert!(
            lo < phase_ns && phase_ns < hi,
            "{phase_ns} ns outside {lo}..{hi}"
        );
        // The default is the window's middle, to a tick.
        let mid = ns_to_ticks((lo + hi) / 2, TIM1_CLK_HZ);
        assert!(SAMPLING_PHASE_TICKS.abs_diff(mid) <= 1);
        assert_eq!(SAMPLING_TIMERS.tim1.ccr1 as u32, SAMPLING_PHASE_TICKS);
        assert_eq!(SAMPLES_PER_HALF, 4);
        // Without a skipped sample the transient reaches a kept one: no window.
        assert_eq!(c.phase_window_ns(5_000, 4, 0), None);
    }
}
