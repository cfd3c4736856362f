//! The robot's log frame: one per control period, sent on the serial line
//! and decoded on the host with this same code.
//!
//! Wire format, format version 4:
//!
//! ```text
//! COBS( version (1 byte) | postcard(LogFrame) | CRC-16 (LE) ) | 0x00
//! ```
//!
//! Version 2 added [`LogFrame::calibration`], so that a host can recompute
//! the calibrated values from the raw times (`host replay`); version 3
//! added [`LogFrame::robot_id`] and [`LogFrame::encoder_counts`] (odometry);
//! version 4 added [`LogFrame::choice`], the robot's choice generator
//! before the decision, so that a host rechecks decisions sampled among a
//! state's best actions. Frames of other versions are refused, by their
//! version.
//!
//! - The first byte of every format's payload is its version, so a host
//!   refuses frames of another format with [`LogError::UnsupportedVersion`]
//!   before trying to read their body.
//! - The CRC is CRC-16/IBM-3740 (CCITT-FALSE) over the version and body,
//!   bit-wise (no table: the AVR would copy a table into its 2.5 KiB RAM).
//! - COBS removes every zero byte, so `0x00` ends a frame and a receiver
//!   that starts mid-stream resynchronises at the next zero.
//!
//! A frame is at most [`LogFrame::MAX_ENCODED_LEN`] bytes with its delimiter.

use crate::action::ActionId;
use crate::calibration::FieldCalibration;
use crate::camera::BlobSummary;
use crate::drive::MotorCommand;
use crate::field::FieldValue;
use crate::hasher::State;
use core::fmt;
use crc::{Crc, NoTable, CRC_16_IBM_3740};
use serde::{Deserialize, Serialize};

const CRC16: Crc<u16, NoTable> = Crc::<u16, NoTable>::new(&CRC_16_IBM_3740);

/// Largest body postcard can produce for a [`LogFrame`] (every varint at
/// its longest): tick, mode, faults, raw times, values, blobs, blocks,
/// state, action, motors, the calibration (tag + six times), the robot id
/// the two encoder counts and the choice generator's state (tag + u16).
const MAX_BODY_LEN: usize =
    5 + 1 + 1 + 3 * 3 + 3 * 3 + 4 + 1 + 3 + 1 + 3 * 2 + 1 + 6 * 3 + 1 + 2 * 3 + 1 + 3;
/// Version byte + body + CRC.
const MAX_RAW_LEN: usize = 1 + MAX_BODY_LEN + 2;

/// What the robot is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RunMode {
    /// Stopped, waiting for button A (drive) or B (calibrate).
    #[default]
    Idle,
    /// Running the policy (motors stopped while a fault is flagged).
    Driving,
    /// Standing still, calibrating the field sensors on the display's white
    /// and black screens.
    Calibrating,
}

/// Fault flags, a bit set; 0 = all well.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Faults(pub u8);

impl Faults {
    /// No valid calibration in EEPROM (missing or corrupt): the robot
    /// does not drive until calibrated.
    pub const NO_CALIBRATION: Faults = Faults(1);
    /// The last calibration saw no white-then-black sequence of screens (or
    /// too little contrast between them) and saved nothing.
    pub const CALIBRATION_FAILED: Faults = Faults(2);
    /// The Pixy has not acknowledged or has stalled the bus for several periods.
    pub const CAMERA_SILENT: Faults = Faults(4);
    /// Every field sensor has timed out for several periods.
    pub const SENSORS_TIMEOUT: Faults = Faults(8);

