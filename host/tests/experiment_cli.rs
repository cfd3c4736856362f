//! `host experiment`: quick runs of every experiment file produce their
//! tables and figures; reruns skip finished trials; bad input is refused.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

mod served;

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
    let mut stems: Vec<String> = experiment_files()
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    let mut built_in: Vec<String> = host::experiment::spec::BUILT_IN
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    stems.sort();
    built_in.sort();
    assert_eq!(stems, built_in);
}

#[test]
fn the_list_names_every_built_in_experiment_with_its_trials_and_page() {
    // from the repository root, against which files name their arenas
    let out = host()
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .args(["experiment", "list"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let list = String::from_utf8_lossy(&out.stdout);
    for (name, text) in host::experiment::spec::BUILT_IN {
        let spec = host::experiment::ExperimentSpec::parse(name, text).unwrap();
        let line = format!("{name} {} {}", spec.trials, spec.page.unwrap());
        assert!(
            list.lines().any(|l| l == line),
            "`host experiment list` lacks {line}"
        );
    }
    assert!(list.contains("every-shape 10 robot-sensors"), "{list}");
    assert!(
        list.contains("robot-senses-sweep 3 robot-sensors"),
        "{list}"
    );
}

#[test]
fn quick_runs_of_every_experiment_produce_tables_and_figures() {
    let out = tempfile::tempdir().unwrap();
    for file in experiment_files() {
        let spec = host::experiment::ExperimentSpec::load(file.to_str().unwrap()).unwrap();
        let dir = out.path().join(&spec.name);
        // from the repository root, against which files name sensor configs and policies
        let run = host()
            .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
            .args([
                "experiment",
                file.to_str().unwrap(),
                "--trials",
                "2",
                "--scale",
                "0.0004",
                "--out",
            ])
            .arg(&dir)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success(),
            "{}: {}",
            file.display(),
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(
            stdout.contains(&format!("writing to {}", dir.display())),
            "{stdout}"
        );
        assert!(stdout.contains("0 already done (skipped)"), "{stdout}");

        let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
        assert!(table.contains(&format!("# {}", spec.title)), "{table}");
        for arm in &spec.arms {
            assert!(
                table.contains(&format!("| {} |", arm.row)),
                "{}: row {} missing",
                spec.name,
                arm.row
            );
            let trials = std::fs::read_dir(
                dir.join("trials")
                    .join(host::experiment::runner::slug(&arm.name)),
            )
            .unwrap();
            assert_eq!(trials.count(), 2, "{} {}", spec.name, arm.name);
        }
        let csv = std::fs::read_to_string(dir.join("trials.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 2 * spec.arms.len());
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("trials.json")).unwrap()).unwrap();
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
    let run = |more: &[&str]| {
        let run = host()
            .args(args)
            .arg(out.path())
            .args(more)
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        String::from_utf8(run.stdout).unwrap()
    };
    // one table per trial and column (text, author), shared by the column's six arms
    let first = run(&["--trials", "2"]);
    assert!(
        first.contains("pre-training: 4 tables for the trials to run, 0 already done"),
        "{first}"
    );

    // a third trial needs only its own tables
    let again = run(&["--trials", "3"]);
    assert!(
        again.contains("pre-training: 2 tables for the trials to run, 0 already done"),
        "{again}"
    );
    assert!(
        again.contains("trials: 36, 24 already done (skipped)"),
        "{again}"
    );

    // a lost trial reruns from its stored table
    std::fs::remove_file(out.path().join("trials/1_robot/trial-00.json")).unwrap();
    let lost = run(&["--trials", "3"]);
    assert!(
        lost.contains("pre-training: 1 tables for the trials to run, 1 already done (skipped)"),
        "{lost}"
    );
    assert!(
        lost.contains("trials: 36, 35 already done (skipped)"),
        "{lost}"
    );

    // another seed changes every trial's config hash: nothing is reused
    let reseeded = run(&["--trials", "2", "--seed", "7"]);
    assert!(
        reseeded.contains("trials: 24, 0 already done"),
        "{reseeded}"
    );
}

/// A trial file without its timing fields, which differ between runs.
fn untimed(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let t = v.as_object_mut().unwrap();
    t.remove("seconds");
    t.remove("steps_per_second");
    v
}

/// Every file under `dir`, relative to it, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// A report without its timing columns (steps per second, seconds).
fn untimed_table(text: &str) -> String {
    let mut drop = None;
    let mut out = String::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').collect();
        if let Some(i) = cells.iter().position(|c| c.trim() == "Steps/s") {
            drop = Some(i);
        }
        let kept: Vec<&str> = match drop {
            Some(i) if line.starts_with('|') && cells.len() > i => cells
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i)
                .map(|(_, c)| *c)
                .collect(),
            _ => cells,
        };
        out.push_str(&kept.join("|"));
        out.push('\n');
    }
    out
}

fn untimed_csv(text: &str) -> String {
    // the last two columns are steps_per_second and seconds
    text.lines()
        .map(|l| l.rsplitn(3, ',').last().unwrap().to_string() + "\n")
        .collect()
}

#[test]
fn three_shards_merged_give_the_unsharded_runs_trials_and_tables() {
    let out = tempfile::tempdir().unwrap();
    let common = [
        "experiment",
        "transfer",
        "--trials",
        "2",
        "--scale",
        "0.0002",
        "--threads",
        "1",
        "--out",
    ];
    let whole = out.path().join("whole");
    assert!(host()
        .args(common)
        .arg(&whole)
        .output()
        .unwrap()
        .status
        .success());
    let shards: Vec<PathBuf> = (0..3)
        .map(|k| out.path().join(format!("shard-{k}")))
        .collect();
    for (k, dir) in shards.iter().enumerate() {
        let run = host()
            .args(common)
            .arg(dir)
            .args(["--shard", &format!("{k}/3")])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(String::from_utf8_lossy(&run.stdout).contains(&format!("shard {k}/3: 8 trials")));
        assert!(
            !dir.join("table.md").exists(),
            "a shard leaves the reports to the merge"
        );
    }
    let merged = out.path().join("merged");
    let run = host()
        .args(["experiment", "merge"])
        .args(&shards)
        .arg("--out")
        .arg(&merged)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );

    assert_eq!(files(&merged), files(&whole));
    for f in files(&whole) {
        let (a, b) = (whole.join(&f), merged.join(&f));
        let name = f.to_string_lossy().into_owned();
        if name.starts_with("trials/") {
            assert_eq!(untimed(&a), untimed(&b), "{name}");
        } else if name == "table.md" {
            let read = |p: &Path| untimed_table(&std::fs::read_to_string(p).unwrap());
            assert_eq!(read(&a), read(&b));
        } else if name == "trials.csv" {
            let read = |p: &Path| untimed_csv(&std::fs::read_to_string(p).unwrap());
            assert_eq!(read(&a), read(&b));
        } else if name.starts_with("pretrained/") {
            assert!(
                std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
                "{name}"
            );
        }
    }
}

