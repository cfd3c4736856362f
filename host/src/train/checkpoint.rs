//! The checkpoint file: a complete [`TrainingState`], from which training
//! resumes bit for bit.
//!
//! Layout (integers little-endian):
//!
//! | offset | size | content                                              |
//! |--------|------|------------------------------------------------------|
//! | 0      | 8    | magic `ZSWMCKPT`                                     |
//! | 8      | 2    | format version (1 to 8), u16                         |
//! | 10     | 8    | body length `n`, u64                                 |
//! | 18     | n    | body: the [`TrainingState`]                          |
//! | 18 + n | 4    | CRC-32 (ISO-HDLC, as zlib) of bytes `0 .. 18 + n`    |
//!
//! Format 8, which this build writes, has the body in CBOR (RFC 8949,
//! through `ciborium`): a self-describing record whose structs are maps
//! keyed by their fields' names, so a setting a checkpoint lacks takes its
//! default ([`TrainConfig`] and [`crate::learn::LearnConfig`] are
//! `#[serde(default)]`, their defaults documented on each field) and a
//! setting added later needs no new layout; an unknown setting is refused,
//! naming it. CBOR keeps every `f64` exactly (as 8 bytes, or in 2 or 4
//! when that width holds the same value), so values round-trip
//! bit-exactly.
//!
//! Formats 1 to 7 are postcard's positional layouts of earlier builds
//! ([`super::format1`], [`super::format2`], [`super::format3`],
//! [`super::format4`], [`super::format6`] for 5 and 6, [`super::format7`]):
//! all are read, into the same state, and resume exactly as the builds
//! that wrote them did. Files are written atomically (temporary file, then
//! rename): a run killed at any moment leaves the old checkpoint or the
//! new one.

use super::config::TrainConfig;
use super::format1::StateV1;
use super::format2::StateV2;
use super::format3::StateV3;
use super::format4::StateV4;
use super::format6::StateV6;
use super::format7::StateV7;
use super::trainer::TrainingState;
use anyhow::{Context, Result};
use crc::{Crc, CRC_32_ISO_HDLC};
use sim::base::ranges;
use std::fmt;
use std::io::Write;
use std::path::Path;

/// The first eight bytes of every checkpoint.
pub const MAGIC: [u8; 8] = *b"ZSWMCKPT";
/// The format version this build writes; it reads every one from 1. 2:
/// the settings of how the thesis was run and the world config of a
/// rectangular arena. 3: the run's arena and noise, the motion noise, the
/// world's seed, episode count and dropped-period turns, the robot senses'
/// memory. 4: the arena's border (`walls`) and the learner's rules. 5:
/// the robots' outline and decaying exploration. 6: the rewards
/// `per-robot`, `success` and `success-shaped`. 7: n-step returns. 8: the
/// state in CBOR, self-describing, the learner's rules among its settings.
pub const VERSION: u16 = 8;
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

/// Encodes a training state into `w`, in format [`VERSION`].
pub fn write_to(w: &mut dyn Write, state: &TrainingState) -> std::io::Result<()> {
    let mut body = Vec::new();
    ciborium::into_writer(state, &mut body).map_err(std::io::Error::other)?;
    write_framed(w, VERSION, &body)
}

/// Encodes a training state into `w` in the oldest of formats 1 to 7 that
/// holds it, byte for byte what the builds before format 8 wrote; returns
/// the version, or `None` (nothing written) when the state has settings
/// none of them holds. For checking that each earlier format reads back
/// and resumes exactly.
pub fn write_earlier_format(
    w: &mut dyn Write,
    state: &TrainingState,
) -> std::io::Result<Option<u16>> {
    let Some(v7) = StateV7::of(state) else {
        return Ok(None);
    };
    let (version, body) = match StateV6::of(&v7) {
        None => (7, postcard::to_stdvec(&v7)),
        // format 6 added the rewards beyond the thesis' four
        Some(v6) if !state.config.learn.reward.from_thesis() => (6, postcard::to_stdvec(&v6)),
        Some(v6) => {
            if let Some(v1) = StateV1::of(&v7) {
                (1, postcard::to_stdvec(&v1))
            } else if let Some(v2) = StateV2::of(&v7) {
                (2, postcard::to_stdvec(&v2))
            } else if let Some(v3) = StateV3::of(&v7) {
                (3, postcard::to_stdvec(&v3))
            } else if let Some(v4) = StateV4::of(&v7) {
                (4, postcard::to_stdvec(&v4))
            } else {
                (5, postcard::to_stdvec(&v6))
            }
        }
    };
    let body = body.map_err(std::io::Error::other)?;
    write_framed(w, version, &body)?;
    Ok(Some(version))
}

/// Writes the header, `body` and the CRC.
fn write_framed(w: &mut dyn Write, version: u16, body: &[u8]) -> std::io::Result<()> {
    let mut head = Vec::with_capacity(HEADER_LEN);
    head.extend_from_slice(&MAGIC);
    head.extend_from_slice(&version.to_le_bytes());
    head.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut digest = CRC32.digest();
    digest.update(&head);
    digest.update(body);
    w.write_all(&head)?;
    w.write_all(body)?;
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
    let old = match version {
        1 => postcard::from_bytes::<StateV1>(body).map(StateV1::into_v7),
        2 => postcard::from_bytes::<StateV2>(body).map(StateV2::into_v7),
        3 => postcard::from_bytes::<StateV3>(body).map(StateV3::into_v7),
        4 => postcard::from_bytes::<StateV4>(body).map(StateV4::into_v7),
        5 | 6 => postcard::from_bytes::<StateV6>(body).map(StateV6::into_v7),
        7 => postcard::from_bytes::<StateV7>(body),
        _ => {
            return ciborium::from_reader(body)
                .map_err(|e| CheckpointError::Malformed(why_malformed(body, e.to_string())))
        }
    };
    old.map(StateV7::into_state).map_err(malformed)
}

/// Why a format-8 body does not decode: the setting at fault and its
/// problem when a setting is (`setting learn.alpha: invalid type: ...`),
/// else the CBOR decoder's `error`.
fn why_malformed(body: &[u8], error: String) -> String {
    let settings = ciborium::from_reader::<ciborium::Value, _>(body)
        .ok()
        .and_then(|v| v.into_map().ok())
        .and_then(|m| m.into_iter().find(|(k, _)| k.as_text() == Some("config")))
        .and_then(|(_, v)| serde_json::to_value(v).ok());
    match settings.map(serde_path_to_error::deserialize::<_, TrainConfig>) {
        Some(Err(e)) => format!("setting {}: {}", e.path(), e.inner()),
        _ => error,
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
