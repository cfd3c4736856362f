//! The hash of the sources a firmware image is built from, so that a test
//! can refuse an ELF older than the code it tests.
//!
//! [`SOURCES`] lists what is hashed, relative to the workspace: every file
//! under `firmware/src` and `shared/src`, and the two crates' `Cargo.toml`
//! and the firmware's `build.rs`. The hash is 64-bit FNV-1a over, for each
//! file in order of its path (`/`-separated): the path, a 0 byte, the
//! length as 8 bytes little-endian, the content. `build.rs` (which
//! includes this file as a module) puts [`marker`] of it into the ELF, in
//! a section that is not loaded (`.zumo.sources`: the hex and the flash
//! stay the same); `tests::zumo::firmware_elf_in` recomputes it and
//! refuses an ELF whose marker differs. The embedded policy is not hashed:
//! the image's identity record carries its CRC.
//!
//! Host only (it reads files).

extern crate std;

use std::path::{Path, PathBuf};
use std::string::String;
use std::vec::Vec;
use std::{format, fs, io};

/// The files and directories hashed, relative to the workspace.
pub const SOURCES: [&str; 5] = [
    "firmware/Cargo.toml",
    "firmware/build.rs",
    "firmware/src",
    "shared/Cargo.toml",
    "shared/src",
];

/// What the ELF carries: `zumo-swarm sources fnv1a64 ` and the hash in 16
/// hex digits.
pub fn marker(hash: u64) -> String {
    format!("{MARKER_PREFIX}{hash:016x}")
}

/// The start of [`marker`]'s text.
pub const MARKER_PREFIX: &str = "zumo-swarm sources fnv1a64 ";

/// The hash of [`SOURCES`] under the workspace `root`.
pub fn of_workspace(root: &Path) -> io::Result<u64> {
    let mut files = Vec::new();
    for source in SOURCES {
        collect(&root.join(source), &mut files)?;
    }
    let mut named: Vec<(String, PathBuf)> = files
        .into_iter()
        .map(|f| {
            let rel = f.strip_prefix(root).unwrap_or(&f);
            let name: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            (name.join("/"), f)
        })
        .collect();
    named.sort();
    let mut hash = Fnv::new();
    for (name, path) in named {
        let bytes = fs::read(&path)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        hash.write(name.as_bytes());
        hash.write(&[0]);
        hash.write(&(bytes.len() as u64).to_le_bytes());
        hash.write(&bytes);
    }
    Ok(hash.0)
}

/// Every file under `path` (itself if a file).
fn collect(path: &Path, out: &mut Vec<PathBuf>) -> io::Result<()> {
    let meta = fs::metadata(path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    if meta.is_dir() {
        for entry in fs::read_dir(path)? {
            collect(&entry?.path(), out)?;
        }
    } else {
        out.push(path.to_path_buf());
    }
    Ok(())
}

/// 64-bit FNV-1a.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_changes_with_any_byte_or_name_of_the_sources() {
        let dir = std::env::temp_dir().join(format!("zumo-source-hash-{}", std::process::id()));
        for source in SOURCES {
            let path = dir.join(source);
            if source.ends_with("src") {
                fs::create_dir_all(path.join("board")).unwrap();
                fs::write(path.join("lib.rs"), "fn a() {}").unwrap();
                fs::write(path.join("board/usb.rs"), "fn b() {}").unwrap();
            } else {
                fs::create_dir_all(path.parent().unwrap()).unwrap();
                fs::write(&path, source).unwrap();
            }
        }
        let first = of_workspace(&dir).unwrap();
        assert_eq!(of_workspace(&dir).unwrap(), first);
        fs::write(dir.join("firmware/src/board/usb.rs"), "fn b() {} ").unwrap();
        let edited = of_workspace(&dir).unwrap();
        assert_ne!(edited, first);
        fs::rename(
            dir.join("shared/src/lib.rs"),
            dir.join("shared/src/main.rs"),
        )
        .unwrap();
        assert_ne!(of_workspace(&dir).unwrap(), edited);
        assert_eq!(marker(0xab), "zumo-swarm sources fnv1a64 00000000000000ab");
        fs::remove_dir_all(&dir).unwrap();
        assert!(of_workspace(&dir).is_err(), "a missing source is an error");
    }
}
