//! The log frames waiting for USART1: a bounded byte queue the control loop
//! fills with a whole frame per period and the board drains one byte at a
//! time while it waits (for the next period, a TWI step, an EEPROM write),
//! so that no period spends a frame's wire time inline.
//!
//! A full queue drops the new frame whole (never part of it, so the stream
//! stays a sequence of complete COBS frames) and counts the drop.

use heapless::Deque;

/// Bytes of log frames waiting to go out, oldest first.
pub struct LogQueue<const N: usize> {
    bytes: Deque<u8, N>,
    dropped: u16,
}

impl<const N: usize> LogQueue<N> {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            bytes: Deque::new(),
            dropped: 0,
        }
    }

    /// Queues `frame` whole, or, if it does not fit in the free room, drops
    /// it whole, counts the drop and returns `false`.
    pub fn push_frame(&mut self, frame: &[u8]) -> bool {
        if N - self.bytes.len() < frame.len() {
            self.dropped = self.dropped.saturating_add(1);
            return false;
        }
        for &byte in frame {
            // room checked above: cannot fail
            let _ = self.bytes.push_back(byte);
        }
        true
    }

    /// The oldest waiting byte, taken out of the queue.
    pub fn pop(&mut self) -> Option<u8> {
        self.bytes.pop_front()
    }

    /// Frames dropped because the queue was full (saturates at `u16::MAX`).
    pub fn dropped(&self) -> u16 {
        self.dropped
    }
}

impl<const N: usize> Default for LogQueue<N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::LogQueue;

    fn drain<const N: usize>(q: &mut LogQueue<N>) -> [u8; 16] {
        let mut out = [0u8; 16];
        let mut i = 0;
        while let Some(b) = q.pop() {
            out[i] = b;
            i += 1;
        }
        out
    }

    #[test]
    fn frames_come_out_as_the_same_bytes_in_the_same_order() {
        let mut q = LogQueue::<8>::new();
        assert!(q.push_frame(&[1, 2, 3]));
        assert!(q.push_frame(&[4, 5]));
        assert_eq!(drain(&mut q)[..6], [1, 2, 3, 4, 5, 0]);
        assert_eq!(q.dropped(), 0);
    }

    #[test]
    fn a_frame_that_does_not_fit_is_dropped_whole_and_counted() {
        let mut q = LogQueue::<6>::new();
        assert!(q.push_frame(&[1, 2, 3, 4]));
        assert!(!q.push_frame(&[5, 6, 7]));
        assert_eq!(q.dropped(), 1);
        // the queue holds only the first frame, untouched
        assert_eq!(drain(&mut q)[..5], [1, 2, 3, 4, 0]);
        // once drained there is room again
        assert!(q.push_frame(&[5, 6, 7]));
        assert_eq!(drain(&mut q)[..4], [5, 6, 7, 0]);
    }

    #[test]
    fn a_frame_filling_exactly_the_free_room_is_queued() {
        let mut q = LogQueue::<4>::new();
        assert!(q.push_frame(&[9]));
        assert!(q.push_frame(&[8, 7, 6]));
        assert!(!q.push_frame(&[5]));
        assert_eq!(drain(&mut q)[..5], [9, 8, 7, 6, 0]);
    }

    #[test]
    fn the_drop_count_saturates() {
        let mut q = LogQueue::<1>::new();
        for _ in 0..u16::MAX as u32 + 5 {
            q.push_frame(&[1, 2]);
        }
        assert_eq!(q.dropped(), u16::MAX);
    }
}
