//! Parser for the Pixy (CMUcam5) word stream, as read over I2C.
//!
//! The camera sends 16-bit words (little-endian on I2C). A frame starts
//! with two sync words in a row; each block is a sync word (`0xAA55`
//! normal, `0xAA56` colour code), a checksum, then signature, x, y, width,
//! height (and an angle for colour codes). The checksum is the wrapping sum
//! of the words after it. When the camera has nothing to send it sends
//! zero words. `0x55AA` means the reader is one byte off.
//!
//! [`PixyParser::push`] takes one word at a time and reports what it
//! completes. It accepts any input: garbage is skipped until the next
//! frame start, and it never panics.

use shared::PixyBlock;

/// Sync word of a normal block (and, doubled, of a frame start).
pub const SYNC: u16 = 0xAA55;
/// Sync word of a colour-code block.
pub const SYNC_CC: u16 = 0xAA56;
/// A sync word read one byte off: the reader must skip one byte.
pub const SYNC_SWAPPED: u16 = 0x55AA;

/// What one word completed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixyEvent {
    /// A new frame starts; its blocks follow.
    FrameStart,
    /// A block whose checksum matched.
    Block(PixyBlock),
    /// A block whose checksum did not match (dropped).
    BadChecksum,
    /// The stream is one byte off: skip one byte, then continue.
    Misaligned,
    /// A zero word where a sync was due: the camera has nothing more now.
    Idle,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Expect {
    /// Looking for the first sync of a frame.
    Sync,
    /// One sync seen; a second one starts a frame.
    SecondSync,
    /// A block's checksum (or a sync: a frame start).
    Checksum { cc: bool },
    /// A block's data words.
    Data {
        cc: bool,
        checksum: u16,
        words: [u16; 6],
        len: u8,
    },
    /// The sync of the frame's next block.
    NextSync,
}

/// The parser's state between words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixyParser {
    expect: Expect,
}

impl Default for PixyParser {
    fn default() -> PixyParser {
        PixyParser::new()
    }
}

impl PixyParser {
    /// A parser looking for a frame start.
    pub const fn new() -> PixyParser {
        PixyParser {
            expect: Expect::Sync,
        }
    }

    /// Feeds one word.
    pub fn push(&mut self, word: u16) -> Option<PixyEvent> {
        let (next, event) = match self.expect {
            Expect::Sync => match word {
                SYNC => (Expect::SecondSync, None),
                SYNC_SWAPPED => (Expect::Sync, Some(PixyEvent::Misaligned)),
                0 => (Expect::Sync, Some(PixyEvent::Idle)),
                _ => (Expect::Sync, None),
            },
            Expect::SecondSync => match word {
                SYNC => (Expect::Checksum { cc: false }, Some(PixyEvent::FrameStart)),
                SYNC_CC => (Expect::Checksum { cc: true }, Some(PixyEvent::FrameStart)),
                SYNC_SWAPPED => (Expect::Sync, Some(PixyEvent::Misaligned)),
                0 => (Expect::Sync, Some(PixyEvent::Idle)),
                _ => (Expect::Sync, None),
            },
            Expect::Checksum { cc } => match word {
                // Two syncs in a row: the previous one marked a new frame.
                SYNC => (Expect::Checksum { cc: false }, Some(PixyEvent::FrameStart)),
                SYNC_CC => (Expect::Checksum { cc: true }, Some(PixyEvent::FrameStart)),
                0 => (Expect::Sync, Some(PixyEvent::Idle)),
                checksum => (
                    Expect::Data {
                        cc,
                        checksum,
                        words: [0; 6],
                        len: 0,
                    },
                    None,
                ),
            },
            Expect::Data {
                cc,
                checksum,
                mut words,
                len,
            } => {
                if let Some(slot) = words.get_mut(usize::from(len)) {
                    *slot = word;
                }
                let len = len + 1;
                let needed = if cc { 6 } else { 5 };
                if len < needed {
                    (
                        Expect::Data {
                            cc,
                            checksum,
                            words,
                            len,
                        },
                        None,
                    )
                } else {
                    (Expect::NextSync, Some(Self::finish(cc, checksum, &words)))
                }
            }
            Expect::NextSync => match word {
                SYNC => (Expect::Checksum { cc: false }, None),
                SYNC_CC => (Expect::Checksum { cc: true }, None),
                SYNC_SWAPPED => (Expect::Sync, Some(PixyEvent::Misaligned)),
                0 => (Expect::Sync, Some(PixyEvent::Idle)),
                _ => (Expect::Sync, None),
            },
        };
        self.expect = next;
        event
    }

    fn finish(cc: bool, checksum: u16, words: &[u16; 6]) -> PixyEvent {
        let count = if cc { 6 } else { 5 };
        let sum = words
            .iter()
            .take(count)
            .fold(0u16, |s, w| s.wrapping_add(*w));
        if sum != checksum {
            return PixyEvent::BadChecksum;
        }
        let [signature, x, y, width, height, angle] = *words;
        PixyEvent::Block(PixyBlock {
            signature,
            x,
            y,
            width,
            height,
            angle: if cc { angle as i16 } else { 0 },
        })
    }
}

