//! Atomic file writes: a reader sees the old content or the new, never a mix.
//!
//! A write goes to a temporary file beside its target, named
//! `.tmp-<pid>-<random>` after the writing process, is flushed to disk
//! and renamed over the target. A process killed mid-write leaves its
//! temporary file behind; the next write into that folder removes every
//! temporary file of a process that no longer runs. Writes never create
//! folders: the commands create the folders the user asked for (`host
//! train --out`, an experiment's directory and the tree under it) with
//! [`create_dirs`], so a mistyped folder of an output file is an error, not
//! a new folder.

use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::Path;

/// What every temporary file's name starts with.
const TEMP_PREFIX: &str = ".tmp-";

/// Writes `bytes` to `path` through a temporary file in the same directory,
/// flushed to disk and then renamed over `path`. The file gets the
/// permissions a plain create would (0666 less the umask).
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes))
}

/// Like [`write`], with the content produced by `fill`. If `fill` fails, the
/// temporary file is removed and `path` is untouched.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let dir = folder_of(path);
    if !dir.is_dir() {
        bail!(
            "cannot write {}: the folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    remove_stale_temporaries(dir);
    let mut builder = tempfile::Builder::new();
    let prefix = format!("{TEMP_PREFIX}{}-", std::process::id());
    builder.prefix(&prefix);
    // Like a plain create: readable by all, subject to the umask (a
    // temporary file would otherwise stay owner-only after the rename).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    fill(tmp.as_file_mut()).with_context(|| format!("cannot write {}", path.display()))?;
    tmp.as_file()
        .sync_all()
        .with_context(|| format!("cannot flush {}", path.display()))?;
    tmp.persist(path).map_err(|e| {
        anyhow::Error::new(e.error).context(format!(
            "cannot move the new file into place at {}",
            path.display()
        ))
    })?;
    Ok(())
}

/// Creates `dir` and the folders above it, for a command's own output
/// folder; the error names it.
pub fn create_dirs(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create folder {}", dir.display()))
}

/// Checks that files can be written into `dir` (creating it, as
/// [`create_dirs`]), by writing and removing a temporary file: for a
/// command that would otherwise find out only when it writes its results.
pub fn check_writable(dir: &Path) -> Result<()> {
    create_dirs(dir)?;
    remove_stale_temporaries(dir);
    tempfile::Builder::new()
        .prefix(&format!("{TEMP_PREFIX}{}-", std::process::id()))
        .tempfile_in(dir)
        .map(drop)
        .with_context(|| format!("cannot write into folder {}", dir.display()))
}

/// The folder `path` is in (`.` for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Removes the temporary files in `dir` of processes that no longer run:
/// writes killed before their rename. Best effort: what cannot be read or
/// removed stays.
fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(TEMP_PREFIX))
            .and_then(|rest| rest.split_once('-'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if !process_runs(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether the process `pid` runs (on systems where this cannot be asked,
/// every process is taken to run, so nothing is removed).
fn process_runs(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        // SAFETY: signal 0 sends nothing; it only checks that the process
        // exists (EPERM: it exists but is another user's).
        let sent = unsafe { libc::kill(pid, 0) };
        sent == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_writer_leaves_the_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.bin");
        write(&path, b"old").unwrap();
        let err = write_with(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temporary file left behind"
        );
        write(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }

    #[test]
    fn the_next_write_in_a_folder_removes_the_temporary_files_of_killed_writes() {
        let dir = tempfile::tempdir().unwrap();
        // A child that exits at once: its pid runs no more.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let killed = dir.path().join(format!("{TEMP_PREFIX}{dead}-a1B2c3"));
        std::fs::write(&killed, b"half a checkpoint").unwrap();
        // Another running process's write in progress, and a file of ours.
        let running = dir
            .path()
            .join(format!("{TEMP_PREFIX}{}-x9Y8z7", std::process::id()));
        std::fs::write(&running, b"in progress").unwrap();
        let other = dir.path().join(".tmp-notes");
        std::fs::write(&other, b"not ours").unwrap();
        write(&dir.path().join("x.bin"), b"new").unwrap();
        assert!(!killed.exists(), "the killed write's file is still there");
        assert!(running.exists() && other.exists());
    }

    #[test]
    fn writes_create_no_folders_and_name_a_missing_one_or_a_folder_in_the_way() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no/such/x.png");
        let e = format!("{:#}", write(&missing, b"x").unwrap_err());
        assert!(e.contains("does not exist") && e.contains("no/such"), "{e}");
        assert!(!dir.path().join("no").exists());
        let e = format!("{:#}", write(dir.path(), b"x").unwrap_err());
        assert_eq!(
            e,
            format!("cannot write {}: it is a folder", dir.path().display())
        );
        create_dirs(&dir.path().join("no/such")).unwrap();
        write(&missing, b"x").unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn an_unwritable_folder_is_found_before_anything_is_computed() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let locked = dir.path().join("locked");
        std::fs::create_dir(&locked).unwrap();
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
        // root writes into any folder of a normal file system, not into /proc
        let unwritable = if std::fs::write(locked.join("probe"), b"").is_ok() {
            Path::new("/proc")
        } else {
            locked.as_path()
        };
        let e = format!("{:#}", check_writable(unwritable).unwrap_err());
        assert!(
            e.contains("cannot write into folder") && e.contains(&unwritable.display().to_string()),
            "{e}"
        );
        check_writable(&dir.path().join("new/out")).unwrap();
        assert!(dir.path().join("new/out").is_dir());
    }
}
