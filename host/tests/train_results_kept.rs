//! `host train` loses nothing: a new run keeps the results it would
//! replace as `<name>.N.policy` and `<name>.N.ckpt`, and SIGTERM or Ctrl-C
//! (SIGINT) during training writes the policy and checkpoint of the state
//! reached, which load and resume.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// A small world, so a run is quick.
const SMALL: [&str; 5] = ["train", "--robots", "4", "--pucks", "60"];

fn host(dir: &Path, args: &[&str]) -> Output {
    Command::new(HOST)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("cannot run host")
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let out = host(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The number after `key` on the line starting with it.
fn figure(text: &str, key: &str) -> u64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(key))
        .unwrap_or_else(|| panic!("no line {key:?} in {text}"));
    line[key.len()..]
        .split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no number after {key:?}: {line}"))
}

#[test]
fn a_second_run_keeps_the_first_runs_policy_and_checkpoint_and_says_where() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let first = [&SMALL[..], &["--steps", "2000"]].concat();
    ok(d, &first);
    let policy = std::fs::read(d.join("out/annulus-original.policy")).unwrap();
    let checkpoint = std::fs::read(d.join("out/annulus-original.ckpt")).unwrap();

    let out = host(d, &[&SMALL[..], &["--steps", "3000"]].concat());
    assert!(out.status.success());
    let (stdout, stderr) = (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    );
    for said in [&stdout, &stderr] {
        assert!(
            said.contains(
                "the previous out/annulus-original.policy as out/annulus-original.1.policy"
            ),
            "{said}"
        );
        assert!(
            said.contains("out/annulus-original.ckpt as out/annulus-original.1.ckpt"),
            "{said}"
        );
    }
    assert_eq!(
        std::fs::read(d.join("out/annulus-original.1.policy")).unwrap(),
        policy
    );
    assert_eq!(
        std::fs::read(d.join("out/annulus-original.1.ckpt")).unwrap(),
        checkpoint
    );
    assert!(d.join("out/annulus-original.policy").is_file());

    // a third keeps the second's under the next free number
    ok(d, &first);
    assert!(d.join("out/annulus-original.2.policy").is_file());
    assert!(d.join("out/annulus-original.2.ckpt").is_file());

    // resuming continues the same run: its own files are replaced
    let resumed = host(
        d,
        &[
            "train",
            "--resume",
            "out/annulus-original.ckpt",
            "--steps",
            "1000",
        ],
    );
    assert!(resumed.status.success());
    assert!(!String::from_utf8_lossy(&resumed.stderr).contains("kept"));
    assert!(!d.join("out/annulus-original.3.policy").exists());
}

#[test]
fn the_summary_puts_its_formations_beside_orbital_constructions_on_the_same_settings() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = ok(d, &[&SMALL[..], &["--steps", "3000"]].concat());
    let oc = ok(
        d,
        &["run", "--robots", "4", "--pucks", "60", "--steps", "3000"],
    );
    let line = text.lines().find(|l| l.starts_with("formations")).unwrap();
    assert!(
        line.contains(&format!(
            "orbital construction: {} in as many steps",
            figure(&oc, "formations")
        )),
        "{line} against host run: {oc}"
    );
}

/// Starts a long run, waits for its first periodic checkpoint (training
/// is under way), sends `signal`, and returns its exit code and stdout.
fn interrupted_run(d: &Path, signal: &str) -> (Option<i32>, String) {
    let mut child = Command::new(HOST)
        .current_dir(d)
        .args(SMALL)
        .args(["--steps", "1000000000", "--checkpoint-every", "20000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start host train");
    let start = Instant::now();
    while !d.join("out/annulus-original.ckpt").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no checkpoint in two minutes"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let pid = child.id().to_string();
    let sent = Command::new("kill")
        .args([signal, &pid])
        .status()
        .expect("cannot run kill");
    assert!(sent.success());
    let mut stdout = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut stdout)
        .unwrap();
    let status = child.wait().unwrap();
    (status.code(), stdout)
}

#[test]
fn sigterm_and_ctrl_c_write_the_policy_and_checkpoint_of_the_state_reached() {
    for signal in ["-TERM", "-INT"] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let (code, stdout) = interrupted_run(d, signal);
        assert_eq!(code, Some(130), "{signal}: {stdout}");
        assert!(stdout.contains("interrupted          after"), "{stdout}");
        let reached = figure(&stdout, "steps");
        assert!(reached > 0 && reached < 1_000_000_000, "{signal}: {stdout}");
        let summary = ok(
            d,
            &[
                "policy",
                "inspect",
                "--summary",
                "out/annulus-original.policy",
            ],
        );
        assert!(summary.contains("annulus"), "{summary}");
        // the checkpoint holds the state reached, not the last periodic one
        let resumed = ok(
            d,
            &[
                "train",
                "--resume",
                "out/annulus-original.ckpt",
                "--steps",
                "1000",
            ],
        );
        assert!(
            resumed.contains(&format!("run total {}", reached + 1000)),
            "{signal}: stopped at {reached}; {resumed}"
        );
        let leftovers: Vec<_> = std::fs::read_dir(d.join("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| !n.ends_with(".policy") && !n.ends_with(".ckpt"))
            .collect();
        assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    }
}
