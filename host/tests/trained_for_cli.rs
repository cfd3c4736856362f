//! Policy blobs of format version 2 from the command line: `host train`
//! records the sensor model and arena and the learner's ties, `policy
//! inspect` shows them, `run` and `render` warn on a mismatch and `flash`
//! refuses a blob trained for another sensor model than the robot's.

use assert_cmd::Command;
use shared::{ActionSets, ActionTable, PolicyBlob, Provenance, State, StateHasher, TrainedFor};
use std::path::{Path, PathBuf};

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .unwrap()
}

/// (status ok, stdout, stderr)
fn output(cmd: &mut Command) -> (bool, String, String) {
    let out = cmd.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// A blob with ties in states 0 and 5, trained for `sensors` in `arena`.
fn tied_blob(dir: &Path, sensors: &str, arena: &str) -> PathBuf {
    let mut sets = ActionSets::new(StateHasher::Original);
    for s in 0..256u16 {
        sets.set(State(s), 0b0100);
    }
    sets.set(State(0), 0b1111);
    sets.set(State(5), 0b0011);
    let blob = PolicyBlob::with_sets(
        ActionTable::default(),
        sets,
        Provenance::new("annulus", "tied", 10, 1).unwrap(),
    )
    .unwrap()
    .with_trained_for(TrainedFor::new(sensors, arena).unwrap());
    let path = dir.join(format!("{sensors}-{arena}.policy"));
    std::fs::write(&path, blob.encode()).unwrap();
    path
}

#[test]
fn a_trained_policy_records_its_sensor_model_and_arena_and_inspect_shows_them() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, _, err) = output(
        host()
            .args(["train", "--steps", "3000", "--name", "t", "--out"])
            .arg(dir.path()),
    );
    assert!(ok, "{err}");
    let bytes = std::fs::read(dir.path().join("t.policy")).unwrap();
    assert_eq!(bytes[4], 2, "host train writes format version 2");
    let blob = PolicyBlob::decode(&bytes).unwrap();
    let t = blob.trained_for().unwrap();
    assert_eq!((t.sensors.as_str(), t.arena.as_str()), ("disc", "thesis"));
    // 3,000 steps leave most states unvisited: every action is best there
    assert!(blob.sets().has_ties());
    let (ok, out, err) = output(
        host()
            .args(["policy", "inspect", "--summary"])
            .arg(dir.path().join("t.policy")),
    );
    assert!(ok, "{err}");
    assert!(out.contains("format     QPOL v2"), "{out}");
    assert!(
        out.contains("for        sensors disc, arena thesis"),
        "{out}"
    );
    assert!(out.contains("ties       "), "{out}");
}

#[test]
fn inspect_shows_each_tied_states_best_actions_and_says_when_a_blob_does_not_record_its_training() {
    let dir = tempfile::tempdir().unwrap();
    let path = tied_blob(dir.path(), "robot", "tv75");
    let (ok, out, err) = output(host().args(["policy", "inspect"]).arg(&path));
    assert!(ok, "{err}");
    assert!(
        out.contains("ties       1 states with 2 best actions, 0 with 3, 1 with 4"),
        "{out}"
    );
    let state = |s: &str| {
        out.lines()
            .find(|l| l.trim_start().starts_with(s))
            .unwrap()
            .to_string()
    };
    assert!(state("0 ").ends_with("0|1|2|3  tie"), "{out}");
    assert!(state("5 ").ends_with("0|1  tie"), "{out}");
    assert!(state("6 ").ends_with("2  -0.150"), "{out}");
    let (ok, out, _) = output(
        host()
            .args(["policy", "inspect", "--summary"])
            .arg(repo().join("policies/oc-heuristic.policy")),
    );
    assert!(ok);
    assert!(out.contains("format     QPOL v1"), "{out}");
    assert!(out.contains("for        not recorded"), "{out}");
}

#[test]
fn run_and_render_warn_when_the_policy_was_trained_for_other_senses_or_another_arena() {
    let dir = tempfile::tempdir().unwrap();
    let robot_tv = tied_blob(dir.path(), "robot", "tv75");
    let controller = format!("policy:{}", robot_tv.display());
    // the default run: disc sensors in the thesis' square
    let (ok, _, err) = output(host().args(["run", "--steps", "200", "--controller", &controller]));
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: policy file")
            && err.contains("sensor model robot (this run: disc)")
            && err.contains("arena tv75 (this run: thesis)"),
        "{err}"
    );
    // its own senses and arena: no word
    let (ok, _, err) = output(host().args([
        "run",
        "--steps",
        "200",
        "--sensors",
        "robot",
        "--controller",
        &controller,
    ]));
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
    // a version 1 blob does not say: no word
    let v1_path = repo().join("policies/oc-heuristic.policy");
    let v1_blob = PolicyBlob::decode(&std::fs::read(&v1_path).unwrap()).unwrap();
    assert_eq!(
        v1_blob.version(),
        1,
        "the shipped hand-written policy is a version 1 blob"
    );
    let v1 = format!("policy:{}", v1_path.display());
    let (ok, _, err) = output(host().args(["run", "--steps", "200", "--controller", &v1]));
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let png = dir.path().join("x.png");
    let (ok, _, err) = output(
        host()
            .args([
                "render",
                "--steps",
                "10",
                "--sensors",
                "robot",
                "--arena",
                "thesis",
                "--controller",
                &controller,
                "--out",
            ])
            .arg(&png),
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("arena tv75 (this run: thesis)") && !err.contains("sensor model robot"),
        "{err}"
    );
}

#[test]
fn flash_refuses_a_policy_trained_for_other_senses_unless_told() {
    let dir = tempfile::tempdir().unwrap();
    let disc = tied_blob(dir.path(), "disc", "thesis");
    let flash = |extra: &[&str]| {
        output(
            host()
                .current_dir(repo())
                .args(["flash", "--dry-run", "--port", "/dev/ttyACM0", "--policy"])
                .arg(&disc)
                .args(extra),
        )
    };
    let (ok, _, err) = flash(&[]);
    assert!(!ok);
    assert!(
        err.contains("sensor model disc") && err.contains("--any-sensors"),
        "{err}"
    );
    let (ok, out, err) = flash(&["--any-sensors"]);
    assert!(ok, "{err}");
    assert!(out.contains("avrdude"), "{out}");
    assert!(
        err.contains("warning") && err.contains("thesis' square"),
        "{err}"
    );
    let robot = tied_blob(dir.path(), "robot", "tv75");
    let (ok, _, err) = output(
        host()
            .current_dir(repo())
            .args(["flash", "--dry-run", "--port", "/dev/ttyACM0", "--policy"])
            .arg(&robot),
    );
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
}
