//! Smoke tests of the firmware's release ELF in simavr (`scripts/build-firmware`
//! builds it; these tests fail, never skip, when it is missing).
//!
//! The emulated Zumo has RC-timed field sensors, a Pixy on TWI, buttons A
//! and B; the tests read the motor duties from OCR1A/OCR1B and decode the
//! USART1 log frames with `shared`, and check every decision against the
//! same decision computed on the host.

use firmware::calibration_record;
use firmware::config::{CALIBRATION_SPIN, CAMERA, RC_TIMEOUT_TICKS};
use firmware::decision::Decider;
use firmware::embedded;
use shared::{FieldCalibration, Faults, LogFrame, MotorCommand, PixyBlock, RunMode, SensorRange};
use tests::zumo::Zumo;

const CALIBRATION: FieldCalibration = FieldCalibration { ranges: [SensorRange { bright: 40, dark: 440 }; 3] };
/// Left 0.35, mid 0.6 (bin 9 of 16), right 0.725.
const SENSOR_TICKS: [Option<u16>; 3] = [Some(300), Some(200), Some(150)];
const PUCK_LEFT: PixyBlock = PixyBlock { signature: 1, x: 60, y: 150, width: 20, height: 14, angle: 0 };
const ROBOT_RIGHT: PixyBlock = PixyBlock { signature: 2, x: 250, y: 180, width: 40, height: 30, angle: 0 };
const BUDGET_CYCLES: u64 = 2_000;

fn calibrated_zumo() -> Zumo {
    let mut z = Zumo::boot();
    z.write_eeprom(0, &calibration_record::encode(&CALIBRATION));
    z.set_sensor_ticks(SENSOR_TICKS);
    z
}

fn decoded(z: &mut Zumo) -> Vec<LogFrame> {
    let frames: Vec<LogFrame> =
        z.frames().into_iter().map(|f| f.unwrap_or_else(|e| panic!("undecodable log frame: {e}"))).collect();
    assert!(!frames.is_empty(), "no log frames on USART1");
    for pair in frames.windows(2) {
        assert_eq!(pair[1].tick, pair[0].tick + 1, "a log frame was lost");
    }
    frames
}

/// The frame's decision, recomputed on the host from its raw times.
fn check_decision(frame: &LogFrame, blocks: &[PixyBlock]) -> shared::DriveOutputs {
    let scales = CALIBRATION.scales();
    let decider = Decider::new(&scales, CAMERA, embedded::HASHER, &embedded::POLICY[..], embedded::MOTORS);
    let expected = decider.decide(&frame.raw_times, blocks);
    assert_eq!(frame.values, expected.values);
    assert_eq!(frame.blobs, expected.blobs);
    assert_eq!(frame.state, expected.state);
    assert_eq!(frame.action, expected.action);
    assert_eq!(frame.blocks as usize, blocks.len());
    expected.outputs
}

