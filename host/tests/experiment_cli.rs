//! `host experiment`: quick runs of every experiment file produce their
//! tables and figures; reruns skip finished trials; bad input is refused.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

fn experiment_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_experiment_file_is_built_in() {
    let mut stems: Vec<String> =
        experiment_files().iter().map(|p| p.file_stem().unwrap().to_string_lossy().into_owned()).collect();
    let mut built_in: Vec<String> = host::experiment::spec::BUILT_IN.iter().map(|(n, _)| n.to_string()).collect();
    stems.sort();
    built_in.sort();
    assert_eq!(stems, built_in);
}

#[test]
fn quick_runs_of_every_experiment_produce_tables_and_figures() {
    let out = tempfile::tempdir().unwrap();
    for file in experiment_files() {
        let spec = host::experiment::ExperimentSpec::load(file.to_str().unwrap()).unwrap();
        let dir = out.path().join(&spec.name);
        let run = host()
            .args(["experiment", file.to_str().unwrap(), "--trials", "2", "--scale", "0.0004", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&run.stderr));
        assert!(stdout.contains(&format!("writing to {}", dir.display())), "{stdout}");
        assert!(stdout.contains("0 already done (skipped)"), "{stdout}");

        let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
        assert!(table.contains(&format!("# {}", spec.title)), "{table}");
        for arm in &spec.arms {
            assert!(table.contains(&format!("| {} |", arm.row)), "{}: row {} missing", spec.name, arm.row);
            let trials = std::fs::read_dir(dir.join("trials").join(host::experiment::runner::slug(&arm.name))).unwrap();
            assert_eq!(trials.count(), 2, "{} {}", spec.name, arm.name);
        }
        let csv = std::fs::read_to_string(dir.join("trials.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 2 * spec.arms.len());
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("trials.json")).unwrap()).unwrap();
        assert_eq!(json.as_array().unwrap().len(), 2 * spec.arms.len());
        for figure in &spec.figures {
            let png = image::open(dir.join(&figure.file)).unwrap();
            assert!(png.width() > 100, "{}", figure.file);
        }
    }
}

#[test]
fn a_rerun_skips_finished_trials_and_reuses_pretrained_tables() {
    let out = tempfile::tempdir().unwrap();
    let args = ["experiment", "transfer", "--scale", "0.0002", "--out"];
    let first = host().args(args).arg(out.path()).args(["--trials", "2"]).output().unwrap();
    assert!(first.status.success(), "{}", String::from_utf8_lossy(&first.stderr));
    let first = String::from_utf8(first.stdout).unwrap();
    assert!(first.contains("pre-training: 2 tables, 0 already done"), "one table per trial, shared by the arms: {first}");

    let again = host().args(args).arg(out.path()).args(["--trials", "3"]).output().unwrap();
    let again = String::from_utf8(again.stdout).unwrap();
    assert!(again.contains("pre-training: 3 tables, 2 already done (skipped)"), "{again}");
    assert!(again.contains("trials: 18, 12 already done (skipped)"), "{again}");

    // another seed changes every trial's config hash: nothing is reused
    let reseeded = host().args(args).arg(out.path()).args(["--trials", "2", "--seed", "7"]).output().unwrap();
    assert!(String::from_utf8(reseeded.stdout).unwrap().contains("trials: 12, 0 already done"));
}

#[test]
fn bad_experiment_inputs_are_refused() {
    let fails = |args: &[&str]| {
        let out = host().args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(&["experiment", "nonsense"]);
    assert!(e.contains("unknown experiment \"nonsense\"") && e.contains("annulus"), "{e}");
    assert!(fails(&["experiment", "/no/such/file.toml"]).contains("/no/such/file.toml"));
    assert!(fails(&["experiment", "annulus", "--trials", "0"]).contains("--trials 0"));
    assert!(fails(&["experiment", "annulus", "--scale=-1"]).contains("--scale -1"));
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "title = \"x\"\n[[arms]]\nname = \"a\"\nhasher = \"bits7\"\n").unwrap();
    let e = fails(&["experiment", bad.to_str().unwrap()]);
    assert!(e.contains("bad.toml") && e.contains("arm \"a\"") && e.contains("hasher"), "{e}");
}

#[test]
fn results_do_not_depend_on_the_number_of_threads() {
    let out = tempfile::tempdir().unwrap();
    let run = |threads: &str| {
        let dir = out.path().join(threads);
        let args = ["experiment", "annulus", "--trials", "3", "--scale", "0.0006", "--threads", threads, "--out"];
        assert!(host().args(args).arg(&dir).output().unwrap().status.success());
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("trials.json")).unwrap()).unwrap();
        let mut trials = json.as_array().unwrap().clone();
        for t in &mut trials {
            let t = t.as_object_mut().unwrap();
            t.remove("steps_per_second");
            t.remove("seconds");
        }
        trials
    };
    assert_eq!(run("1"), run("2"));
}
