//! Reading and writing policy blob files.

use anyhow::{Context, Result};
use shared::PolicyBlob;
use std::path::Path;

/// Reads and decodes a policy blob file; errors name the file and what is wrong.
pub fn read(path: &Path) -> Result<PolicyBlob> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read policy file {}", path.display()))?;
    PolicyBlob::decode(&bytes).map_err(|e| anyhow::anyhow!("policy file {}: {e}", path.display()))
}

/// Writes a policy blob atomically: to a temporary file beside `path`, then
/// renamed over it, so a crash leaves the old file or the new one.
pub fn write(path: &Path, blob: &PolicyBlob) -> Result<()> {
    crate::atomic::write(path, &blob.encode())
}
