//! Playing stimuli to the firmware in simavr, one control period each:
//! a calibrated, driving Zumo, and what the firmware did in each period
//! (its log frame, duties and direction pins).

use crate::equivalence::cycles_of_ticks;
use crate::zumo::Zumo;
use firmware::calibration_record;
use shared::{Faults, LogFrame, PixyBlock, RunMode};
use sim::sensors::robot::RobotSensors;
use std::collections::HashMap;
use std::path::Path;

/// One period's stimulus.
pub struct Stimulus<'a> {
    /// RC delays in CPU cycles after each pin becomes an input.
    pub cycles: [u64; 3],
    /// The camera frame.
    pub frame: &'a [PixyBlock],
}

/// What the firmware did in the period of one stimulus.
pub struct Observed {
    /// Its log frame.
    pub frame: LogFrame,
    /// OCR1A and OCR1B after the decision.
    pub duties: (u16, u16),
    /// The direction pins after the decision.
    pub directions: (bool, bool),
}

/// A Zumo running `elf`, with `usb` its USB serial port open and
/// streaming to a host in the background, calibrated by the real procedure (button B, then
/// the display's white and black screens as RC delays on the sensor pins:
/// each sensor's model time at field 1.0 and at 0.0, placed mid-tick as in
/// the exact check), driving, stopped right after a decision. Panics unless
/// the stored calibration is the simulator's.
pub fn driving_zumo(elf: &Path, model: &RobotSensors, latency_us: f64, usb: bool) -> Zumo {
    let mut z = Zumo::boot_elf(elf);
    z.run_ms(40);
    if usb {
        // USB enumerated and streaming all along, a control request every 7 ms.
        z.usb_open(4);
        z.stream_usb_in_background(firmware::usb::IN_EP, 7_000);
    }
    calibrate_and_drive(&mut z, model, latency_us);
    z
}

/// Calibrates a booted Zumo by the real procedure (as [`driving_zumo`]
/// does), starts it driving with button A and stops right after its first
/// decision. Panics unless the stored calibration is the simulator's.
pub fn calibrate_and_drive(z: &mut Zumo, model: &RobotSensors, latency_us: f64) {
    let cal = model.calibration();
    let screen = |ticks: [u16; 3]| ticks.map(|t| Some(cycles_of_ticks(t, latency_us)));
    z.calibrate_cycles(
        screen(cal.ranges.map(|r| r.bright)),
        screen(cal.ranges.map(|r| r.dark)),
    );
    let record: [u8; calibration_record::RECORD_LEN] = z
        .read_eeprom(0, calibration_record::RECORD_LEN)
        .try_into()
        .expect("a record's bytes");
    let stored = calibration_record::decode(&record);
    assert_eq!(
        stored,
        Ok(cal),
        "the procedure must store the simulator's calibration (PhotoSensorConfig::calibration)"
    );
    z.press_a();
    z.run_to_decision();
}

/// Plays one stimulus per control period and returns what the firmware did
/// in each. A period whose camera frame is empty right after one that was
/// not gets one more period first: the firmware uses a frame's blocks for
/// two periods and the Pixy sends nothing when it sees nothing.
pub fn play(z: &mut Zumo, stimuli: &[Stimulus<'_>], holding: &mut bool) -> Vec<Observed> {
    let mut periods = Vec::with_capacity(stimuli.len());
    // A period may be under way (after an earlier play's closing run), its
    // sensors read with the earlier stimulus: finish it first.
    z.run_to_decision();
    for s in stimuli {
        z.set_sensor_cycles(s.cycles.map(Some));
        z.show(s.frame);
        let mut tick = z.run_to_decision();
        if s.frame.is_empty() && *holding {
            tick = z.run_to_decision();
        }
        *holding = !s.frame.is_empty();
        periods.push((tick, z.duties(), z.directions()));
    }
    z.run_ms(10);
    let frames: HashMap<u64, LogFrame> = z
        .frames()
        .into_iter()
        .map(|f| f.unwrap_or_else(|e| panic!("undecodable log frame: {e}")))
        .map(|f| (u64::from(f.tick), f))
        .collect();
    periods
        .into_iter()
        .map(|(tick, duties, directions)| {
            let frame = *frames
                .get(&tick)
                .unwrap_or_else(|| panic!("no log frame for period {tick}"));
            assert_eq!(
                (frame.mode, frame.faults),
                (RunMode::Driving, Faults::NONE),
                "period {tick}: {frame:?}"
            );
            Observed {
                frame,
                duties,
                directions,
            }
        })
        .collect()
}

/// Every log frame the firmware has sent on USART1 since it booted, in
/// order (a frame still being sent is left out).
pub fn frames_since_boot(z: &Zumo) -> Vec<LogFrame> {
    frames_of_stream(z.uart_bytes())
}

/// The frames of a serial stream, in order; a last frame without its
/// delimiter is left out. Panics on one that does not decode.
pub fn frames_of_stream(bytes: &[u8]) -> Vec<LogFrame> {
    let end = bytes
        .iter()
        .rposition(|b| *b == LogFrame::DELIMITER)
        .map_or(0, |i| i + 1);
    bytes[..end]
        .split(|b| *b == LogFrame::DELIMITER)
        .filter(|f| !f.is_empty())
        .map(|f| LogFrame::decode(f).unwrap_or_else(|e| panic!("undecodable log frame: {e}")))
        .collect()
}