#[test]
fn boots_starts_with_button_a_reads_sensors_and_camera_and_drives() {
    let mut z = calibrated_zumo();
    z.show(&[PUCK_LEFT, ROBOT_RIGHT]);
    z.run_ms(1);
    z.paint_stack();
    z.run_ms(100);
    let idle = decoded(&mut z);
    let last = idle.last().unwrap();
    assert_eq!((last.mode, last.faults, last.motors), (RunMode::Idle, Faults::NONE, MotorCommand::default()));
    assert_eq!(z.duties(), (0, 0));
    assert_ne!(z.boot_key(), 0x7777, "the bootloader key must not be left at 0x0800");

    z.press_a();
    z.run_ms(200);
    let frames = decoded(&mut z);
    let last = *frames.last().unwrap();
    assert_eq!((last.mode, last.faults), (RunMode::Driving, Faults::NONE));
    for (got, want) in last.raw_times.iter().zip(SENSOR_TICKS) {
        let want = want.unwrap();
        assert!(got.abs_diff(want) <= 2, "raw times {:?}, emulated {SENSOR_TICKS:?}", last.raw_times);
    }
    assert!(last.blobs.puck_left && !last.blobs.puck_right && last.blobs.obstacle_right);
    let outputs = check_decision(&last, &[PUCK_LEFT, ROBOT_RIGHT]);
    assert_eq!(last.motors, embedded::MOTORS.commands[last.action.index()]);
    assert_eq!(z.duties(), (outputs.left.duty, outputs.right.duty));
    assert!(z.duties() != (0, 0));

    let cycles = z.decision_cycles();
    let worst = *cycles.iter().max().expect("no decision markers seen");
    println!("decision cycles over {} decisions: min {}, max {worst}", cycles.len(), cycles.iter().min().unwrap());
    assert!(worst <= BUDGET_CYCLES, "a decision took {worst} cycles, budget {BUDGET_CYCLES}");

    // The stack stays above the bootloader key at 0x0800 (the firmware
    // clears it at start-up; nothing else may write it).
    let low = z.stack_low_water();
    println!("stack low water {low:#06x}: {} bytes of stack", 0x0B00 - low);
    assert!(low > 0x0801, "the stack reached {low:#06x}, over the bootloader key at 0x0800");

    // A again stops.
    z.press_a();
    z.run_ms(60);
    assert_eq!(decoded(&mut z).last().unwrap().mode, RunMode::Idle);
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn without_a_calibration_it_reports_and_does_not_drive() {
    let mut z = Zumo::boot();
    z.run_ms(60);
    z.press_a();
    z.run_ms(100);
    for f in decoded(&mut z) {
        assert!(f.faults.contains(Faults::NO_CALIBRATION));
        assert_eq!((f.mode, f.motors), (RunMode::Idle, MotorCommand::default()));
    }
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn a_corrupt_calibration_is_refused_and_the_robot_does_not_drive() {
    let mut record = calibration_record::encode(&CALIBRATION);
    record[3] ^= 0x10;
    let mut z = Zumo::boot();
    z.write_eeprom(0, &record);
    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(60);
    z.press_a();
    z.run_ms(100);
    for f in decoded(&mut z) {
        assert!(f.faults.contains(Faults::NO_CALIBRATION), "{f:?}");
        assert_eq!((f.mode, f.motors), (RunMode::Idle, MotorCommand::default()));
    }
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn a_silent_camera_or_blind_sensors_stop_the_motors_until_readings_return() {
    let mut z = calibrated_zumo();
    z.run_ms(40);
    z.press_a();
    z.run_ms(60);
    assert!(z.duties() != (0, 0));

    z.connect_pixy(false);
    z.run_ms(120);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!((last.mode, last.faults, last.motors), (RunMode::Driving, Faults::CAMERA_SILENT, MotorCommand::default()));
    assert_eq!(z.duties(), (0, 0));

    z.connect_pixy(true);
    z.run_ms(60);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.faults, Faults::NONE);
    let outputs = check_decision(&last, &[]);
    assert_eq!(z.duties(), (outputs.left.duty, outputs.right.duty));

    z.set_sensor_ticks([None; 3]);
    z.run_ms(120);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.raw_times, [RC_TIMEOUT_TICKS; 3]);
    assert_eq!((last.faults, last.motors), (Faults::SENSORS_TIMEOUT, MotorCommand::default()));
    assert_eq!(z.duties(), (0, 0));

    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(60);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.faults, Faults::NONE);
    assert!(z.duties() != (0, 0));
}

#[test]
fn button_b_sweeps_stores_the_calibration_in_eeprom_and_enables_driving() {
    let mut z = Zumo::boot();
    z.run_ms(40);
    // The robot spins over bright and dark field: alternate every period.
    z.calibrate();
    let frames = decoded(&mut z);
    let sweeping: Vec<_> = frames.iter().filter(|f| f.mode == RunMode::Calibrating).collect();
    assert!(sweeping.len() >= 190, "{} calibrating frames", sweeping.len());
    assert!(sweeping.iter().all(|f| f.motors == CALIBRATION_SPIN));
    let last = frames.last().unwrap();
    assert_eq!((last.mode, last.faults), (RunMode::Idle, Faults::NONE));

    let stored = calibration_record::decode(&z.read_eeprom(0, 16).try_into().unwrap()).expect("a stored calibration");
    for (range, offset) in stored.ranges.iter().zip([0, 10, 20]) {
        assert!(range.bright.abs_diff(100 + offset) <= 2 && range.dark.abs_diff(400 + offset) <= 2, "{stored:?}");
    }

    z.set_sensor_ticks(SENSOR_TICKS);
    z.press_a();
    z.run_ms(40);
    assert_eq!(decoded(&mut z).last().unwrap().mode, RunMode::Driving);
    assert!(z.duties() != (0, 0));
}