    /// No fault.
    pub const NONE: Faults = Faults(0);
    /// The faults that stop the motors while driving (they clear by
    /// themselves when readings return); the others are about calibration.
    pub const STOPS_MOTORS: Faults = Faults(Faults::CAMERA_SILENT.0 | Faults::SENSORS_TIMEOUT.0);
    /// Every flag with its name, lowest bit first (for reports).
    pub const NAMED: [(Faults, &'static str); 4] = [
        (Faults::NO_CALIBRATION, "no calibration"),
        (Faults::CALIBRATION_FAILED, "calibration failed"),
        (Faults::CAMERA_SILENT, "camera silent"),
        (Faults::SENSORS_TIMEOUT, "sensors timed out"),
    ];

    /// Whether every flag of `other` is set.
    pub const fn contains(self, other: Faults) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether any flag of `other` is set.
    pub const fn intersects(self, other: Faults) -> bool {
        self.0 & other.0 != 0
    }

    /// Whether no flag is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The union of both sets.
    pub const fn with(self, other: Faults) -> Faults {
        Faults(self.0 | other.0)
    }

    /// This set without `other`'s flags.
    pub const fn without(self, other: Faults) -> Faults {
        Faults(self.0 & !other.0)
    }

    /// Sets or clears `other`'s flags.
    pub const fn set(self, other: Faults, on: bool) -> Faults {
        if on {
            self.with(other)
        } else {
            self.without(other)
        }
    }
}

/// One control period as the robot saw and acted on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct LogFrame {
    /// Control periods since start-up.
    pub tick: u32,
    /// What the robot is doing.
    pub mode: RunMode,
    /// Active faults.
    pub faults: Faults,
    /// Raw discharge times of the left, mid and right field sensors, in
    /// timer ticks (the timeout value when a sensor timed out).
    pub raw_times: [u16; 3],
    /// Calibrated field values of the same sensors.
    pub values: [FieldValue; 3],
    /// What the camera's blocks mean as sensor bits.
    pub blobs: BlobSummary,
    /// Number of camera blocks the decision used.
    pub blocks: u8,
    /// The hashed state.
    pub state: State,
    /// The policy's action for that state.
    pub action: ActionId,
    /// The motor commands applied (0 when stopped).
    pub motors: MotorCommand,
    /// The calibration `values` were computed with (the whole timing range
    /// while uncalibrated), sent in the first frame after start-up, in the
    /// first frame after a new calibration takes effect, and at least every
    /// [`LogFrame::CALIBRATION_EVERY`] frames; it holds until the next
    /// one. `None` in the other frames.
    pub calibration: Option<FieldCalibration>,
    /// The robot's id (`host flash --robot-id`, 0 when none was given), so
    /// that logs of a whole swarm can be told apart and merged.
    pub robot_id: u8,
    /// Wheel encoder counts, left and right, during the control period
    /// before this one (while the previous frame's motor commands drove);
    /// positive = forward.
    pub encoder_counts: [i16; 2],
    /// When this period's decision drew from the robot's
    /// [`crate::ChoiceRng`] (its state had two or more best actions): the
    /// generator's state before the draw, which with the state's best
    /// actions gives `action` (`ChoiceRng::from_state(s).pick(mask)`), so a
    /// host rechecks every sampled decision. `None` when it did not draw.
    pub choice: Option<u16>,
}

/// Why a frame was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogError {
    /// Longer than any frame of this format.
    TooLong(usize),
    /// Not valid COBS.
    BadCobs,
    /// Too short to hold a version, a body and a CRC.
    TooShort(usize),
    /// The CRC does not match: a corrupted frame.
    CrcMismatch {
        /// CRC in the frame.
        stored: u16,
        /// CRC of the content.
        computed: u16,
    },
    /// A frame of another format version.
    UnsupportedVersion(u8),
    /// The body does not decode as a [`LogFrame`], or has unused bytes.
    Malformed,
}

impl fmt::Display for LogError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LogError::TooLong(n) => write!(
                f,
                "log frame of {n} bytes is longer than any frame ({})",
                LogFrame::MAX_ENCODED_LEN
            ),
            LogError::BadCobs => f.write_str("log frame is not valid COBS"),
            LogError::TooShort(n) => write!(f, "log frame of {n} bytes is too short"),
            LogError::CrcMismatch { stored, computed } => {
                write!(
                    f,
                    "log frame is corrupt: CRC-16 is {computed:#06x}, frame says {stored:#06x}"
                )
            }
            LogError::UnsupportedVersion(v) => write!(
                f,
                "log frame format version {v} is not supported (this build reads version {}; {})",
                LogFrame::VERSION,
                if v < LogFrame::VERSION {
                    "recorded by older firmware: flash the robot again and record a new log"
                } else {
                    "recorded by newer firmware: update the host"
                }
            ),
            LogError::Malformed => f.write_str("log frame body does not decode"),
        }
    }
}

impl core::error::Error for LogError {}

/// Buffer for one encoded frame.
pub type EncodedFrame = [u8; LogFrame::MAX_ENCODED_LEN];

impl LogFrame {
    /// The format version this build writes and reads.
    pub const VERSION: u8 = 4;
    /// The robot repeats its calibration at least every this many frames
    /// (one second), so a host that starts listening mid-run learns it.
    pub const CALIBRATION_EVERY: u8 = 50;
    /// The byte that ends every frame.
    pub const DELIMITER: u8 = 0;
    /// Longest encoded frame, delimiter included.
    pub const MAX_ENCODED_LEN: usize = cobs::max_encoding_length(MAX_RAW_LEN) + 1;

