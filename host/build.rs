//! Builds the list of the experiments shipped in `experiments/` (every
//! `*.toml` directly in it, by file stem, in name order) into the binary:
//! `$OUT_DIR/built_in.rs` holds `BUILT_IN`, each name with its file's text
//! (`include_str!`), so that `host experiment NAME` works from any
//! directory and a new experiment is one new file.

use std::path::Path;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|entry| {
            let path = entry.ok()?.path();
            let stem = path.file_stem()?.to_str()?.to_string();
            let is_toml = path.extension().is_some_and(|e| e == "toml") && path.is_file();
            is_toml.then(|| (stem, path.display().to_string()))
        })
        .collect();
    files.sort();
    let mut out = String::from(
        "/// The experiments shipped in `experiments/`, by name (the file stem),\n\
         /// in name order, each with its file's text (found by `host/build.rs`).\n\
         pub const BUILT_IN: &[(&str, &str)] = &[\n",
    );
    for (name, path) in &files {
        println!("cargo:rerun-if-changed={path}");
        out.push_str(&format!("    ({name:?}, include_str!({path:?})),\n"));
    }
    out.push_str("];\n");
    let target =
        Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("built_in.rs");
    std::fs::write(&target, out)
        .unwrap_or_else(|e| panic!("cannot write {}: {e}", target.display()));
}
