//! What a firmware image is: the policy it embeds (the policy blob's
//! CRC-32) and the robot it is for. The firmware keeps these 12 bytes in
//! flash, reads its robot id from them for the log, and `host flash` finds
//! them in the hex file it is about to write, so a stale or foreign build
//! is never flashed.
//!
//! | offset | size | content                                    |
//! |--------|------|--------------------------------------------|
//! | 0      | 6    | magic `ZUMOID`                             |
//! | 6      | 1    | layout version, 1                          |
//! | 7      | 1    | robot id                                   |
//! | 8      | 4    | the policy blob's CRC-32 (its last 4 bytes), LE |

/// The baud rate that, set on the robot's USB serial port with DTR then
/// dropped (the port opened at it and closed), resets the robot into its
/// bootloader: the "1200-baud touch" of Arduino's tools, which the
/// firmware answers and `host flash` sends.
pub const USB_TOUCH_BAUD: u32 = 1200;

/// The identity of one firmware build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FirmwareIdentity {
    /// The robot the build is for (`host flash --robot-id`; 0 = none given).
    pub robot_id: u8,
    /// The embedded policy blob's CRC-32, as the blob stores it.
    pub policy_crc: u32,
}

impl FirmwareIdentity {
    /// Length of the record in bytes.
    pub const LEN: usize = 12;
    /// The record's first bytes.
    pub const MAGIC: [u8; 6] = *b"ZUMOID";
    /// Offset of the robot id in the record.
    pub const ROBOT_ID_OFFSET: usize = 7;
    const LAYOUT: u8 = 1;

    /// The record as stored in flash.
    pub const fn to_bytes(&self) -> [u8; FirmwareIdentity::LEN] {
        let c = self.policy_crc.to_le_bytes();
        let m = Self::MAGIC;
        [
            m[0],
            m[1],
            m[2],
            m[3],
            m[4],
            m[5],
            Self::LAYOUT,
            self.robot_id,
            c[0],
            c[1],
            c[2],
            c[3],
        ]
    }

    /// The USB serial number the firmware presents (`robot-` and the robot
    /// id in three digits, `robot-007`), so that `/dev/serial/by-id/`
    /// tells robots apart.
    pub const fn usb_serial(robot_id: u8) -> [u8; 9] {
        [
            b'r',
            b'o',
            b'b',
            b'o',
            b't',
            b'-',
            b'0' + robot_id / 100,
            b'0' + robot_id / 10 % 10,
            b'0' + robot_id % 10,
        ]
    }

    /// The CRC-32 a policy blob stores (its last 4 bytes, LE), or `None`
    /// for a slice too short to be a blob.
    pub fn policy_crc_of(blob: &[u8]) -> Option<u32> {
        let tail = blob.len().checked_sub(4).and_then(|i| blob.get(i..))?;
        Some(u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]))
    }

    /// Every identity record in an image.
    pub fn find_all(image: &[u8]) -> impl Iterator<Item = FirmwareIdentity> + '_ {
        image
            .windows(Self::LEN)
            .filter(|w| w[..6] == Self::MAGIC && w[6] == Self::LAYOUT)
            .map(|w| FirmwareIdentity {
                robot_id: w[Self::ROBOT_ID_OFFSET],
                policy_crc: u32::from_le_bytes([w[8], w[9], w[10], w[11]]),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_record_is_found_in_an_image_and_names_robot_and_policy() {
        let id = FirmwareIdentity {
            robot_id: 5,
            policy_crc: 0xDEAD_BEEF,
        };
        let mut image = [0xFFu8; 64];
        image[20..32].copy_from_slice(&id.to_bytes());
        let mut found = FirmwareIdentity::find_all(&image);
        assert_eq!(found.next(), Some(id));
        assert_eq!(found.next(), None);
        assert_eq!(
            FirmwareIdentity::policy_crc_of(&[1, 2, 0xEF, 0xBE, 0xAD, 0xDE]),
            Some(0xDEAD_BEEF)
        );
        assert_eq!(FirmwareIdentity::policy_crc_of(&[1, 2]), None);
    }

    #[test]
    fn the_usb_serial_number_names_the_robot_in_three_digits() {
        assert_eq!(&FirmwareIdentity::usb_serial(0), b"robot-000");
        assert_eq!(&FirmwareIdentity::usb_serial(7), b"robot-007");
        assert_eq!(&FirmwareIdentity::usb_serial(255), b"robot-255");
    }
}
