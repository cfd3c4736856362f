//! `host train --view`: the page's stream carries the world the learner
//! learns in with its progress, names the exported policy's world beside
//! it, which acts while someone watches; a run with the view trains
//! exactly as one without, and keeps serving its final state until Ctrl-C.

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, ChildStdout, Command, Stdio};
use tungstenite::{Message, WebSocket};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// A running `host train --view`, stopped when dropped.
struct Training {
    child: Child,
    learning: String,
    greedy: String,
    /// Kept open: a pipe closed under it would kill it with SIGPIPE.
    _stdout: BufReader<ChildStdout>,
}

impl Drop for Training {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn train_with_view(out: &Path, steps: &str) -> Training {
    let mut child = Command::new(HOST)
        .args([
            "train",
            "--view",
            "127.0.0.1:0",
            "--steps",
            steps,
            "--seed",
            "4",
        ])
        .arg("--out")
        .arg(out)
        .stdout(Stdio::piped())
        .spawn()
        .expect("cannot start host train");
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    // view: http://A/ (the exported policy acting: http://B/)
    let addresses: Vec<String> = first
        .split("http://")
        .skip(1)
        .map(|s| s.split('/').next().unwrap().to_string())
        .collect();
    assert!(first.starts_with("view: "), "first line: {first:?}");
    assert_eq!(addresses.len(), 2, "first line: {first:?}");
    Training {
        child,
        learning: addresses[0].clone(),
        greedy: addresses[1].clone(),
        _stdout: stdout,
    }
}

fn viewer(address: &str) -> WebSocket<TcpStream> {
    let stream = TcpStream::connect(address).unwrap();
    tungstenite::client(format!("ws://{address}/stream").as_str(), stream)
        .unwrap()
        .0
}

fn next_json(socket: &mut WebSocket<TcpStream>) -> serde_json::Value {
    loop {
        if let Message::Text(t) = socket.read().unwrap() {
            return serde_json::from_str(&t).unwrap();
        }
    }
}

/// The next frame whose step is past `step`.
fn frame_after(socket: &mut WebSocket<TcpStream>, step: u64) -> serde_json::Value {
    loop {
        let m = next_json(socket);
        if m["t"] == "frame" && m["step"].as_u64().unwrap() > step {
            return m;
        }
    }
}

#[test]
fn the_page_shows_the_learning_world_with_its_progress_and_the_exported_policy_acting_beside_it() {
    let out = std::env::temp_dir().join(format!("train-view-{}", std::process::id()));
    let training = train_with_view(&out, "50000000");

    let mut learning = viewer(&training.learning);
    let hello = next_json(&mut learning);
    assert_eq!(hello["t"], "hello");
    assert_eq!(
        hello["companion"]["url"],
        format!("http://{}/", training.greedy),
        "{hello}"
    );
    let first = frame_after(&mut learning, 0);
    let later = frame_after(&mut learning, first["step"].as_u64().unwrap() + 200_000);
    for frame in [&first, &later] {
        let l = &frame["learning"];
        assert_eq!(l["states_total"], 256, "{l}");
        assert!(l["states_visited"].as_u64().unwrap() > 0, "{l}");
        assert!(
            (0.0..=1.0).contains(&l["exploration"].as_f64().unwrap()),
            "{l}"
        );
    }
    // the training speed, measured from the frames the trainer gives
    assert!(
        later["steps_per_second"].as_f64().unwrap() > 1000.0,
        "{later}"
    );
    // the greedy world's policy is refreshed as training goes on
    let refreshed = |f: &serde_json::Value| f["learning"]["greedy_step"].as_u64().unwrap();
    assert!(refreshed(&later) > refreshed(&first), "{first} {later}");
    assert!(refreshed(&later) <= later["step"].as_u64().unwrap());

    // the exported policy's world acts while someone watches it
    let mut greedy = viewer(&training.greedy);
    assert_eq!(next_json(&mut greedy)["t"], "hello");
    let a = frame_after(&mut greedy, 0);
    let b = frame_after(&mut greedy, a["step"].as_u64().unwrap() + 20);
    assert!(b["step"].as_u64() > a["step"].as_u64());
    assert!(a.get("learning").is_none(), "{a}");
    drop(training);
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn training_with_the_view_gives_the_policy_and_figures_of_training_without_it_and_serves_until_ctrl_c(
) {
    let base = std::env::temp_dir().join(format!("train-view-same-{}", std::process::id()));
    let (with, without) = (base.join("with"), base.join("without"));
    let mut training = train_with_view(&with, "300000");
    // a viewer, so the greedy world runs too
    let mut socket = viewer(&training.learning);
    let _ = next_json(&mut socket);
    // the summary, then the line saying the page stays until Ctrl-C
    let mut rest = String::new();
    loop {
        let mut line = String::new();
        let read = training._stdout.read_line(&mut line).unwrap();
        assert!(read > 0, "host train --view ended before Ctrl-C: {rest}");
        rest.push_str(&line);
        if line.starts_with("view: training ended") {
            break;
        }
    }
    assert!(rest.contains("until Ctrl-C"), "{rest}");
    // still serving its final state after training ended
    let mut late = viewer(&training.learning);
    assert!(next_json(&mut late).is_object());
    let pid = training.child.id().to_string();
    let sent = Command::new("kill").args(["-INT", &pid]).status().unwrap();
    assert!(sent.success());
    assert!(training.child.wait().unwrap().success());
    let plain = Command::new(HOST)
        .args(["train", "--steps", "300000", "--seed", "4", "--out"])
        .arg(&without)
        .output()
        .unwrap();
    assert!(plain.status.success());
    let report = String::from_utf8(plain.stdout).unwrap();
    let figures = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| {
                l.starts_with("formations") || l.starts_with("stuck") || l.starts_with("states")
            })
            .map(String::from)
            .collect()
    };
    assert!(!figures(&report).is_empty(), "{report}");
    assert_eq!(figures(&rest), figures(&report));
    let policy = |dir: &Path| std::fs::read(dir.join("annulus-original.policy")).unwrap();
    assert_eq!(policy(&with), policy(&without));
    let _ = std::fs::remove_dir_all(base);
}
