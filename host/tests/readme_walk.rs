//! The README's commands, run as a newcomer runs them: every line of every
//! `sh` code block of README.md, in order, in a copy of the repository,
//! with `host` resolved as the README says (its `export PATH=...` line,
//! run before each command, must make `host` the binary the first command
//! builds, `target/release/host`; here that file is this build's `host`).
//! A command that does not run fails the test.
//!
//! What the walk changes, and why (each rule is checked to apply):
//! - `cargo run --release -p host -- ARGS` runs as `host ARGS`: the binary
//!   that command builds is the one under test (a release build inside a
//!   test would take ten minutes).
//! - `./scripts/test` is skipped: it is the test suite this test is part of.
//! - Commands that would run long get tiny settings ([`TINY`]): a flag the
//!   command already has gets the tiny value, others are appended.
//! - Servers (`host display`, `host view`, `host train --view`) listen on
//!   any free port (`--port 0`, `--view 127.0.0.1:0`); the walk waits for
//!   the line naming the page (for `train --view`, the line saying training
//!   ended), requests the page, then sends Ctrl-C (SIGINT) and expects a
//!   clean exit.
//! - `host flash` runs with `--dry-run` (no robot is plugged in);
//!   `host experiment --view`, which ends with its trials, on a free port.
//! - Commands that read what only hardware makes are skipped, each with
//!   its reason ([`NEEDS_HARDWARE`]); the walk checks that the file they
//!   read is indeed not in the repository.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// Tiny settings by command (the words after `host`): flags given the
/// value here whether or not the README's command has them.
const TINY: &[(&str, &[(&str, &str)])] = &[
    ("train", &[("--steps", "2000")]),
    ("shape", &[("--generations", "1"), ("--scale", "0.005")]),
    ("render", &[("--steps", "2000"), ("--size", "200")]),
    ("experiment", &[("--scale", "0.0005"), ("--trials", "1")]),
];

/// Servers by command: the port flag and the value that picks a free port,
/// and the start of the stdout line after which the page is up.
const SERVERS: &[(&str, &str, &str, &str)] = &[
    ("display", "--port", "0", "display: serving http://"),
    ("view", "--port", "0", "view: serving http://"),
    ("train", "--view", "127.0.0.1:0", "view: training ended"),
];

/// Commands skipped because they read what only a robot, a panel or a
/// camera makes: (command words, the file it reads, the reason).
const NEEDS_HARDWARE: &[(&str, &str, &str)] = &[
    ("monitor", "", "records a robot on a serial port"),
    (
        "replay",
        "run.log",
        "reads the log host monitor recorded from a robot",
    ),
    (
        "view --log",
        "run.log",
        "reads the log host monitor recorded from a robot",
    ),
    (
        "field gain",
        "mark-*.zlog",
        "reads a robot's logs at the display page's marks",
    ),
    (
        "display --field thesis:T --gain",
        "gain.toml",
        "reads the gain host field gain measures from a robot's logs",
    ),
    ("observe", "run.jpg", "reads a photo of the panel"),
];

/// The lines of the README's `sh` code blocks, comments and all.
fn readme_commands(readme: &str) -> Vec<String> {
    let mut lines = Vec::new();
    let mut inside = false;
    for line in readme.lines() {
        if line.trim_start().starts_with("```") {
            inside = !inside && line.trim() == "```sh";
            continue;
        }
        if inside && !line.trim().is_empty() {
            lines.push(line.trim().to_string());
        }
    }
    lines
}

/// The command without its trailing `# comment`, as words.
fn words(line: &str) -> Vec<String> {
    let command = match line.find(" #") {
        Some(i) => &line[..i],
        None => line,
    };
    command.split_whitespace().map(String::from).collect()
}

/// Sets `flag` to `value`: replaces the value it has (a flag standing
/// alone, as `--view`, takes it after it) or appends both.
fn set_flag(words: &mut Vec<String>, flag: &str, value: &str) {
    match words.iter().position(|w| w == flag) {
        Some(i) if words.get(i + 1).is_some_and(|v| !v.starts_with("--")) => {
            words[i + 1] = value.to_string()
        }
        Some(i) => words.insert(i + 1, value.to_string()),
        None => words.extend([flag.to_string(), value.to_string()]),
    }
}

/// Copies the repository into `to`, without build outputs and results.
fn copy_repository(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        let skip = [
            "target",
            ".git",
            "out",
            "__pycache__",
            ".venv",
            ".pytest_cache",
        ];
        if skip.iter().any(|s| name == *s) {
            continue;
        }
        let (source, dest) = (entry.path(), to.join(&name));
        let kind = entry.file_type().unwrap();
        if kind.is_dir() {
            std::fs::create_dir_all(&dest).unwrap();
            copy_repository(&source, &dest);
        } else if kind.is_file() {
            std::fs::copy(&source, &dest).unwrap();
        }
    }
}

/// A shell running the README's PATH line, then `command`, in `dir`.
fn shell(dir: &Path, path_line: &str, command: &str) -> Command {
    let mut shell = Command::new("bash");
    shell
        .current_dir(dir)
        .args(["-c", &format!("{path_line}\n{command}")])
        // a newcomer's PATH, without the test's own additions
        .env(
            "PATH",
            std::env::var("PATH").unwrap_or_else(|_| "/usr/bin:/bin".into()),
        );
    shell
}

