//! The recorded-log file `host monitor` writes and `host replay` reads
//! (format described in `docs/robot-logs.md`):
//!
//! ```text
//! header:  "ZUMOLOG" 0x00 | format version (1 byte, 1)
//! record:  COBS( host time (u64 LE, microseconds since the Unix epoch)
//!              | frame bytes as received (the robot's COBS frame, without its 0x00)
//!              | CRC-16/IBM-3740 (LE) of the time and frame bytes ) | 0x00
//! ```
//!
//! Records are appended one `write` each, so a crash loses at most the
//! record being written; a record cut short or damaged is found by its CRC
//! and skipped, and the next `0x00` resynchronises. The frame bytes are kept
//! as received, undecoded, so a replay sees exactly what came off the wire.
//!
//! A file without the header is read as a raw capture of the serial line
//! (`cat /dev/ttyUSB0 > x.bin`): the robot's frames split at `0x00`, with no
//! host times.

use super::frame_splitter::{Chunk, ChunkEnd, FrameSplitter, MAX_CHUNK};
use anyhow::{bail, Context, Result};
use crc::{Crc, CRC_16_IBM_3740};
use shared::LogFrame;
use sim::base::ranges;
use std::fmt;
use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The first bytes of a recorded log. The `0x00` makes it impossible for a
/// raw capture to start with them (no robot frame is 7 bytes long).
pub const MAGIC: [u8; 8] = *b"ZUMOLOG\0";
/// The format version this build writes and reads.
pub const VERSION: u8 = 1;
/// Header length: magic and version.
pub const HEADER_LEN: usize = MAGIC.len() + 1;
/// Bytes of a record payload around the frame: host time and CRC.
const RECORD_OVERHEAD: usize = 8 + 2;
/// Longest record (without its terminator): the record of the longest
/// chunk the monitor keeps ([`MAX_CHUNK`]). Reading splits at this limit,
/// so every record the monitor writes reads back whole, and only a
/// damaged file has a longer one.
pub const MAX_RECORD_LEN: usize = cobs::max_encoding_length(RECORD_OVERHEAD + MAX_CHUNK);
/// Records are forced to the disk at most this often (a process crash
/// loses nothing already written; a power cut at most this much).
const SYNC_EVERY: Duration = Duration::from_secs(1);

const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

/// Microseconds since the Unix epoch, the records' host time.
pub fn host_time_us() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_micros()).unwrap_or(u64::MAX))
}

/// Encodes one record, its `0x00` terminator included.
pub fn encode_record(host_time_us: u64, frame: &[u8]) -> Vec<u8> {
    let mut payload = Vec::with_capacity(frame.len() + RECORD_OVERHEAD);
    payload.extend_from_slice(&host_time_us.to_le_bytes());
    payload.extend_from_slice(frame);
    let crc = CRC16.checksum(&payload);
    payload.extend_from_slice(&crc.to_le_bytes());
    let mut out = vec![0u8; cobs::max_encoding_length(payload.len()) + 1];
    let n = cobs::encode(&payload, &mut out);
    out.truncate(n + 1);
    out[n] = 0;
    out
}

/// Appends records to a recorded-log file.
pub struct LogWriter {
    file: File,
    path: PathBuf,
    last_sync: Instant,
}

impl LogWriter {
    /// Creates `path` with a header, or with `append` adds to an existing
    /// recorded log (checking its header; created if missing). Refuses to
    /// overwrite an existing file without `append`.
    pub fn create(path: &Path, append: bool) -> Result<LogWriter> {
        let existing = std::fs::metadata(path).ok().map(|m| m.len());
        if existing.is_some() && !append {
            bail!(
                "log file {} already exists: choose another --out, or pass --append to add to it",
                path.display()
            );
        }
        let has_content = existing.is_some_and(|len| len > 0);
        if has_content {
            let mut header = [0u8; HEADER_LEN];
            let mut f = File::open(path)
                .with_context(|| format!("cannot open log file {}", path.display()))?;
            let n = read_up_to(&mut f, &mut header)
                .with_context(|| format!("cannot read log file {}", path.display()))?;
            check_header(&header[..n])
                .with_context(|| format!("cannot append to {}", path.display()))?;
        }
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .with_context(|| format!("cannot open log file {} for writing", path.display()))?;
        let mut w = LogWriter {
            file,
            path: path.to_path_buf(),
            last_sync: Instant::now(),
        };
        if has_content {
            // Ends a record a crash may have cut short, so that it does not
            // swallow the first new one (an empty record is skipped).
            w.write(&[0])?;
        } else {
            let mut header = MAGIC.to_vec();
            header.push(VERSION);
            w.write(&header)?;
        }
        w.file
            .sync_all()
            .with_context(|| format!("cannot flush log file {}", path.display()))?;
        Ok(w)
    }

