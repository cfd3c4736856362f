//! The checkpoint file: a complete [`TrainingState`], from which training
//! resumes bit for bit.
//!
//! Layout (integers little-endian):
//!
//! | offset | size | content                                              |
//! |--------|------|------------------------------------------------------|
//! | 0      | 8    | magic `ZSWMCKPT`                                     |
//! | 8      | 2    | format version (1 to 7), u16                         |
//! | 10     | 8    | body length `n`, u64                                 |
//! | 18     | n    | body: the [`TrainingState`], postcard-encoded        |
//! | 18 + n | 4    | CRC-32 (ISO-HDLC, as zlib) of bytes `0 .. 18 + n`    |
//!
//! Format 7 has the [`TrainingState`] as body; formats 1 to 6 are the
//! state without the settings added since ([`super::format1`],
//! [`super::format2`], [`super::format3`], [`super::format4`], and
//! [`super::format6`] for 5 and 6, 6 for the rewards format 5's readers
//! cannot decode). A state is written in the oldest format that holds it,
//! byte for byte what earlier builds wrote; all seven are read.
//!
//! postcard stores every `f64` as its 8 IEEE bytes, so values round-trip
//! bit-exactly. Files are written atomically (temporary file, then rename):
//! a run killed at any moment leaves the old checkpoint or the new one.

use super::format1::StateV1;
use super::format2::StateV2;
use super::format3::StateV3;
use super::format4::StateV4;
use super::format6::StateV6;
use super::trainer::TrainingState;
use anyhow::{Context, Result};
use crc::{Crc, CRC_32_ISO_HDLC};
use sim::base::ranges;
use std::fmt;
use std::io::Write;
use std::path::Path;

/// The first eight bytes of every checkpoint.
pub const MAGIC: [u8; 8] = *b"ZSWMCKPT";
/// The newest format version, which this build writes when no older one
/// holds the state; it reads them all. 2: the settings of how the thesis
/// was run and the world config of a rectangular arena (width, height, the
/// field's frame and sampling, puck mass, millimetres per unit). 3: the
/// run's arena and noise, the counts left to the arena, the motion noise,
/// the world's seed, episode count and dropped-period turns, the robot
/// senses' memory. 4: the arena's border (`walls`) and the learner's
/// rules (`rules`). 5: the robots' outline (`robot_shape`: a wedge) and
/// decaying exploration (`epsilon_decay`); disc states of constant
/// exploration keep format 4 or older. 6: the rewards `per-robot`,
/// `success` and `success-shaped` (the same layout as 5, with reward
/// variants format 5's readers do not know). 7: n-step returns (`n_step`,
/// and each robot's steps waiting for their update).
pub const VERSION: u16 = 7;
const HEADER_LEN: usize = 18;
const CRC_LEN: usize = 4;
const CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);

/// Why bytes are not a checkpoint this build can resume from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CheckpointError {
    /// The input ends before the checkpoint does (a torn or cut file).
    Truncated {
        /// Bytes the checkpoint needs.
        needed: u64,
        /// Bytes there are.
        found: u64,
    },
    /// The file is a policy blob, which holds no Q-values.
    PolicyBlob,
    /// The first bytes are not the checkpoint magic: some other file.
    WrongMagic,
    /// A format version this build does not read.
    UnsupportedVersion(u16),
    /// Bytes after the end the header declares.
    TrailingBytes {
        /// Length the header declares, CRC included.
        expected: u64,
        /// Length of the input.
        found: u64,
    },
    /// The stored CRC does not match the content.
    CrcMismatch {
        /// CRC stored in the file.
        stored: u32,
        /// CRC of the content.
        computed: u32,
    },
    /// The body does not decode as a training state.
    Malformed(String),
}

impl fmt::Display for CheckpointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckpointError::Truncated { needed, found } => {
                write!(
                    f,
                    "checkpoint is truncated: {found} bytes, the checkpoint needs {needed}"
                )
            }
            CheckpointError::PolicyBlob => {
                f.write_str("this is a policy blob, not a checkpoint (it holds no Q-values)")
            }
            CheckpointError::WrongMagic => {
                f.write_str("not a checkpoint: the file does not start with ZSWMCKPT")
            }
            CheckpointError::UnsupportedVersion(v) => {
                write!(f, "checkpoint format version {v} is not supported (this build reads versions 1 to {VERSION})")
            }
            CheckpointError::TrailingBytes { expected, found } => {
                write!(
                    f,
                    "checkpoint has {found} bytes, {} more than its header declares",
                    found - expected
                )
            }
            CheckpointError::CrcMismatch { stored, computed } => {
                write!(f, "checkpoint is corrupt: CRC-32 is {computed:#010x}, the file says {stored:#010x}")
            }
            CheckpointError::Malformed(why) => write!(f, "checkpoint body does not decode: {why}"),
        }
    }
}

