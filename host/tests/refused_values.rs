//! Refused values, as `docs/ranges.md` documents them: exit code 1 whether
//! the value is refused while the command line is parsed or after, 2 only
//! for a command line that cannot be read; numeric flags checked against
//! their rows before anything starts; and `host monitor` giving up on a
//! port that is no serial device instead of retrying forever.

use assert_cmd::Command;
use std::time::{Duration, Instant};

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

/// Runs `host args` (at most 60 s) and returns its exit code and stderr.
fn refused(args: &[&str]) -> (Option<i32>, String) {
    let out = host()
        .args(args)
        .timeout(Duration::from_secs(60))
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn a_value_refused_while_parsing_exits_1_as_one_refused_after() {
    for (args, says) in [
        (
            &[
                "replay",
                "--log",
                "x.log",
                "--policy",
                "p",
                "--counts-per-mm",
                "0",
            ][..],
            "--counts-per-mm 0: outside its plausible range [0.1, 1000]",
        ),
        (
            &[
                "replay",
                "--log",
                "x.log",
                "--policy",
                "p",
                "--track-mm",
                "NaN",
            ],
            "--track-mm NaN mm: outside its plausible range",
        ),
        (
            &["view", "--log", "x.log", "--policy", "p", "--mm-per-unit=0"],
            "--mm-per-unit 0 mm: outside its plausible range",
        ),
        (
            &[
                "field", "gain", "--marks", "2x1", "--out", "g.json", "a.log",
            ],
            "gain.rows = 1: outside its plausible range [2, 32]",
        ),
        (
            &["run", "--pucks", "many"],
            "invalid value 'many' for '--pucks",
        ),
        (&["bench", "--sensors", "eyes"], "invalid value 'eyes'"),
        (
            &["run", "--pucks", "0", "--steps", "1"],
            "pucks = 0: outside its plausible range",
        ),
    ] {
        let (code, err) = refused(args);
        assert_eq!(code, Some(1), "host {}: {err}", args.join(" "));
        assert!(err.contains(says), "host {}: {err}", args.join(" "));
    }
}

#[test]
fn a_command_line_that_cannot_be_read_exits_2_and_help_exits_0() {
    let (code, err) = refused(&["run", "--no-such-flag"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--no-such-flag"), "{err}");
    let (code, err) = refused(&["replay", "--policy", "p"]);
    assert_eq!(code, Some(2), "{err}");
    let out = host().args(["run", "--help"]).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn search_refuses_threads_and_steps_outside_their_rows_before_starting() {
    for (flag, value, says) in [
        (
            "--threads",
            "5000",
            "--threads 5000: outside its plausible range [1, 1024]",
        ),
        (
            "--fitness-steps",
            "100000000000",
            "--fitness-steps 1e11 steps: outside its plausible range [1, 1e10] steps",
        ),
        (
            "--validation-seeds",
            "0",
            "--validation-seeds 0: outside its plausible range [1, 1000]",
        ),
        (
            "--population",
            "100000",
            "--population 100000: outside its plausible range [1, 1024]",
        ),
    ] {
        let started = Instant::now();
        let out = tempfile::tempdir().unwrap();
        let (code, err) = refused(&[
            "search",
            "--start",
            "random",
            flag,
            value,
            "--out",
            out.path().to_str().unwrap(),
        ]);
        assert_eq!(code, Some(1), "{flag} {value}: {err}");
        assert!(err.contains(says), "{flag} {value}: {err}");
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "{flag} {value}"
        );
    }
}

#[cfg(unix)]
#[test]
fn monitor_gives_up_at_once_on_a_port_that_is_no_serial_device() {
    let dir = tempfile::tempdir().unwrap();
    let capture = dir.path().join("capture.bin");
    std::fs::write(&capture, [0u8; 16]).unwrap();
    let out = dir.path().join("run.log");
    for (port, what) in [
        ("/dev/zero", "a character device that is not a terminal"),
        ("/dev/null", "a character device that is not a terminal"),
        (capture.to_str().unwrap(), "a regular file"),
        (dir.path().to_str().unwrap(), "a directory"),
    ] {
        let started = Instant::now();
        let (code, err) = refused(&["monitor", "--port", port, "--out", out.to_str().unwrap()]);
        assert_eq!(code, Some(1), "{port}: {err}");
        assert!(
            err.contains(&format!("port {port} is {what}, not a serial device")),
            "{port}: {err}"
        );
        assert!(started.elapsed() < Duration::from_secs(20), "{port}");
        assert!(!out.exists(), "{port}: no log is left behind");
    }
}