    /// Appends one frame as received, stamped with `host_time_us`: one
    /// `write` of the whole record, then at most once a second an `fsync`.
    pub fn append(&mut self, host_time_us: u64, frame: &[u8]) -> Result<()> {
        self.write(&encode_record(host_time_us, frame))?;
        if self.last_sync.elapsed() >= SYNC_EVERY {
            self.sync()?;
        }
        Ok(())
    }

    /// Forces everything written so far to the disk.
    pub fn sync(&mut self) -> Result<()> {
        self.last_sync = Instant::now();
        self.file
            .sync_data()
            .with_context(|| format!("cannot flush log file {}", self.path.display()))
    }

    fn write(&mut self, bytes: &[u8]) -> Result<()> {
        self.file
            .write_all(bytes)
            .with_context(|| format!("cannot write log file {}", self.path.display()))
    }
}

fn read_up_to(f: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// What kind of file was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceKind {
    /// A recorded log of this format version.
    Recorded,
    /// A raw capture of the serial line.
    RawCapture,
}

impl fmt::Display for SourceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SourceKind::Recorded => write!(f, "recorded log (format version {VERSION})"),
            SourceKind::RawCapture => f.write_str("raw serial capture"),
        }
    }
}

/// Why a record of a recorded log was skipped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// The file ends inside the record (no terminator) and what is there
    /// does not check out: the recording stopped mid-write.
    Truncated,
    /// Not valid COBS.
    BadCobs,
    /// Too short for a host time, a frame byte and a CRC.
    TooShort(usize),
    /// Longer than any record the monitor writes ([`MAX_RECORD_LEN`]): no
    /// terminator where there should be one (damaged).
    TooLong,
    /// The record's CRC does not match: damaged on disk.
    CrcMismatch {
        /// CRC in the record.
        stored: u16,
        /// CRC of its content.
        computed: u16,
    },
}

impl fmt::Display for RecordError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            RecordError::Truncated => {
                f.write_str("record truncated: the file ends before its terminator")
            }
            RecordError::BadCobs => f.write_str("record is not valid COBS"),
            RecordError::TooShort(n) => write!(f, "record of {n} bytes is too short"),
            RecordError::TooLong => write!(
                f,
                "record has no terminator within {MAX_RECORD_LEN} bytes, the longest the monitor writes"
            ),
            RecordError::CrcMismatch { stored, computed } => {
                write!(
                    f,
                    "record is corrupt: CRC-16 is {computed:#06x}, record says {stored:#06x}"
                )
            }
        }
    }
}

/// One record (or, in a raw capture, one chunk between delimiters).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Byte offset of the record or chunk in the file.
    pub offset: u64,
    /// Its length in the file, without the terminator.
    pub len: usize,
    /// Host time in microseconds since the Unix epoch (recorded logs only).
    pub host_time_us: Option<u64>,
    /// The robot frame's bytes as received, or why the record was skipped.
    pub frame: Result<Vec<u8>, RecordError>,
}

impl Entry {
    /// The robot's frame, if the record is whole and its frame decodes.
    pub fn log_frame(&self) -> Option<LogFrame> {
        LogFrame::decode(self.frame.as_ref().ok()?).ok()
    }
}

/// A whole file, split into entries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Recording {
    /// Recorded log or raw capture.
    pub kind: SourceKind,
    /// Every record or chunk, in file order.
    pub entries: Vec<Entry>,
}

