//! The firmware's fixed settings: timing, caps and thresholds.
//!
//! Every duration is in ticks of Timer3, which runs free at clk/64: one
//! tick is 4 us at 16 MHz, and the 16-bit counter wraps every 262 ms.

use shared::{CameraConfig, FieldCalibration, SensorRange};

/// Length of one Timer3 tick, in microseconds (`shared`: the simulator
/// quantises to the same ticks).
pub const TICK_US: u16 = shared::calibration::RC_TICK_US;
/// Control period: 20 ms, one Pixy frame (50 frames/s).
pub const PERIOD_TICKS: u16 = 20_000 / TICK_US;
/// The end of each period's wait, without USB work, so that the next
/// period starts on time: 200 us (serving USB once takes at most about
/// 100 us, a 64-byte packet written byte by byte).
pub const USB_QUIET_TICKS: u16 = 200 / TICK_US;
/// RC discharge timeout: 2000 us, as in Pololu's Zumo library. A sensor
/// still high after it reads this value.
pub const RC_TIMEOUT_TICKS: u16 = shared::calibration::RC_TIMEOUT_TICKS;
/// How long the field sensors are charged before timing, in microseconds.
pub const RC_CHARGE_US: u16 = 10;
/// Most Pixy blocks kept per frame (the Pixy sends the largest first; a
/// block costs about 2 ms on the bus at 100 kHz); in `shared` because the
/// simulator's camera model keeps the same blocks.
pub const PIXY_MAX_BLOCKS: usize = shared::camera::MAX_BLOCKS_PER_PERIOD;
/// Most 16-bit words read from the Pixy in one control period: a frame
/// start, [`PIXY_MAX_BLOCKS`] colour-code blocks and the end marker.
pub const PIXY_MAX_WORDS: u8 = 2 + 8 * PIXY_MAX_BLOCKS as u8 + 1;
/// A frame's blocks are used in at most this many control periods, so a
/// camera that stops seeing an object (and then sends nothing) clears it
/// (`shared::camera::HOLD_PERIODS`, which the simulator models).
pub const PIXY_HOLD_PERIODS: u8 = shared::camera::HOLD_PERIODS;
/// How long one TWI bus step may take before the bus counts as stalled
/// (a byte takes 90 us at 100 kHz).
pub const TWI_TIMEOUT_TICKS: u16 = 1_000 / TICK_US;
/// A fault is raised after this many bad control periods in a row.
pub const FAULT_PERIODS: u8 = 3;
/// How long an armed calibration waits for the white-then-black screens
/// before it fails: 60 s.
pub const CALIBRATION_PERIODS: u16 = 3_000;
/// Smallest calibrated range a sensor needs (100 us) between the white and
/// the black screen: less means it does not see the display.
pub const CALIBRATION_MIN_SPAN: u16 = 100 / TICK_US;
/// The calibration used until a valid one exists (the robot does not drive
/// then; the values in the log are only indicative): the whole timing range.
pub const UNCALIBRATED: FieldCalibration = FieldCalibration {
    ranges: [SensorRange {
        bright: 0,
        dark: RC_TIMEOUT_TICKS,
    }; 3],
};
/// How Pixy blocks become puck and obstacle bits.
pub const CAMERA: CameraConfig = CameraConfig::DEFAULT;
/// EEPROM address of the calibration record.
pub const CALIBRATION_EEPROM_ADDR: u16 = 0;