#[test]
fn a_merge_refuses_missing_foreign_or_disagreeing_shards() {
    let out = tempfile::tempdir().unwrap();
    let shard = |k: usize, n: usize, seed: &str| {
        let dir = out.path().join(format!("s{k}of{n}-{seed}"));
        let args = [
            "experiment",
            "transfer",
            "--trials",
            "1",
            "--scale",
            "0.0002",
            "--seed",
            seed,
            "--out",
        ];
        let run = host()
            .args(args)
            .arg(&dir)
            .args(["--shard", &format!("{k}/{n}")])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        dir
    };
    let merge = |dirs: &[&PathBuf]| {
        let run = host()
            .args(["experiment", "merge"])
            .args(dirs)
            .arg("--out")
            .arg(out.path().join("m"))
            .output()
            .unwrap();
        assert!(!run.status.success());
        String::from_utf8(run.stderr).unwrap()
    };
    let (a, b) = (shard(0, 2, "1"), shard(1, 2, "1"));
    let e = merge(&[&a]);
    assert!(
        e.contains("shard 1/2 is missing") && e.contains("--shard 1/2"),
        "{e}"
    );
    let other = shard(1, 2, "5");
    assert!(merge(&[&a, &other]).contains("shards of different runs"));
    assert!(merge(&[&a, &a]).contains("shard 0/2 is given twice"));
    // both shards pre-train the table of trial 0 of each column: the copies must agree
    let table = std::fs::read_dir(a.join("pretrained"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let copy = b.join("pretrained").join(table.file_name().unwrap());
    let mut bytes = std::fs::read(&copy).unwrap();
    bytes[40] ^= 1;
    std::fs::write(&copy, bytes).unwrap();
    assert!(merge(&[&a, &b]).contains("differ, though they are of the same settings and seed"));
    std::fs::remove_dir_all(b.join("trials")).unwrap();
    assert!(merge(&[&a, &b]).contains("has not finished"));
    let e = merge(&[&out.path().join("nowhere")]);
    assert!(e.contains("is not a shard's directory"), "{e}");
}

#[test]
fn bad_experiment_inputs_are_refused() {
    let fails = |args: &[&str]| {
        let out = host().args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(&["experiment", "nonsense"]);
    assert!(
        e.contains("unknown experiment \"nonsense\"") && e.contains("annulus"),
        "{e}"
    );
    assert!(fails(&["experiment", "/no/such/file.toml"]).contains("/no/such/file.toml"));
    assert!(fails(&["experiment", "annulus", "--trials", "0"]).contains("--trials 0"));
    assert!(fails(&["experiment", "annulus", "--scale=-1"]).contains("--scale -1"));
    assert!(fails(&["experiment", "annulus", "--shard", "3/3"]).contains("0 <= K < N"));
    let e = fails(&["experiment", "annulus", "--reuse", "/no/such/run"]);
    assert!(e.contains("--reuse /no/such/run: not a directory"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "title = \"x\"\n[[arms]]\nname = \"a\"\nhasher = \"bits7\"\n",
    )
    .unwrap();
    let e = fails(&["experiment", bad.to_str().unwrap()]);
    assert!(
        e.contains("bad.toml") && e.contains("arm \"a\"") && e.contains("hasher"),
        "{e}"
    );
}

#[test]
fn results_do_not_depend_on_the_number_of_threads() {
    let out = tempfile::tempdir().unwrap();
    let run = |threads: &str| {
        let dir = out.path().join(threads);
        let args = [
            "experiment",
            "annulus",
            "--trials",
            "3",
            "--scale",
            "0.0006",
            "--threads",
            threads,
            "--out",
        ];
        assert!(host()
            .args(args)
            .arg(&dir)
            .output()
            .unwrap()
            .status
            .success());
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("trials.json")).unwrap()).unwrap();
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

/// The state-bits and obstacle experiments share the arm "8 bits
/// (Original)" in both columns: with `--reuse` an obstacle run copies those
/// trials from a state-bits run, renamed as its own, and its trial files
/// and table are what running them gives.
#[test]
fn trials_another_run_made_with_the_same_settings_are_copied_not_run() {
    let out = tempfile::tempdir().unwrap();
    let run = |name: &str, dir: &str, more: &[&str]| {
        let run = host()
            .args([
                "experiment",
                name,
                "--trials",
                "2",
                "--scale",
                "0.0002",
                "--out",
            ])
            .arg(out.path().join(dir))
            .args(more)
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        String::from_utf8(run.stdout).unwrap()
    };
    run("state-bits", "state-bits", &[]);
    let state_bits = out.path().join("state-bits");
    let reused = run(
        "obstacle",
        "reused",
        &["--reuse", state_bits.to_str().unwrap()],
    );
    assert!(
        reused.contains("reuse: 4 trials copied from 12 stored"),
        "{reused}"
    );
    assert!(
        reused.contains("8 trials run, 0 skipped, 4 copied"),
        "{reused}"
    );
    let ran = run("obstacle", "ran", &[]);
    assert!(ran.contains("12 trials run, 0 skipped, 0 copied"), "{ran}");

    let (reused, ran) = (out.path().join("reused"), out.path().join("ran"));
    assert_eq!(files(&reused), files(&ran));
    for file in files(&ran).iter().filter(|f| f.starts_with("trials/")) {
        assert_eq!(
            untimed(&reused.join(file)),
            untimed(&ran.join(file)),
            "{}",
            file.display()
        );
    }
    let copy = untimed(&reused.join("trials/8_bits__Original_/trial-01.json"));
    assert_eq!(
        (
            copy["experiment"].as_str(),
            copy["arm"].as_str(),
            copy["trial"].as_u64()
        ),
        (Some("obstacle"), Some("8 bits (Original)"), Some(1))
    );
    let table = |dir: &Path| untimed_table(&std::fs::read_to_string(dir.join("table.md")).unwrap());
    assert_eq!(table(&reused), table(&ran));

    // a rerun finds them finished; a run of other settings copies nothing
    let again = run(
        "obstacle",
        "reused",
        &["--reuse", state_bits.to_str().unwrap()],
    );
    assert!(
        again.contains("0 trials run, 12 skipped, 0 copied"),
        "{again}"
    );
    let other = run(
        "obstacle",
        "other-seed",
        &["--seed", "9", "--reuse", state_bits.to_str().unwrap()],
    );
    assert!(other.contains("reuse: 0 trials copied"), "{other}");
}

/// `host experiment --view`: the trials run one at a time on the live
/// view's page, each under a caption naming it, a learning arm with its
/// learner's progress; and they give what a run without the view gives.
#[test]
fn with_the_view_each_trial_is_shown_in_turn_and_its_results_do_not_change() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("watched.toml");
    std::fs::write(
        &spec,
        r#"
title = "watched"
seed = 3
[table]
row_header = "Controller"
metrics = ["formations"]
[defaults]
robots = 3
pucks = 12
steps = 100_000
# long enough to be running when the test asks what the page shows
[[arms]]
name = "learner"
controller = "learn"
steps = 2_000_000
[[arms]]
name = "orbital"
controller = "oc"
"#,
    )
    .unwrap();
    let watched = dir.path().join("watched");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_host"))
        .arg("experiment")
        .arg(&spec)
        .args(["--trials", "1", "--view", "127.0.0.1:0", "--out"])
        .arg(&watched)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let address = loop {
        let line = lines.next().expect("a line naming the view").unwrap();
        if let Some(url) = line.strip_prefix("view: serving http://") {
            break url.trim_end_matches('/').to_string();
        }
    };
    let (_, body) = served::request(&address, "GET", "/state.json");
    let state: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(
        state["hello"]["caption"], "watched: arm learner, trial 0 (1 of 2 to run)",
        "{state}"
    );
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    assert!(child.wait().unwrap().success());
    assert!(
        rest.iter().any(|l| l.starts_with("[2/2] orbital trial 0")),
        "{rest:?}"
    );

    let plain = dir.path().join("plain");
    assert!(host()
        .arg("experiment")
        .arg(&spec)
        .args(["--trials", "1", "--out"])
        .arg(&plain)
        .output()
        .unwrap()
        .status
        .success());
    for arm in ["learner", "orbital"] {
        let trial = Path::new("trials").join(arm).join("trial-00.json");
        assert_eq!(
            untimed(&watched.join(&trial)),
            untimed(&plain.join(&trial)),
            "{arm}"
        );
    }
}