fn check_header(bytes: &[u8]) -> Result<()> {
    if !MAGIC.starts_with(&bytes[..bytes.len().min(MAGIC.len())]) {
        bail!("not a recorded log (it does not start with \"ZUMOLOG\\0\")");
    }
    if bytes.len() < HEADER_LEN {
        bail!(
            "the recorded-log header is truncated ({} of {HEADER_LEN} bytes)",
            bytes.len()
        );
    }
    let version = bytes[MAGIC.len()];
    if version != VERSION {
        bail!("recorded-log format version {version} is not supported (this build reads version {VERSION})");
    }
    Ok(())
}

/// Splits a file's bytes into entries. Fails only on a header that cannot
/// be read (truncated, another format version); damaged records become
/// entries with an error.
pub fn parse(bytes: &[u8]) -> Result<Recording> {
    let mut entries = Vec::new();
    let kind = split(bytes, None, &mut |e| entries.push(e))?;
    Ok(Recording { kind, entries })
}

/// Bytes read from the file at a time.
const READ_BLOCK: usize = 64 * 1024;

/// Splits what `reader` gives into entries, handing each to `visit` as it
/// is read (memory does not grow with the file), and refuses more than
/// `limit` bytes; returns what kind of file it is. Errors as [`parse`]'s,
/// and the reader's.
fn split(
    mut reader: impl Read,
    limit: Option<&'static ranges::Range>,
    visit: &mut dyn FnMut(Entry),
) -> Result<SourceKind> {
    let mut first = [0u8; HEADER_LEN];
    let n = read_up_to(&mut reader, &mut first)?;
    let first = &first[..n];
    let starts_like_header = n > 0 && MAGIC.starts_with(&first[..n.min(MAGIC.len())]);
    let (kind, mut splitter) = if starts_like_header {
        check_header(first)?;
        let splitter = FrameSplitter::with_limit(HEADER_LEN as u64, MAX_RECORD_LEN);
        (SourceKind::Recorded, splitter)
    } else {
        (SourceKind::RawCapture, FrameSplitter::new())
    };
    let entry = |chunk: Chunk| match kind {
        SourceKind::Recorded => decode_record(&chunk),
        SourceKind::RawCapture => Entry {
            offset: chunk.offset,
            len: chunk.bytes.len(),
            host_time_us: None,
            frame: Ok(chunk.bytes),
        },
    };
    if kind == SourceKind::RawCapture {
        splitter
            .push(first)
            .into_iter()
            .map(entry)
            .for_each(&mut *visit);
    }
    let mut total = n as u64;
    let mut block = vec![0u8; READ_BLOCK];
    loop {
        let n = match reader.read(&mut block) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        };
        total += n as u64;
        if let Some(limit) = limit.filter(|l| total as f64 > l.max) {
            return Err(ranges::too_large(limit).into());
        }
        splitter
            .push(&block[..n])
            .into_iter()
            .map(entry)
            .for_each(&mut *visit);
    }
    splitter.finish().into_iter().map(entry).for_each(visit);
    Ok(kind)
}

fn decode_record(chunk: &Chunk) -> Entry {
    let mut payload = vec![0u8; chunk.bytes.len()];
    let checked = match cobs::decode(&chunk.bytes, &mut payload) {
        Err(_) => Err(RecordError::BadCobs),
        Ok(n) if n <= RECORD_OVERHEAD => Err(RecordError::TooShort(n)),
        Ok(n) => {
            let stored = u16::from_le_bytes([payload[n - 2], payload[n - 1]]);
            let computed = CRC16.checksum(&payload[..n - 2]);
            if stored == computed {
                Ok(n)
            } else {
                Err(RecordError::CrcMismatch { stored, computed })
            }
        }
    };
    let entry = |host_time_us, frame| Entry {
        offset: chunk.offset,
        len: chunk.bytes.len(),
        host_time_us,
        frame,
    };
    match checked {
        // a piece of a run longer than any record the monitor writes
        _ if chunk.end == ChunkEnd::Cut => entry(None, Err(RecordError::TooLong)),
        Ok(n) => {
            let mut time = [0u8; 8];
            time.copy_from_slice(&payload[..8]);
            entry(
                Some(u64::from_le_bytes(time)),
                Ok(payload[8..n - 2].to_vec()),
            )
        }
        Err(_) if chunk.end == ChunkEnd::StreamEnd => entry(None, Err(RecordError::Truncated)),
        Err(e) => entry(None, Err(e)),
    }
}