/// Encodes blocks as the camera sends one frame (for tests and emulators):
/// the frame's extra sync, then each block.
pub fn encode_frame(blocks: &[PixyBlock], out: &mut [u16]) -> usize {
    let mut n = 0;
    let mut put = |w: u16| {
        if let Some(slot) = out.get_mut(n) {
            *slot = w;
            n += 1;
        }
    };
    if !blocks.is_empty() {
        put(SYNC);
    }
    for b in blocks {
        let cc = b.signature > 7;
        let mut data = [b.signature, b.x, b.y, b.width, b.height, b.angle as u16];
        let count = if cc { 6 } else { 5 };
        let checksum = data
            .iter()
            .take(count)
            .fold(0u16, |s, w| s.wrapping_add(*w));
        put(if cc { SYNC_CC } else { SYNC });
        put(checksum);
        for w in data.iter_mut().take(count) {
            put(*w);
        }
    }
    n
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;

    fn block(signature: u16, x: u16, y: u16) -> PixyBlock {
        PixyBlock {
            signature,
            x,
            y,
            width: 12,
            height: 9,
            angle: 0,
        }
    }

    fn events(words: &[u16]) -> std::vec::Vec<PixyEvent> {
        let mut p = PixyParser::new();
        words.iter().filter_map(|w| p.push(*w)).collect()
    }

    fn frame(blocks: &[PixyBlock]) -> std::vec::Vec<u16> {
        let mut buf = [0u16; 64];
        let n = encode_frame(blocks, &mut buf);
        buf[..n].to_vec()
    }

    #[test]
    fn a_frame_of_two_normal_blocks() {
        let (a, b) = (block(1, 100, 150), block(2, 200, 20));
        let mut words = frame(&[a, b]);
        words.push(0);
        assert_eq!(
            events(&words),
            [
                PixyEvent::FrameStart,
                PixyEvent::Block(a),
                PixyEvent::Block(b),
                PixyEvent::Idle
            ]
        );
    }

    #[test]
    fn colour_code_blocks_carry_a_signed_angle() {
        let cc = PixyBlock {
            signature: 0o12,
            x: 5,
            y: 6,
            width: 7,
            height: 8,
            angle: -90,
        };
        let words = frame(&[cc, block(1, 1, 2)]);
        assert_eq!(
            events(&words),
            [
                PixyEvent::FrameStart,
                PixyEvent::Block(cc),
                PixyEvent::Block(block(1, 1, 2))
            ]
        );
    }

    #[test]
    fn consecutive_frames_each_start_with_a_double_sync() {
        let (a, b) = (block(1, 10, 10), block(1, 20, 20));
        let mut words = frame(&[a]);
        words.extend(frame(&[b]));
        assert_eq!(
            events(&words),
            [
                PixyEvent::FrameStart,
                PixyEvent::Block(a),
                PixyEvent::FrameStart,
                PixyEvent::Block(b)
            ]
        );
    }

    #[test]
    fn zero_block_frames_and_silence() {
        assert_eq!(events(&[0, 0]), [PixyEvent::Idle, PixyEvent::Idle]);
        assert_eq!(
            events(&[SYNC, SYNC, 0]),
            [PixyEvent::FrameStart, PixyEvent::Idle]
        );
    }

    #[test]
    fn a_bad_checksum_drops_only_that_block() {
        let (a, b) = (block(1, 10, 10), block(2, 30, 40));
        let mut words = frame(&[a, b]);
        words[3] ^= 1; // a's signature
        assert_eq!(
            events(&words),
            [
                PixyEvent::FrameStart,
                PixyEvent::BadChecksum,
                PixyEvent::Block(b)
            ]
        );
    }

    #[test]
    fn resynchronises_after_garbage_and_reports_byte_slips() {
        let a = block(3, 1, 2);
        let mut words = std::vec![0x1234, SYNC, 0x9999, 0xFFFF, SYNC_CC];
        words.extend(frame(&[a]));
        assert_eq!(events(&words), [PixyEvent::FrameStart, PixyEvent::Block(a)]);
        assert_eq!(events(&[0x1111, SYNC_SWAPPED]), [PixyEvent::Misaligned]);
        // Garbage where the next block's sync is due drops back to seeking.
        let mut words = frame(&[a]);
        words.push(0x4242);
        words.extend(frame(&[a]));
        assert_eq!(
            events(&words),
            [
                PixyEvent::FrameStart,
                PixyEvent::Block(a),
                PixyEvent::FrameStart,
                PixyEvent::Block(a)
            ]
        );
    }

    proptest! {
        #[test]
        fn never_panics_and_recovers(garbage in proptest::collection::vec(any::<u16>(), 0..200), x in 0u16..320, y in 0u16..200) {
            let mut p = PixyParser::new();
            for w in &garbage {
                let _ = p.push(*w);
            }
            // A moment of silence (the camera sends zeros when idle), then a
            // clean frame, is always understood.
            let a = block(1, x, y);
            let mut words = std::vec![0u16; 8];
            words.extend(frame(&[a]));
            let got: std::vec::Vec<_> = words.iter().filter_map(|w| p.push(*w)).collect();
            prop_assert!(got.ends_with(&[PixyEvent::FrameStart, PixyEvent::Block(a)]), "{:?}", got);
        }
    }
}
