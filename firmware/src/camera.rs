//! Reading the Pixy once per control period: which blocks the decision
//! uses, bounded in time.
//!
//! Each period reads words until the camera has nothing more (a zero word),
//! [`PIXY_MAX_BLOCKS`] blocks of the current frame are in, or
//! [`PIXY_MAX_WORDS`] words were read. A frame start replaces the kept
//! blocks; blocks are kept for [`PIXY_HOLD_PERIODS`] periods, because the
//! camera's 50 frames/s and the control loop drift against each other (a
//! period may see no new frame), while a camera that stops seeing an
//! object sends nothing at all, which must clear it.

use crate::config::{PIXY_HOLD_PERIODS, PIXY_MAX_BLOCKS, PIXY_MAX_WORDS};
use crate::pixy::{PixyEvent, PixyParser};
use shared::PixyBlock;

/// Why the camera could not be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BusError {
    /// The camera did not acknowledge its address.
    Nack,
    /// A bus step did not complete in time (the bus is stalled).
    Stalled,
    /// A device held SDA low and clocking SCL did not free it.
    Stuck,
    /// A step ended in a state the transaction does not allow (arbitration
    /// lost, a bus error, a byte acknowledged other than asked).
    Unexpected,
}

/// Where words come from: the board's TWI driver, or a test's script.
pub trait WordSource {
    /// Reads one 16-bit word.
    fn read_word(&mut self) -> Result<u16, BusError>;
    /// Reads and drops one byte (after [`PixyEvent::Misaligned`]).
    fn skip_byte(&mut self) -> Result<(), BusError>;
}

/// The blocks of the latest frame and the parser's state.
#[derive(Clone, Debug)]
pub struct Camera {
    parser: PixyParser,
    blocks: [PixyBlock; PIXY_MAX_BLOCKS],
    len: u8,
    /// Periods since the kept frame started.
    age: u8,
}

impl Default for Camera {
    fn default() -> Camera {
        Camera::new()
    }
}

impl Camera {
    /// Nothing seen yet.
    pub const fn new() -> Camera {
        Camera {
            parser: PixyParser::new(),
            blocks: [PixyBlock {
                signature: 0,
                x: 0,
                y: 0,
                width: 0,
                height: 0,
                angle: 0,
            }; PIXY_MAX_BLOCKS],
            len: 0,
            age: PIXY_HOLD_PERIODS,
        }
    }

    /// One period's read. On a bus error the kept blocks still age.
    pub fn acquire<S: WordSource>(&mut self, source: &mut S) -> Result<(), BusError> {
        self.age = self.age.saturating_add(1);
        let result = self.read(source);
        if self.age >= PIXY_HOLD_PERIODS {
            self.len = 0;
        }
        result
    }

    fn read<S: WordSource>(&mut self, source: &mut S) -> Result<(), BusError> {
        for _ in 0..PIXY_MAX_WORDS {
            match self.parser.push(source.read_word()?) {
                Some(PixyEvent::FrameStart) => {
                    self.len = 0;
                    self.age = 0;
                }
                Some(PixyEvent::Block(block)) => {
                    if let Some(slot) = self.blocks.get_mut(usize::from(self.len)) {
                        *slot = block;
                        self.len += 1;
                    }
                    if usize::from(self.len) == PIXY_MAX_BLOCKS {
                        return Ok(());
                    }
                }
                Some(PixyEvent::Misaligned) => source.skip_byte()?,
                Some(PixyEvent::Idle) => return Ok(()),
                Some(PixyEvent::BadChecksum) | None => {}
            }
        }
        Ok(())
    }

    /// The blocks the decision uses, largest first (the camera's order).
    pub fn blocks(&self) -> &[PixyBlock] {
        self.blocks.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::pixy::encode_frame;
    use std::collections::VecDeque;

    /// A camera that serves queued words, then zeros; or fails.
    struct Script {
        words: VecDeque<u16>,
        error: Option<BusError>,
        reads: usize,
    }

    impl Script {
        fn new() -> Script {
            Script {
                words: VecDeque::new(),
                error: None,
                reads: 0,
            }
        }
        fn frame(&mut self, blocks: &[PixyBlock]) {
            let mut buf = [0u16; 128];
            let n = encode_frame(blocks, &mut buf);
            self.words.extend(&buf[..n]);
        }
    }

    impl WordSource for Script {
        fn read_word(&mut self) -> Result<u16, BusError> {
            self.reads += 1;
            match self.error {
                Some(e) => Err(e),
                None => Ok(self.words.pop_front().unwrap_or(0)),
            }
        }
        fn skip_byte(&mut self) -> Result<(), BusError> {
            Ok(())
        }
    }

    fn block(x: u16) -> PixyBlock {
        PixyBlock {
            signature: 1,
            x,
            y: 150,
            width: 10,
            height: 10,
            angle: 0,
        }
    }

    #[test]
    fn a_frame_is_used_then_expires_when_the_camera_goes_quiet() {
        let (mut cam, mut src) = (Camera::new(), Script::new());
        assert_eq!(cam.acquire(&mut src), Ok(()));
        assert!(cam.blocks().is_empty());
        src.frame(&[block(10), block(20)]);
        cam.acquire(&mut src).unwrap();
        assert_eq!(cam.blocks(), &[block(10), block(20)]);
        // One period without a new frame keeps it, the next one drops it.
        cam.acquire(&mut src).unwrap();
        assert_eq!(cam.blocks().len(), 2);
        cam.acquire(&mut src).unwrap();
        assert!(cam.blocks().is_empty());
    }

    #[test]
    fn a_new_frame_replaces_the_old_one() {
        let (mut cam, mut src) = (Camera::new(), Script::new());
        src.frame(&[block(10), block(20)]);
        cam.acquire(&mut src).unwrap();
        src.frame(&[block(30)]);
        cam.acquire(&mut src).unwrap();
        assert_eq!(cam.blocks(), &[block(30)]);
    }

    #[test]
    fn reading_is_capped_in_blocks_and_words() {
        let (mut cam, mut src) = (Camera::new(), Script::new());
        let many: std::vec::Vec<_> = (0..10).map(|i| block(i * 10)).collect();
        src.frame(&many);
        cam.acquire(&mut src).unwrap();
        assert_eq!(cam.blocks().len(), PIXY_MAX_BLOCKS);
        assert!(src.reads <= usize::from(PIXY_MAX_WORDS));
        // Endless garbage costs at most the word cap.
        let (mut cam, mut src) = (Camera::new(), Script::new());
        src.words.extend(core::iter::repeat_n(0x1234, 1000));
        cam.acquire(&mut src).unwrap();
        assert_eq!(src.reads, usize::from(PIXY_MAX_WORDS));
    }

    #[test]
    fn bus_errors_are_reported_and_kept_blocks_still_expire() {
        let (mut cam, mut src) = (Camera::new(), Script::new());
        src.frame(&[block(10)]);
        cam.acquire(&mut src).unwrap();
        src.error = Some(BusError::Nack);
        assert_eq!(cam.acquire(&mut src), Err(BusError::Nack));
        assert_eq!(cam.acquire(&mut src), Err(BusError::Nack));
        assert!(cam.blocks().is_empty());
    }
}
