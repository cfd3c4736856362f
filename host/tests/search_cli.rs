//! `host search` end to end: a tiny search writes its blob and log, and bad
//! inputs are refused with an error naming them.

use assert_cmd::Command;

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

/// Runs a one-generation search of two candidates on worlds of `steps`
/// steps in `dir`, writing `s/NAME.policy`; `args` adds the world's flags.
/// Returns what it printed.
fn tiny_search(dir: &std::path::Path, args: &[&str], steps: &str, name: &str) -> String {
    let out = host()
        .current_dir(dir)
        .arg("search")
        .args(args)
        .args(["--start", "random", "--generations", "1"])
        .args(["--population", "2", "--elites", "1"])
        .args(["--fitness-seeds", "1", "--fitness-steps", steps])
        .args(["--validation-seeds", "1", "--validation-steps", steps])
        .args(["--out", "s", "--name", name])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn a_search_ends_by_printing_its_steps_per_second_per_core_and_keeps_time_out_of_its_log() {
    let dir = tempfile::tempdir().unwrap();
    let printed = tiny_search(dir.path(), &["--threads", "1"], "300", "speed");
    let line = printed
        .lines()
        .find(|l| l.starts_with("speed"))
        .unwrap_or_else(|| panic!("no speed line in:\n{printed}"));
    let rate: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(rate > 0.0, "{line}");
    assert!(line.contains("steps/s per core (1 core,"), "{line}");
    let log = std::fs::read_to_string(dir.path().join("s/speed.search.json")).unwrap();
    assert!(
        !log.contains("elapsed"),
        "the log is the search's result, not its timing"
    );
}

#[test]
fn a_small_search_writes_a_policy_that_host_run_drives_and_a_json_log() {
    let dir = tempfile::tempdir().unwrap();
    tiny_search(
        dir.path(),
        &["--sensors", "robot", "--noise", "1"],
        "500",
        "tiny",
    );
    let log: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s/tiny.search.json")).unwrap())
            .unwrap();
    assert_eq!(log["generations"].as_array().unwrap().len(), 1);
    assert_eq!(log["world"]["pucks"], 12, "the annulus' count on the TV");
    let run = host()
        .current_dir(dir.path())
        .args([
            "run",
            "--sensors",
            "robot",
            "--steps",
            "200",
            "--controller",
            "policy:s/tiny.policy",
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn a_searched_table_records_its_senses_so_that_flash_refuses_one_searched_with_discs() {
    let dir = tempfile::tempdir().unwrap();
    for sensors in ["robot", "disc"] {
        tiny_search(
            dir.path(),
            &["--sensors", sensors, "--arena", "tv75"],
            "300",
            sensors,
        );
    }
    let inspect = host()
        .current_dir(dir.path())
        .args(["policy", "inspect", "s/robot.policy"])
        .output()
        .unwrap();
    let text = String::from_utf8(inspect.stdout).unwrap();
    let line = text.lines().find(|l| l.starts_with("for ")).unwrap();
    assert!(line.contains("robot") && line.contains("tv75"), "{line}");
    let flash = host()
        .current_dir(dir.path())
        .args(["flash", "--dry-run", "--policy", "s/disc.policy"])
        .output()
        .unwrap();
    assert!(!flash.status.success());
    let e = String::from_utf8(flash.stderr).unwrap();
    assert!(e.contains("sensor model disc"), "{e}");
}

#[test]
fn bad_search_settings_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    for (args, says) in [
        (vec!["--population", "1"], "--population = 1"),
        (vec!["--elites", "20"], "--elites = 20"),
        (vec!["--floor", "0.5"], "--floor = 0.5"),
        (vec!["--start", "missing.policy"], "missing.policy"),
    ] {
        let out = host()
            .current_dir(dir.path())
            .arg("search")
            .args(&args)
            .args(["--out", "s"])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(says), "{args:?}: {e}");
    }
}

#[test]
fn the_search_help_shows_the_world_and_the_search_and_none_of_the_learners_settings() {
    let out = host().args(["search", "--help"]).output().unwrap();
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    for shown in [
        "The world searched in:",
        "The search:",
        "--field",
        "--population",
        "--also-noise",
        "[default: robot]",
        "[default: tv75]",
        "[default: 1]",
    ] {
        assert!(help.contains(shown), "{shown} missing from:\n{help}");
    }
    for hidden in [
        "--alpha",
        "--gamma",
        "--epsilon",
        "--initial-q",
        "--n-step",
        "--checkpoint-every",
        "--tie-tolerance",
    ] {
        assert!(!help.contains(hidden), "{hidden} shown in:\n{help}");
    }
    let refused = host().args(["search", "--alpha", "0.5"]).output().unwrap();
    assert!(!refused.status.success());
    let e = String::from_utf8_lossy(&refused.stderr);
    assert!(e.contains("host search does not use --alpha"), "{e}");
}

#[test]
fn a_search_without_world_flags_is_the_robots_on_the_tv_at_the_default_noise_and_prints_a_line_per_generation(
) {
    let dir = tempfile::tempdir().unwrap();
    let out = host()
        .current_dir(dir.path())
        .arg("search")
        .args(["--start", "random", "--generations", "2"])
        .args(["--population", "2", "--elites", "1"])
        .args(["--fitness-seeds", "1", "--fitness-steps", "300"])
        .args(["--validation-seeds", "1", "--validation-steps", "300"])
        .args(["--out", "s", "--name", "plain"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s/plain.search.json")).unwrap())
            .unwrap();
    assert_eq!(log["world"]["sensors"], "robot");
    assert_eq!(log["world"]["arena"], "tv75");
    assert_eq!(log["world"]["noise"], 1.0);
    // its output is a pipe here: one progress line per generation
    let progress = String::from_utf8(out.stderr).unwrap();
    let lines: Vec<&str> = progress
        .lines()
        .filter(|l| l.starts_with("generation "))
        .collect();
    assert_eq!(lines.len(), 2, "{progress}");
    assert!(
        lines[0].starts_with("generation 1/2  best "),
        "{}",
        lines[0]
    );
    assert!(lines[1].contains("time left 0m00s"), "{}", lines[1]);
    assert!(
        !progress.contains('\r'),
        "no live line in a pipe: {progress:?}"
    );
}
