//! Output frames: round trip, CRC, no loss of angle when the queue is full.

use gyro_sp::fog::scale_factor::{
    FogTempFlags, FogTempWords, ScaleFactorComp, ScaleFactorConfig, ScaleFactorTable,
};
use gyro_sp::fog::{ClosureOutput, Faults, FogConfig, FogParams};
use gyro_sp::frame::{Frame, FrameBuilder, FrameError, ResetCause, FRAME_LEN};
use gyro_sp::rlg::{RlgFlags, RlgWords};
use proptest::prelude::*;

fn out(sagnac_phase: i64) -> ClosureOutput {
    ClosureOutput {
        sagnac_phase,
        sagnac_phase_corrected: sagnac_phase - 3,
        ..ClosureOutput::default()
    }
}

#[test]
fn round_trip_and_crc() {
    let f = Frame {
        seq: 7,
        faults: Faults::from_bits_retain(5),
        closures: 25,
        closure_counter: 1234,
        fog_angle: -99,
        fog_angle_raw: 1 << 40,
        fog_residual: -5,
        codes_per_turn_q8: 12_582_912,
        dc: 25_000,
        rlg: RlgWords {
            delta_counts: -70_000,
            rate_comp_udps: 123_456_789,
            bias_q16_dph: -6554,
            t_mono_a_q8: -40 * 256,
            t_mono_b_q8: 85 * 256 + 3,
            t_case_q8: 20 * 256,
            flags: RlgFlags::from_bits_retain(0b1010),
        },
        fog_angle_comp: -(1 << 50) + 17,
        fog_temp: FogTempWords {
            sf_corr_q32: -859_000,
            bias_q16_dph: 31_000,
            t_coil_q8: 48 * 256 + 7,
            t_sensor_q8: -40 * 256,
            flags: FogTempFlags::from_bits_retain(0b110),
        },
        reset_cause: ResetCause::HardFault,
        closures_missed: 3,
    };
    let b = f.encode();
    assert_eq!(Frame::decode(&b), Ok(f));
    let mut bad = b;
    bad[20] ^= 1;
    assert_eq!(Frame::decode(&bad), Err(FrameError::Crc));
    let mut bad = b;
    bad[57] ^= 0x80;
    assert_eq!(Frame::decode(&bad), Err(FrameError::Crc));
    let mut bad = b;
    bad[81] ^= 0x01;
    assert_eq!(Frame::decode(&bad), Err(FrameError::Crc));
    assert_eq!(Frame::decode(&b[..FRAME_LEN - 1]), Err(FrameError::Length));
    // Another version with a good CRC is a version error, not noise.
    let mut v3 = b;
    v3[2] = 3;
    let crc = gyro_sp::frame::crc16(&v3[2..FRAME_LEN - 2]);
    v3[FRAME_LEN - 2..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(Frame::decode(&v3), Err(FrameError::Version));
    assert_eq!(gyro_sp::frame::any_version(&v3), Some(3));
    assert_eq!(gyro_sp::frame::any_version(&bad), None);
}

/// A table that scales by exactly 1/(1 + 100 ppm) and removes no bias.
fn sf_table() -> (ScaleFactorConfig, ScaleFactorComp) {
    let fog = FogConfig::new(FogParams::default()).unwrap();
    let t = ScaleFactorTable::from_nodes(&[0.0, 50.0], &[100.0, 100.0], &[0.0, 0.0], 0.0);
    let cfg = ScaleFactorConfig::new(&t, &fog, 1.0);
    let mut comp = ScaleFactorComp::default();
    comp.update_temperature(&cfg, Some(25 * 256));
    (cfg, comp)
}

#[test]
fn restored_frame_loses_no_angle() {
    let (sf_cfg, sf) = sf_table();
    let mut fb = FrameBuilder::new(4, 16);
    let mut emitted = Vec::new();
    let mut total = 0i64;
    let mut refused = std::collections::HashSet::new();
    for k in 0..40 {
        total += (k - 3) * 16;
        if let Some(mut f) = fb.push(&out(k), k as u32 + 1) {
            f.compensate_fog(&sf, &sf_cfg);
            // Every other frame "does not fit in the queue".
            if f.seq % 2 == 1 && refused.insert(f.seq) {
                fb.restore(f);
            } else {
                emitted.push(f);
            }
        }
    }
    let sent: i64 = emitted.iter().map(|f| f.fog_angle).sum();
    let pending = 40 - emitted.iter().map(|f| f.closures as i64).sum::<i64>();
    let pending_angle: i64 = (40 - pending..40).map(|k| (k - 3) * 16).sum();
    assert_eq!(sent + pending_angle, total);
    // The compensated angle of a frame merged back is compensated whole
    // with the next: the sent compensated angles are the sent angles
    // scaled, to the multiply's rounding (one LSB per frame).
    let comp: i64 = emitted.iter().map(|f| f.fog_angle_comp).sum();
    let expected = sent as f64 / (1.0 + 100e-6);
    assert!(
        (comp as f64 - expected).abs() <= emitted.len() as f64 + 1.0,
        "{comp} vs {expected}"
    );
    assert!(emitted
        .iter()
        .any(|f| f.faults.contains(Faults::QUEUE_FULL)));
    for w in emitted.windows(2) {
        assert_eq!(
            w[1].seq,
            w[0].seq.wrapping_add(1),
            "sequence numbers stay contiguous"
        );
    }
}

proptest! {
    #[test]
    fn decode_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..100)) {
        let _ = Frame::decode(&bytes);
    }

    /// The closure step takes any ADC input and watchdog flag without panicking,
    /// and its DAC words stay inside the digital gain's range.
    #[test]
    fn closure_never_panics(
        adc in proptest::collection::vec(any::<u16>(), 0..80),
        over_range in any::<bool>(),
    ) {
        let cfg = gyro_sp::fog::FogConfig::new(gyro_sp::fog::FogParams::default()).unwrap();
        let mut fog = gyro_sp::fog::FogLoop::new(&cfg);
        let mut dac = [0u16; 16];
        for _ in 0..3 {
            let out = fog.process(&cfg, &adc, over_range, &mut dac);
            prop_assert!(out.codes_per_turn_q8 >= (cfg.gain_loop.min_q15 >> 7) as u32 && out.codes_per_turn_q8 <= (cfg.gain_loop.max_q15 >> 7) as u32);
            prop_assert!(dac.iter().all(|&d| u32::from(d) <= (cfg.gain_loop.max_q15 >> 15) as u32));
            if adc.len() < cfg.n_samples || over_range {
                prop_assert!(out.faults.contains(gyro_sp::fog::Faults::ADC_SATURATION));
            }
        }
    }
}
