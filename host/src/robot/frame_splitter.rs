//! Splits a byte stream at `0x00` delimiters into chunks, the frames of the
//! robot's log (COBS never produces `0x00` inside a frame), remembering
//! where in the stream each chunk started.

/// Longest chunk of the serial line that can be a frame: far over any log
/// frame (`shared::LogFrame::MAX_ENCODED_LEN`), so a longer run between
/// delimiters is noise (a wrong baud rate, a floating line). Such a run is
/// cut into pieces of this length, so that memory stays bounded, and every
/// piece is marked [`ChunkEnd::Cut`]: the monitor neither records nor
/// counts them as frames. The one rule for both ends: the monitor records
/// chunks of at most this length, and the recorded log's record limit
/// derives from it (`log_file::MAX_RECORD_LEN`), so every record the
/// monitor writes reads back whole and only a damaged file has a longer one.
pub const MAX_CHUNK: usize = 1024;

/// How a chunk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChunkEnd {
    /// At a delimiter.
    Delimiter,
    /// A piece of a run longer than the splitter's limit (cut at the limit,
    /// or the run's last piece, up to its delimiter): noise, not a frame.
    Cut,
    /// At the stream's end, before a delimiter.
    StreamEnd,
}

/// One chunk: the bytes between two delimiters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chunk {
    /// Offset of its first byte in the stream.
    pub offset: u64,
    /// Its bytes, without the delimiter; never empty, never containing `0x00`.
    pub bytes: Vec<u8>,
    /// What ended it.
    pub end: ChunkEnd,
}

/// Incremental splitter: feed bytes as they arrive, take whole chunks out.
#[derive(Clone, Debug)]
pub struct FrameSplitter {
    pending: Vec<u8>,
    pending_offset: u64,
    position: u64,
    limit: usize,
    /// Whether the pending run was cut: its remaining pieces are noise too.
    overlong: bool,
}

impl Default for FrameSplitter {
    fn default() -> FrameSplitter {
        FrameSplitter::new()
    }
}

impl FrameSplitter {
    /// A splitter of the serial line at stream offset 0, cutting at
    /// [`MAX_CHUNK`].
    pub fn new() -> FrameSplitter {
        FrameSplitter::with_limit(0, MAX_CHUNK)
    }

    /// A splitter whose first byte is at `offset` of the stream, cutting
    /// chunks at `limit` bytes.
    pub fn with_limit(offset: u64, limit: usize) -> FrameSplitter {
        FrameSplitter {
            pending: Vec::new(),
            pending_offset: offset,
            position: offset,
            limit,
            overlong: false,
        }
    }

    /// Feeds bytes; returns the chunks they complete, in order.
    pub fn push(&mut self, bytes: &[u8]) -> Vec<Chunk> {
        let mut out = Vec::new();
        for &b in bytes {
            let at = self.position;
            self.position += 1;
            if b == 0 {
                if !self.pending.is_empty() {
                    let end = if self.overlong {
                        ChunkEnd::Cut
                    } else {
                        ChunkEnd::Delimiter
                    };
                    out.push(self.take(end));
                }
                self.overlong = false;
                self.pending_offset = self.position;
            } else {
                // cut only when a byte beyond the limit comes: a chunk of
                // exactly the limit's length still ends at its delimiter
                if self.pending.len() == self.limit {
                    out.push(self.take(ChunkEnd::Cut));
                    self.overlong = true;
                    self.pending_offset = at;
                }
                self.pending.push(b);
            }
        }
        out
    }

    /// Ends the stream: returns the bytes after the last delimiter as an
    /// unterminated chunk (a piece of noise if its run was cut), if any.
    pub fn finish(&mut self) -> Option<Chunk> {
        let end = if self.overlong {
            ChunkEnd::Cut
        } else {
            ChunkEnd::StreamEnd
        };
        self.overlong = false;
        (!self.pending.is_empty()).then(|| self.take(end))
    }

    /// Drops a partial chunk (the stream was interrupted: what follows does
    /// not continue it).
    pub fn discard_partial(&mut self) {
        self.pending.clear();
        self.overlong = false;
        self.pending_offset = self.position;
    }

    fn take(&mut self, end: ChunkEnd) -> Chunk {
        Chunk {
            offset: self.pending_offset,
            bytes: std::mem::take(&mut self.pending),
            end,
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
                    end: ChunkEnd::Delimiter
                },
                Chunk {
                    offset: 5,
                    bytes: vec![3],
                    end: ChunkEnd::Delimiter
                },
                Chunk {
                    offset: 7,
                    bytes: vec![4, 5],
                    end: ChunkEnd::StreamEnd
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
        let mut s = FrameSplitter::with_limit(10, MAX_CHUNK);
        let chunks = s.push(&vec![7u8; MAX_CHUNK * 2 + 3]);
        assert_eq!(chunks.len(), 2);
        assert_eq!(
            (chunks[1].offset, chunks[1].end),
            (10 + MAX_CHUNK as u64, ChunkEnd::Cut)
        );
        s.discard_partial();
        assert_eq!(
            s.push(&[9, 0]),
            vec![Chunk {
                offset: 10 + 2 * MAX_CHUNK as u64 + 3,
                bytes: vec![9],
                end: ChunkEnd::Delimiter
            }]
        );
        assert_eq!(s.finish(), None);
    }

    #[test]
    fn every_piece_of_a_run_longer_than_the_limit_is_marked_cut() {
        let mut s = FrameSplitter::with_limit(0, 4);
        let chunks = s.push(&[1, 2, 3, 4, 0, 1, 2, 3, 4, 5, 6, 0, 8, 0]);
        let ends: Vec<(usize, ChunkEnd)> = chunks.iter().map(|c| (c.bytes.len(), c.end)).collect();
        assert_eq!(
            ends,
            [
                (4, ChunkEnd::Delimiter),
                (4, ChunkEnd::Cut),
                (2, ChunkEnd::Cut),
                (1, ChunkEnd::Delimiter)
            ]
        );
        s.push(&[1, 2, 3, 4, 5]);
        assert_eq!(s.finish().map(|c| c.end), Some(ChunkEnd::Cut));
    }
}
