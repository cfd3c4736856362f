//! Splits a byte stream at `0x00` delimiters into chunks, the frames of the
//! robot's log (COBS never produces `0x00` inside a frame), remembering
//! where in the stream each chunk started.

/// Longest chunk kept: far over any log frame (64 bytes), so only noise
/// (a wrong baud rate, a floating line) gets here; such a run is cut into
/// chunks of this length so that memory stays bounded.
pub const MAX_CHUNK: usize = 1024;

/// One chunk: the bytes between two delimiters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chunk {
    /// Offset of its first byte in the stream.
    pub offset: u64,
    /// Its bytes, without the delimiter; never empty, never containing `0x00`.
    pub bytes: Vec<u8>,
    /// Whether a delimiter ended it (false: cut at [`MAX_CHUNK`], or the
    /// stream's end before a delimiter).
    pub terminated: bool,
}

/// Incremental splitter: feed bytes as they arrive, take whole chunks out.
#[derive(Clone, Debug, Default)]
pub struct FrameSplitter {
    pending: Vec<u8>,
    pending_offset: u64,
    position: u64,
}

impl FrameSplitter {
    /// A splitter at stream offset 0.
    pub fn new() -> FrameSplitter {
        FrameSplitter::default()
    }

    /// A splitter whose first byte is at `offset` of the stream.
    pub fn at_offset(offset: u64) -> FrameSplitter {
        FrameSplitter {
            pending: Vec::new(),
            pending_offset: offset,
            position: offset,
        }
    }

    /// Feeds bytes; returns the chunks they complete, in order.
    pub fn push(&mut self, bytes: &[u8]) -> Vec<Chunk> {
        let mut out = Vec::new();
        for &b in bytes {
            self.position += 1;
            if b == 0 {
                if !self.pending.is_empty() {
                    out.push(self.take(true));
                }
                self.pending_offset = self.position;
            } else {
                self.pending.push(b);
                if self.pending.len() == MAX_CHUNK {
                    out.push(self.take(false));
                    self.pending_offset = self.position;
                }
            }
        }
        out
    }

    /// Ends the stream: returns the bytes after the last delimiter as an
    /// unterminated chunk, if any.
    pub fn finish(&mut self) -> Option<Chunk> {
        (!self.pending.is_empty()).then(|| self.take(false))
    }

    /// Drops a partial chunk (the stream was interrupted: what follows does
    /// not continue it).
    pub fn discard_partial(&mut self) {
        self.pending.clear();
        self.pending_offset = self.position;
    }

    fn take(&mut self, terminated: bool) -> Chunk {
        Chunk {
            offset: self.pending_offset,
            bytes: std::mem::take(&mut self.pending),
            terminated,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_have_their_offsets_whatever_the_feeding() {
        let stream = [0, 1, 2, 0, 0, 3, 0, 4, 5];
        let whole = {
            let mut s = FrameSplitter::new();
            let mut v = s.push(&stream);
            v.extend(s.finish());
            v
        };
        assert_eq!(
            whole,
            vec![
                Chunk {
                    offset: 1,
                    bytes: vec![1, 2],
                    terminated: true
                },
                Chunk {
                    offset: 5,
                    bytes: vec![3],
                    terminated: true
                },
                Chunk {
                    offset: 7,
                    bytes: vec![4, 5],
                    terminated: false
                },
            ]
        );
        let mut s = FrameSplitter::new();
        let mut bytewise: Vec<Chunk> = stream.iter().flat_map(|b| s.push(&[*b])).collect();
        bytewise.extend(s.finish());
        assert_eq!(bytewise, whole);
    }

    #[test]
    fn noise_without_delimiters_is_cut_and_a_partial_chunk_can_be_dropped() {
        let mut s = FrameSplitter::at_offset(10);
        let chunks = s.push(&vec![7u8; MAX_CHUNK * 2 + 3]);
        assert_eq!(chunks.len(), 2);
        assert_eq!(
            (chunks[1].offset, chunks[1].terminated),
            (10 + MAX_CHUNK as u64, false)
        );
        s.discard_partial();
        assert_eq!(
            s.push(&[9, 0]),
            vec![Chunk {
                offset: 10 + 2 * MAX_CHUNK as u64 + 3,
                bytes: vec![9],
                terminated: true
            }]
        );
        assert_eq!(s.finish(), None);
    }
}
