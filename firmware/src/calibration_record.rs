//! The field calibration as stored in EEPROM: 16 bytes with a checksum.
//!
//! | offset | size | content                                              |
//! |--------|------|------------------------------------------------------|
//! | 0      | 2    | magic `ZC`                                           |
//! | 2      | 12   | left, mid, right: bright then dark time (u16 LE)     |
//! | 14     | 2    | CRC-16/IBM-3740 of bytes 0..14 (LE)                  |
//!
//! An erased EEPROM (all `0xFF`) reads as "not calibrated", anything else
//! that does not check out as corrupt; both keep the robot from driving.

use crate::config::CALIBRATION_MIN_SPAN;
use crc::{Crc, NoTable, CRC_16_IBM_3740};
use shared::{FieldCalibration, SensorRange};

/// Size of a record in bytes.
pub const RECORD_LEN: usize = 16;
const MAGIC: [u8; 2] = *b"ZC";
const CRC16: Crc<u16, NoTable> = Crc::<u16, NoTable>::new(&CRC_16_IBM_3740);

/// Why a stored calibration cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// The EEPROM is erased: the robot was never calibrated.
    Erased,
    /// Wrong magic or checksum.
    Corrupt,
    /// Checks out but a sensor's range is too narrow.
    Invalid,
}

/// Encodes a calibration as a record.
pub fn encode(calibration: &FieldCalibration) -> [u8; RECORD_LEN] {
    let mut out = [0u8; RECORD_LEN];
    out[..2].copy_from_slice(&MAGIC);
    for (chunk, range) in out[2..14]
        .chunks_exact_mut(4)
        .zip(calibration.ranges.iter())
    {
        chunk[..2].copy_from_slice(&range.bright.to_le_bytes());
        chunk[2..].copy_from_slice(&range.dark.to_le_bytes());
    }
    let crc = CRC16.checksum(&out[..14]);
    out[14..].copy_from_slice(&crc.to_le_bytes());
    out
}

/// Decodes and checks a record.
pub fn decode(bytes: &[u8; RECORD_LEN]) -> Result<FieldCalibration, RecordError> {
    if bytes.iter().all(|b| *b == 0xFF) {
        return Err(RecordError::Erased);
    }
    let stored = u16::from_le_bytes([bytes[14], bytes[15]]);
    if bytes[..2] != MAGIC || stored != CRC16.checksum(&bytes[..14]) {
        return Err(RecordError::Corrupt);
    }
    let mut ranges = [SensorRange { bright: 0, dark: 0 }; 3];
    for (range, chunk) in ranges.iter_mut().zip(bytes[2..14].chunks_exact(4)) {
        let bright = u16::from_le_bytes([chunk[0], chunk[1]]);
        let dark = u16::from_le_bytes([chunk[2], chunk[3]]);
        *range =
            SensorRange::new(bright, dark, CALIBRATION_MIN_SPAN).ok_or(RecordError::Invalid)?;
    }
    Ok(FieldCalibration { ranges })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> FieldCalibration {
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

    #[test]
    fn round_trip() {
        assert_eq!(decode(&encode(&sample())), Ok(sample()));
    }

    #[test]
    fn erased_corrupt_and_invalid() {
        assert_eq!(decode(&[0xFF; RECORD_LEN]), Err(RecordError::Erased));
        assert_eq!(decode(&[0; RECORD_LEN]), Err(RecordError::Corrupt));
        let good = encode(&sample());
        for i in 0..RECORD_LEN {
            for bit in 0..8 {
                let mut bad = good;
                bad[i] ^= 1 << bit;
                assert_eq!(
                    decode(&bad),
                    Err(RecordError::Corrupt),
                    "byte {i} bit {bit}"
                );
            }
        }
        let narrow = FieldCalibration {
            ranges: [SensorRange {
                bright: 100,
                dark: 101,
            }; 3],
        };
        assert_eq!(decode(&encode(&narrow)), Err(RecordError::Invalid));
    }
}
