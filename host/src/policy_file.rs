//! Writing policy blob files (reading them is `sim::control::policy_file`'s).

use anyhow::Result;
use shared::PolicyBlob;
use std::path::Path;

/// Writes a policy blob atomically: to a temporary file beside `path`, then
/// renamed over it, so a crash leaves the old file or the new one.
pub fn write(path: &Path, blob: &PolicyBlob) -> Result<()> {
    crate::atomic::write(path, &blob.encode())
}
