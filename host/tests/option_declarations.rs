//! Every setting is declared once. A training config's settings (the
//! fields of `TrainConfig` and the structs it holds, the world's among
//! them: `WorldChoices` of `sim`, flags under its `clap` feature) are at the same time
//! the keys of training and experiment files and the flags of `host train`,
//! `run`, `render` and the TV tools, which take their argument definitions
//! from there; so no other `clap` field in `host` may declare a flag of the
//! same name. The frozen checkpoint formats (`train/format1.rs`,
//! `train/format2.rs`) keep their own copies by design and declare no flags.
//!
//! The check reads the sources: each field under an `#[arg(...)]`
//! attribute (or `#[cfg_attr(feature = "clap", arg(...))]`) declares the
//! flag `--<long>` (the attribute's `long = "..."`, else the field's name
//! in kebab case).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Files whose `#[arg]` fields are the training config's settings.
const SETTINGS: [&str; 4] = [
    "train/config.rs",
    "learn/learner.rs",
    "train/selection.rs",
    // The scenario flags' own extras (--controller, --naive).
    "cli/scenario.rs",
];

/// One `#[arg]` field: its flag and where it is declared.
#[derive(Debug)]
struct Declaration {
    flag: String,
    at: String,
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The `#[arg]` fields of one source file.
fn declarations(file: &Path, name: &str) -> Vec<Declaration> {
    let text = std::fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        let line = line
            .strip_prefix("#[cfg_attr(feature = \"clap\", ")
            .map_or(line.to_string(), |rest| format!("#[{rest}"));
        let line = line.as_str();
        if line.starts_with("#[arg(") && !line.starts_with("#[arg(skip") {
            // The attribute may span lines; the field follows it.
            let mut attribute = String::from(line);
            let mut j = i;
            while !attribute.contains(")]") {
                j += 1;
                attribute.push_str(lines[j].trim());
            }
            let field = lines[j + 1..]
                .iter()
                .map(|l| l.trim())
                .find(|l| !l.starts_with("#[") && !l.starts_with("///"))
                .unwrap_or_default();
            let field = field
                .trim_start_matches("pub(crate) ")
                .trim_start_matches("pub ");
            if let Some((ident, _)) = field.split_once(':') {
                let flag = attribute
                    .split("long = \"")
                    .nth(1)
                    .and_then(|s| s.split('"').next())
                    .map(str::to_string)
                    .unwrap_or_else(|| ident.trim().replace('_', "-"));
                out.push(Declaration {
                    flag,
                    at: format!("{name}:{}", i + 1),
                });
            }
            i = j;
        }
        i += 1;
    }
    out
}

#[test]
fn no_flag_of_a_training_setting_is_declared_a_second_time() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut settings: BTreeMap<String, Vec<String>> = BTreeMap::new();
    // the world's settings, declared in `sim`
    let world = src.join("../../sim/src/scenario/choices.rs");
    for d in declarations(&world, "sim/src/scenario/choices.rs") {
        settings.entry(d.flag).or_default().push(d.at);
    }
    let mut others: Vec<Declaration> = Vec::new();
    for file in &files {
        let name = file
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .into_owned();
        if name.starts_with("train/format") {
            continue;
        }
        for d in declarations(file, &name) {
            if SETTINGS.contains(&name.as_str()) {
                settings.entry(d.flag).or_default().push(d.at);
            } else {
                others.push(d);
            }
        }
    }
    assert!(
        settings.len() >= 25,
        "the scan found only {} setting flags: {settings:?}",
        settings.len()
    );
    let twice: Vec<_> = settings.iter().filter(|(_, at)| at.len() > 1).collect();
    assert!(twice.is_empty(), "settings declared twice: {twice:?}");
    let again: Vec<_> = others
        .iter()
        .filter(|d| settings.contains_key(&d.flag))
        .filter(|d| !HOMONYMS.iter().any(|(flag, _)| *flag == d.flag))
        .collect();
    assert!(
        again.is_empty(),
        "training settings declared again elsewhere: {again:?} (first declared at {:?})",
        again.iter().map(|d| &settings[&d.flag]).collect::<Vec<_>>()
    );
}

/// Flags that share a training setting's name but are another option.
const HOMONYMS: [(&str, &str); 7] = [
    ("seed", "`host experiment --seed`: the experiment's seed, from which every trial's derives"),
    ("steps", "`run`, `render`, `bench`: steps to run or time, not a config's run length"),
    ("out", "`render`, `field export`, `monitor`: the file to write, not a training run's directory"),
    ("sensors", "`bench --sensors`: which of the two benchmark workloads (disc with OC, robot with random turns)"),
    ("arena", "`bench --arena`: the benchmark's world, whose robots and pucks are the arena's own"),
    ("naive", "`bench --naive`: the broad phase of the benchmark's variant"),
    ("hasher", "`flash --hasher`: the hasher the firmware is built for, checked against the policy's"),
];

#[test]
fn the_scan_finds_a_second_declaration() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("x.rs");
    std::fs::write(
        &file,
        "struct A {\n    /// Doc.\n    #[arg(\n        long = \"check-every\",\n        required = false\n    )]\n    pub every: u64,\n    #[arg(long)]\n    pub alpha_beta: f64,\n    #[arg(skip)]\n    pub gone: u8,\n}\n",
    )
    .unwrap();
    let found = declarations(&file, "x.rs");
    let flags: Vec<&str> = found.iter().map(|d| d.flag.as_str()).collect();
    assert_eq!(flags, ["check-every", "alpha-beta"]);
    assert_eq!(found[0].at, "x.rs:3");
}
