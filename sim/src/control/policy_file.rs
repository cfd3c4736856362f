//! Reading policy blob files (writing them is the trainer's).

use crate::base::ranges;
use shared::{BlobError, PolicyBlob};
use std::fmt;
use std::path::{Path, PathBuf};

/// A policy file that cannot be used, naming the file and the reason.
#[derive(Debug)]
pub enum PolicyFileError {
    /// The file cannot be read.
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: std::io::Error,
    },
    /// The file is not a valid policy blob.
    Blob {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: BlobError,
    },
}

impl fmt::Display for PolicyFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PolicyFileError::Read { path, reason } => {
                write!(f, "cannot read policy file {}: {reason}", path.display())
            }
            PolicyFileError::Blob { path, reason } => {
                write!(f, "policy file {}: {reason}", path.display())
            }
        }
    }
}

impl std::error::Error for PolicyFileError {}

/// Reads (no further than the largest blob, [`ranges::POLICY_FILE`]) and
/// decodes a policy blob file.
pub fn read(path: &Path) -> Result<PolicyBlob, PolicyFileError> {
    let bytes =
        ranges::read_file(path, &ranges::POLICY_FILE).map_err(|reason| PolicyFileError::Read {
            path: path.to_path_buf(),
            reason,
        })?;
    decode(path, &bytes)
}

/// Decodes the bytes of the policy file `path` (already read, for callers
/// that look at them first).
pub fn decode(path: &Path, bytes: &[u8]) -> Result<PolicyBlob, PolicyFileError> {
    PolicyBlob::decode(bytes).map_err(|reason| PolicyFileError::Blob {
        path: path.to_path_buf(),
        reason,
    })
}