/// Reads and splits a recorded log or raw capture; errors name the file.
pub fn read(path: &Path) -> Result<Recording> {
    let mut entries = Vec::new();
    let kind = read_each(path, &ranges::LOG_FILE, &mut |e| entries.push(e))?;
    Ok(Recording { kind, entries })
}

/// Reads a recorded log or raw capture of at most `limit` bytes entry by
/// entry, handing each to `visit` as it is read: memory does not grow
/// with the file. Returns what kind of file it is; errors name the file.
pub fn read_each(
    path: &Path,
    limit: &'static ranges::Range,
    visit: &mut dyn FnMut(Entry),
) -> Result<SourceKind> {
    let file =
        File::open(path).with_context(|| format!("cannot read log file {}", path.display()))?;
    split(file, Some(limit), visit).with_context(|| format!("log file {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file_of(records: &[(u64, &[u8])]) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.push(VERSION);
        for (t, f) in records {
            bytes.extend(encode_record(*t, f));
        }
        bytes
    }

    const FRAMES: [(u64, &[u8]); 3] = [
        (1_000_000, &[3, 1, 2, 9]),
        (0x0100_0000_0000_0000, &[1]),
        (7, &[5; 300]),
    ];

    #[test]
    fn records_round_trip_with_offsets() {
        let bytes = file_of(&FRAMES);
        let rec = parse(&bytes).unwrap();
        assert_eq!(rec.kind, SourceKind::Recorded);
        assert_eq!(rec.entries.len(), 3);
        for (e, (t, f)) in rec.entries.iter().zip(FRAMES) {
            assert_eq!((e.host_time_us, e.frame.as_deref()), (Some(t), Ok(f)));
        }
        assert_eq!(rec.entries[0].offset, HEADER_LEN as u64);
        assert_eq!(
            rec.entries[1].offset,
            (HEADER_LEN + encode_record(FRAMES[0].0, FRAMES[0].1).len()) as u64
        );
    }

    #[test]
    fn the_longest_chunk_the_monitor_records_reads_back_as_one_record() {
        // the monitor's limit (MAX_CHUNK) and the reader's (MAX_RECORD_LEN)
        // are one rule: before, this record read back as two damaged
        // entries, one of them "ends before its terminator"
        let longest = vec![0x55u8; MAX_CHUNK];
        let bytes = file_of(&[(1, &longest), (2, &[1, 2])]);
        let rec = parse(&bytes).unwrap();
        assert_eq!(rec.entries.len(), 2);
        assert_eq!(rec.entries[0].frame.as_deref(), Ok(&longest[..]));
        assert_eq!(rec.entries[1].frame.as_deref(), Ok(&[1u8, 2][..]));
    }

    #[test]
    fn a_damaged_run_longer_than_any_record_is_named_as_such() {
        let mut bytes = file_of(&[(1, &[3, 1])]);
        bytes.extend(vec![0x55u8; MAX_RECORD_LEN + 10]);
        bytes.push(0);
        bytes.extend(encode_record(2, &[4, 5]));
        let rec = parse(&bytes).unwrap();
        let frames: Vec<_> = rec.entries.iter().map(|e| e.frame.clone()).collect();
        assert_eq!(
            frames,
            [
                Ok(vec![3, 1]),
                Err(RecordError::TooLong),
                Err(RecordError::TooLong),
                Ok(vec![4, 5])
            ]
        );
        assert!(RecordError::TooLong
            .to_string()
            .contains("no terminator within"));
    }

    #[test]
    fn every_truncation_is_an_error_or_loses_only_the_last_record() {
        let bytes = file_of(&FRAMES);
        for len in 0..bytes.len() {
            match parse(&bytes[..len]) {
                Err(e) => assert!(
                    len > 0 && len < HEADER_LEN && e.to_string().contains("truncated"),
                    "{len}: {e}"
                ),
                Ok(rec) if len == 0 => assert!(rec.entries.is_empty()),
                Ok(rec) => {
                    let good: Vec<_> = rec.entries.iter().filter(|e| e.frame.is_ok()).collect();
                    let bad: Vec<_> = rec.entries.iter().filter(|e| e.frame.is_err()).collect();
                    assert!(bad.len() <= 1, "{len}");
                    for b in bad {
                        assert_eq!(b.frame, Err(RecordError::Truncated), "{len}");
                    }
                    for (e, (t, f)) in good.iter().zip(FRAMES) {
                        assert_eq!(
                            (e.host_time_us, e.frame.as_deref()),
                            (Some(t), Ok(f)),
                            "{len}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn every_bit_flip_after_the_header_damages_at_most_two_records_and_never_passes_unnoticed() {
        let bytes = file_of(&FRAMES);
        let clean = parse(&bytes).unwrap();
        for i in HEADER_LEN..bytes.len() {
            for bit in 0..8 {
                let mut bad = bytes.clone();
                bad[i] ^= 1 << bit;
                let rec = parse(&bad).unwrap();
                let good: Vec<&Entry> = rec.entries.iter().filter(|e| e.frame.is_ok()).collect();
                // A flip can join two records (terminator lost) or split one
                // (a zero appears): never more than two lost, never a wrong one kept.
                assert!(good.len() + 2 >= clean.entries.len(), "byte {i} bit {bit}");
                for e in good {
                    assert!(clean
                        .entries
                        .iter()
                        .any(|c| c.frame == e.frame && c.host_time_us == e.host_time_us));
                }
            }
        }
    }

    #[test]
    fn another_version_and_raw_captures() {
        let mut bytes = file_of(&FRAMES);
        bytes[MAGIC.len()] = 2;
        let e = parse(&bytes).unwrap_err().to_string();
        assert!(e.contains("version 2 is not supported"), "{e}");
        let raw = parse(&[0, 4, 5, 0, 6]).unwrap();
        assert_eq!(raw.kind, SourceKind::RawCapture);
        assert_eq!(
            raw.entries
                .iter()
                .map(|e| (e.offset, e.frame.clone().unwrap()))
                .collect::<Vec<_>>(),
            vec![(1, vec![4, 5]), (4, vec![6])]
        );
    }

    #[test]
    fn the_writer_appends_and_refuses_to_overwrite() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.log");
        let mut w = LogWriter::create(&path, false).unwrap();
        w.append(FRAMES[0].0, FRAMES[0].1).unwrap();
        drop(w);
        let e = LogWriter::create(&path, false).err().unwrap().to_string();
        assert!(e.contains("already exists") && e.contains("run.log"), "{e}");
        // A crash cut the last record short: appending loses only that one.
        let mut cut = std::fs::read(&path).unwrap();
        cut.extend(&encode_record(9, &[1, 2, 3])[..5]);
        std::fs::write(&path, &cut).unwrap();
        let mut w = LogWriter::create(&path, true).unwrap();
        w.append(FRAMES[1].0, FRAMES[1].1).unwrap();
        w.sync().unwrap();
        let rec = read(&path).unwrap();
        assert_eq!(rec.entries.len(), 3);
        assert!(rec.entries[1].frame.is_err());
        for (e, (t, f)) in [&rec.entries[0], &rec.entries[2]].into_iter().zip(FRAMES) {
            assert_eq!((e.host_time_us, e.frame.as_deref()), (Some(t), Ok(f)));
        }
        let other = dir.path().join("other.bin");
        std::fs::write(&other, b"hello").unwrap();
        let e = format!("{:#}", LogWriter::create(&other, true).err().unwrap());
        assert!(
            e.contains("other.bin") && e.contains("not a recorded log"),
            "{e}"
        );
    }
}