impl std::error::Error for CheckpointError {}

/// Encodes a training state into `w`.
pub fn write_to(w: &mut dyn Write, state: &TrainingState) -> std::io::Result<()> {
    let (version, body) = match StateV6::of(state) {
        None => (VERSION, postcard::to_stdvec(state)),
        // format 6 added the rewards beyond the thesis' four
        Some(v6) if !state.config.learn.reward.from_thesis() => (6, postcard::to_stdvec(&v6)),
        Some(v6) => {
            if let Some(v1) = StateV1::of(state) {
                (1, postcard::to_stdvec(&v1))
            } else if let Some(v2) = StateV2::of(state) {
                (2, postcard::to_stdvec(&v2))
            } else if let Some(v3) = StateV3::of(state) {
                (3, postcard::to_stdvec(&v3))
            } else if let Some(v4) = StateV4::of(state) {
                (4, postcard::to_stdvec(&v4))
            } else {
                (5, postcard::to_stdvec(&v6))
            }
        }
    };
    let body = body.map_err(std::io::Error::other)?;
    let mut head = Vec::with_capacity(HEADER_LEN);
    head.extend_from_slice(&MAGIC);
    head.extend_from_slice(&version.to_le_bytes());
    head.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut digest = CRC32.digest();
    digest.update(&head);
    digest.update(&body);
    w.write_all(&head)?;
    w.write_all(&body)?;
    w.write_all(&digest.finalize().to_le_bytes())
}

/// Decodes a checkpoint, checking in order: header length, magic, version,
/// declared length, CRC, then the body.
pub fn decode(bytes: &[u8]) -> Result<TrainingState, CheckpointError> {
    let found = bytes.len() as u64;
    // A policy blob is recognised, to say what the file is instead.
    if bytes.starts_with(&shared::PolicyBlob::MAGIC) {
        return Err(CheckpointError::PolicyBlob);
    }
    if bytes.len() < HEADER_LEN {
        if !MAGIC.starts_with(bytes) {
            return Err(CheckpointError::WrongMagic);
        }
        return Err(CheckpointError::Truncated {
            needed: HEADER_LEN as u64,
            found,
        });
    }
    if bytes[..8] != MAGIC {
        return Err(CheckpointError::WrongMagic);
    }
    let version = u16::from_le_bytes([bytes[8], bytes[9]]);
    if !(1..=VERSION).contains(&version) {
        return Err(CheckpointError::UnsupportedVersion(version));
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&bytes[10..18]);
    let needed = u64::from_le_bytes(len).saturating_add((HEADER_LEN + CRC_LEN) as u64);
    if found < needed {
        return Err(CheckpointError::Truncated { needed, found });
    }
    if found > needed {
        return Err(CheckpointError::TrailingBytes {
            expected: needed,
            found,
        });
    }
    let crc_at = bytes.len() - CRC_LEN;
    let stored = u32::from_le_bytes([
        bytes[crc_at],
        bytes[crc_at + 1],
        bytes[crc_at + 2],
        bytes[crc_at + 3],
    ]);
    let computed = CRC32.checksum(&bytes[..crc_at]);
    if stored != computed {
        return Err(CheckpointError::CrcMismatch { stored, computed });
    }
    let body = &bytes[HEADER_LEN..crc_at];
    let malformed = |e: postcard::Error| CheckpointError::Malformed(e.to_string());
    match version {
        1 => postcard::from_bytes::<StateV1>(body)
            .map(StateV1::into_state)
            .map_err(malformed),
        2 => postcard::from_bytes::<StateV2>(body)
            .map(StateV2::into_state)
            .map_err(malformed),
        3 => postcard::from_bytes::<StateV3>(body)
            .map(StateV3::into_state)
            .map_err(malformed),
        4 => postcard::from_bytes::<StateV4>(body)
            .map(StateV4::into_state)
            .map_err(malformed),
        5 | 6 => postcard::from_bytes::<StateV6>(body)
            .map(StateV6::into_state)
            .map_err(malformed),
        _ => postcard::from_bytes(body).map_err(malformed),
    }
}

/// Writes a checkpoint atomically.
pub fn save(path: &Path, state: &TrainingState) -> Result<()> {
    crate::atomic::write_with(path, |w| write_to(w, state))
}

/// Reads a checkpoint; errors name the file and what is wrong with it.
pub fn load(path: &Path) -> Result<TrainingState> {
    let bytes = ranges::read_file(path, &ranges::CHECKPOINT_FILE)
        .with_context(|| format!("cannot read checkpoint {}", path.display()))?;
    decode(&bytes).with_context(|| format!("checkpoint file {}", path.display()))
}