    /// Whether the policy's action drove the motors this period: driving
    /// with no fault that stops the motors (the firmware's supervisor rule).
    pub const fn policy_drove(&self) -> bool {
        matches!(self.mode, RunMode::Driving) && !self.faults.intersects(Faults::STOPS_MOTORS)
    }

    /// Encodes the frame into `out`; returns its length, the trailing
    /// delimiter included.
    pub fn encode(&self, out: &mut EncodedFrame) -> usize {
        let mut raw = [0u8; MAX_RAW_LEN];
        raw[0] = Self::VERSION;
        // Cannot fail: MAX_BODY_LEN bounds every field's longest encoding.
        let body_len =
            postcard::to_slice(self, &mut raw[1..1 + MAX_BODY_LEN]).map_or(0, |b| b.len());
        let end = 1 + body_len;
        let crc = CRC16.checksum(&raw[..end]);
        raw[end..end + 2].copy_from_slice(&crc.to_le_bytes());
        // Cannot fail: `out` holds the longest COBS encoding plus the delimiter.
        let n =
            cobs::try_encode(&raw[..end + 2], &mut out[..Self::MAX_ENCODED_LEN - 1]).unwrap_or(0);
        out[n] = Self::DELIMITER;
        n + 1
    }

    /// Decodes one frame: the bytes between two delimiters (a trailing
    /// delimiter is accepted too).
    pub fn decode(encoded: &[u8]) -> Result<LogFrame, LogError> {
        let encoded = match encoded.split_last() {
            Some((&Self::DELIMITER, rest)) => rest,
            _ => encoded,
        };
        if encoded.len() > Self::MAX_ENCODED_LEN {
            return Err(LogError::TooLong(encoded.len()));
        }
        let mut raw = [0u8; Self::MAX_ENCODED_LEN];
        let n = cobs::decode(encoded, &mut raw).map_err(|_| LogError::BadCobs)?;
        if n < 4 {
            return Err(LogError::TooShort(n));
        }
        let stored = u16::from_le_bytes([raw[n - 2], raw[n - 1]]);
        let computed = CRC16.checksum(&raw[..n - 2]);
        if stored != computed {
            return Err(LogError::CrcMismatch { stored, computed });
        }
        if raw[0] != Self::VERSION {
            return Err(LogError::UnsupportedVersion(raw[0]));
        }
        match postcard::take_from_bytes::<LogFrame>(&raw[1..n - 2]) {
            Ok((frame, [])) => Ok(frame),
            _ => Err(LogError::Malformed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::SensorRange;
    use proptest::prelude::*;

    fn sample() -> LogFrame {
        LogFrame {
            tick: 1234,
            mode: RunMode::Driving,
            faults: Faults::CAMERA_SILENT,
            raw_times: [100, 250, 500],
            values: [
                FieldValue::ONE,
                FieldValue::from_raw(13107),
                FieldValue::ZERO,
            ],
            blobs: BlobSummary {
                puck_left: true,
                ..BlobSummary::default()
            },
            blocks: 2,
            state: State(101),
            action: ActionId(3),
            motors: MotorCommand {
                left: 341,
                right: -41,
            },
            calibration: None,
            robot_id: 7,
            encoder_counts: [81, -12],
            choice: Some(0x1234),
        }
    }

    fn encoded(frame: &LogFrame) -> ([u8; LogFrame::MAX_ENCODED_LEN], usize) {
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = frame.encode(&mut buf);
        (buf, n)
    }

    #[test]
    fn round_trip_and_a_single_trailing_delimiter() {
        let (buf, n) = encoded(&sample());
        assert_eq!(buf[n - 1], 0);
        assert!(!buf[..n - 1].contains(&0));
        assert_eq!(LogFrame::decode(&buf[..n]), Ok(sample()));
        assert_eq!(LogFrame::decode(&buf[..n - 1]), Ok(sample()));
    }

    #[test]
    fn the_largest_frame_fits() {
        let big = LogFrame {
            tick: u32::MAX,
            raw_times: [u16::MAX; 3],
            values: [FieldValue::ONE; 3],
            blocks: u8::MAX,
            state: State(u16::MAX),
            action: ActionId(u8::MAX),
            motors: MotorCommand {
                left: i16::MIN,
                right: i16::MIN,
            },
            faults: Faults(u8::MAX),
            mode: RunMode::Calibrating,
            blobs: BlobSummary {
                puck_left: true,
                puck_right: true,
                obstacle_left: true,
                obstacle_right: true,
            },
            calibration: Some(FieldCalibration {
                ranges: [SensorRange {
                    bright: u16::MAX,
                    dark: u16::MAX,
                }; 3],
            }),
            robot_id: u8::MAX,
            encoder_counts: [i16::MIN; 2],
            choice: Some(u16::MAX),
        };
        let (buf, n) = encoded(&big);
        assert!(n <= LogFrame::MAX_ENCODED_LEN);
        assert_eq!(
            LogFrame::MAX_ENCODED_LEN,
            75,
            "docs/firmware.md states this bound"
        );
        assert_eq!(LogFrame::decode(&buf[..n]), Ok(big));
    }

    #[test]
    fn another_version_is_refused_by_its_first_byte() {
        let mut raw = [0u8; 8];
        raw[0] = 1;
        let crc = CRC16.checksum(&raw[..6]);
        raw[6..].copy_from_slice(&crc.to_le_bytes());
        let mut enc = [0u8; 16];
        let n = cobs::try_encode(&raw, &mut enc).unwrap();
        assert_eq!(
            LogFrame::decode(&enc[..n]),
            Err(LogError::UnsupportedVersion(1))
        );
        extern crate std;
        let message = std::format!("{}", LogError::UnsupportedVersion(2));
        assert!(
            message.contains("version 2 is not supported") && message.contains("older firmware"),
            "{message}"
        );
    }

    #[test]
    fn every_single_bit_flip_is_rejected() {
        let with_calibration = LogFrame {
            calibration: Some(calibration()),
            ..sample()
        };
        for frame in [sample(), with_calibration] {
            every_bit_flip_of(&frame);
        }
        assert!(LogFrame::decode(&[]).is_err());
    }

    fn calibration() -> FieldCalibration {
        FieldCalibration {
            ranges: [
                SensorRange {
                    bright: 40,
                    dark: 420,
                },
                SensorRange {
                    bright: 35,
                    dark: 500,
                },
                SensorRange {
                    bright: 50,
                    dark: 380,
                },
            ],
        }
    }

    fn every_bit_flip_of(frame: &LogFrame) {
        let (buf, n) = encoded(frame);
        for i in 0..n - 1 {
            for bit in 0..8 {
                let mut bad = buf;
                bad[i] ^= 1 << bit;
                assert!(LogFrame::decode(&bad[..n]).is_err(), "byte {i} bit {bit}");
            }
        }
    }

    #[test]
    fn the_calibration_round_trips_and_motor_stopping_faults_are_the_runtime_ones() {
        let f = LogFrame {
            calibration: Some(calibration()),
            ..sample()
        };
        let (buf, n) = encoded(&f);
        assert_eq!(LogFrame::decode(&buf[..n]), Ok(f));
        assert!(Faults::STOPS_MOTORS.contains(Faults::CAMERA_SILENT));
        assert!(Faults::STOPS_MOTORS.contains(Faults::SENSORS_TIMEOUT));
        assert!(!Faults::STOPS_MOTORS.contains(Faults::NO_CALIBRATION));
        let driving = LogFrame {
            mode: RunMode::Driving,
            faults: Faults::CALIBRATION_FAILED,
            ..sample()
        };
        assert!(driving.policy_drove());
        assert!(!LogFrame {
            faults: Faults::SENSORS_TIMEOUT,
            ..driving
        }
        .policy_drove());
        assert!(!LogFrame {
            mode: RunMode::Idle,
            ..driving
        }
        .policy_drove());
        let all = Faults::NAMED
            .iter()
            .fold(Faults::NONE, |acc, (f, _)| acc.with(*f));
        assert_eq!(all, Faults(15));
    }

    proptest! {
        #[test]
        fn decoding_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
            let _ = LogFrame::decode(&bytes);
        }

        #[test]
        fn any_frame_round_trips(tick in any::<u32>(), raw in any::<[u16; 3]>(), state in 0u16..1024, l in -400i16..=400, r in -400i16..=400, cal in any::<Option<[u16; 6]>>(), id in any::<u8>(), counts in any::<[i16; 2]>(), choice in any::<Option<u16>>()) {
            let calibration = cal.map(|t| FieldCalibration {
                ranges: [SensorRange { bright: t[0], dark: t[1] }, SensorRange { bright: t[2], dark: t[3] }, SensorRange { bright: t[4], dark: t[5] }],
            });
            let f = LogFrame { tick, raw_times: raw, state: State(state), motors: MotorCommand { left: l, right: r }, calibration, robot_id: id, encoder_counts: counts, choice, ..sample() };
            let (buf, n) = encoded(&f);
            prop_assert_eq!(LogFrame::decode(&buf[..n]), Ok(f));
        }
    }
}