/// Runs a command to its end; panics with its output if it fails.
fn run(dir: &Path, path_line: &str, command: &str) {
    let out = shell(dir, path_line, command)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "README command failed: {command}\nstdout: {}\nstderr: {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Starts a server, waits for `ready`, requests its page, stops it with
/// SIGINT and expects a clean exit.
fn serve(dir: &Path, path_line: &str, command: &str, ready: &str) {
    // exec: the signal goes to host itself, not to the shell
    let mut child = shell(dir, path_line, &format!("exec {command}"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let start = Instant::now();
    let mut seen = Vec::new();
    let mut address = None;
    loop {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "{command}: not ready in 5 minutes: {seen:?}"
        );
        let Some(Ok(line)) = lines.next() else {
            let _ = child.kill();
            panic!("README command ended before serving: {command}: {seen:?}");
        };
        if address.is_none() {
            address = line
                .split("http://")
                .nth(1)
                .and_then(|rest| rest.split('/').next())
                .map(String::from);
        }
        seen.push(line.clone());
        if line.starts_with(ready) {
            break;
        }
    }
    let address = address.unwrap_or_else(|| panic!("{command}: no address in {seen:?}"));
    assert_eq!(
        status_of_get(&address),
        "200",
        "{command}: GET / on {address}"
    );
    // what it prints next must find an open pipe
    std::thread::spawn(move || lines.for_each(drop));
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    let status = child.wait().unwrap();
    // done, or ended by the signal's default action
    use std::os::unix::process::ExitStatusExt;
    assert!(
        status.success() || status.signal() == Some(2),
        "{command}: Ctrl-C gave {status}"
    );
}

/// The status code of `GET /` at `address` (read from the status line,
/// not waiting for the connection to close).
fn status_of_get(address: &str) -> String {
    let mut stream = TcpStream::connect(address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    write!(
        stream,
        "GET / HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut head = Vec::new();
    let mut byte = [0u8];
    while !head.ends_with(b"\r\n") && stream.read(&mut byte).unwrap_or(0) == 1 {
        head.push(byte[0]);
    }
    let line = String::from_utf8_lossy(&head).to_string();
    line.split(' ').nth(1).unwrap_or_default().to_string()
}

#[test]
fn every_readme_command_runs_as_written_from_a_copy_of_the_repository() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let lines = readme_commands(&readme);
    assert!(lines.len() > 10, "README code blocks: {lines:?}");

    let copy = tempfile::tempdir().unwrap();
    let dir = copy.path();
    copy_repository(&root, dir);
    // what the first command builds
    std::fs::create_dir_all(dir.join("target/release")).unwrap();
    std::os::unix::fs::symlink(HOST, dir.join("target/release/host")).unwrap();

    // the README says once how `host` is found; it must find that binary
    let path_line = lines
        .iter()
        .find(|l| l.starts_with("export PATH="))
        .expect("the README says how to put host on the PATH")
        .clone();
    let found = shell(dir, &path_line, "command -v host").output().unwrap();
    assert_eq!(
        String::from_utf8_lossy(&found.stdout).trim(),
        dir.join("target/release/host").display().to_string(),
        "the README's PATH line does not make `host` target/release/host"
    );

    let mut ran = Vec::new();
    let mut skipped = Vec::new();
    for line in &lines {
        let mut w = words(line);
        if w.first().map(String::as_str) == Some("export") {
            continue;
        }
        if w == ["./scripts/test"] {
            skipped.push("./scripts/test: the test suite this test is part of".to_string());
            continue;
        }
        if w.starts_with(&["cargo", "run", "--release", "-p", "host", "--"].map(String::from)) {
            w.splice(0..6, ["host".to_string()]);
        }
        assert_eq!(w[0], "host", "a README command that is not host's: {line}");
        let rest = w[1..].join(" ");
        if let Some((_, file, reason)) = NEEDS_HARDWARE.iter().find(|(c, _, _)| rest.starts_with(c))
        {
            assert!(
                file.is_empty() || !dir.join(file).exists(),
                "{line} is skipped as needing {file}, which the repository has"
            );
            skipped.push(format!("{line}: {reason}"));
            continue;
        }
        let sub = w[1].clone();
        if let Some((_, flags)) = TINY.iter().find(|(c, _)| *c == sub) {
            for (flag, value) in flags.iter() {
                set_flag(&mut w, flag, value);
            }
        }
        if sub == "flash" {
            w.push("--dry-run".into());
        }
        if sub == "experiment" && w.iter().any(|a| a == "--view") {
            // runs to its end; any free port
            set_flag(&mut w, "--view", "127.0.0.1:0");
        }
        let server = SERVERS
            .iter()
            .find(|(c, flag, _, _)| *c == sub && (*c != "train" || w.contains(&flag.to_string())));
        match server {
            Some((_, flag, value, ready)) => {
                set_flag(&mut w, flag, value);
                serve(dir, &path_line, &w.join(" "), ready);
            }
            None => run(dir, &path_line, &w.join(" ")),
        }
        ran.push(w.join(" "));
    }
    // the results the commands say they write
    for file in [
        "out/annulus-original.policy",
        "world.png",
        "formed.png",
        "tv.png",
        "look.png",
    ] {
        assert!(dir.join(file).is_file(), "no {file} after {ran:#?}");
    }
    assert!(
        ran.iter().any(|c| c.starts_with("host display"))
            && ran.iter().any(|c| c.starts_with("host view"))
            && ran.iter().any(|c| c.starts_with("host flash")),
        "{ran:#?}"
    );
    assert_eq!(
        skipped.len(),
        NEEDS_HARDWARE.len() + 1,
        "every skip rule applies to a README command: {skipped:#?}"
    );
}
