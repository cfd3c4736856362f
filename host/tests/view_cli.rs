//! `host view` against `host run`: the view's simulation, stepped to step
//! N, has what `host run --steps N` reports for the same settings (the
//! page's own tests are the view crate's, `view/tests/page.rs`).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// A running `host view`, stopped when dropped.
struct Served {
    child: Child,
    address: String,
    /// Kept open: `host view` prints more after its first line, and a
    /// pipe closed under it kills it with SIGPIPE.
    _stdout: BufReader<ChildStdout>,
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(args: &[&str]) -> Served {
    let mut child = Command::new(HOST)
        .args(["view", "--port", "0", "--paused"])
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .expect("cannot start host view");
    let mut first = String::new();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    stdout.read_line(&mut first).unwrap();
    let address = first
        .trim()
        .strip_prefix("view: serving http://")
        .unwrap_or_else(|| panic!("first line: {first:?}"))
        .trim_end_matches('/')
        .to_string();
    Served {
        child,
        address,
        _stdout: stdout,
    }
}

fn request(address: &str, method: &str, path: &str) -> (u16, String) {
    let mut stream = TcpStream::connect(address).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: {address}\r\nContent-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut reply = String::new();
    stream.read_to_string(&mut reply).unwrap();
    let (head, body) = reply.split_once("\r\n\r\n").unwrap();
    (
        head.split(' ').nth(1).unwrap().parse().unwrap(),
        body.to_string(),
    )
}

#[test]
fn the_views_state_at_step_n_is_what_host_run_reports_after_n_steps() {
    let world = [
        "--robots", "5", "--pucks", "60", "--seed", "3", "--field", "letter:L",
    ];
    let served = serve(&world);
    let steps = 3000;
    let (status, body) = request(
        &served.address,
        "POST",
        &format!("/control?action=step&steps={steps}"),
    );
    assert_eq!(status, 200, "{body}");
    let deadline = Instant::now() + Duration::from_secs(120);
    let frame = loop {
        let (_, body) = request(&served.address, "GET", "/state.json");
        let state: serde_json::Value = serde_json::from_str(&body).unwrap();
        if state["frame"]["step"] == steps {
            break state["frame"].clone();
        }
        assert!(Instant::now() < deadline, "{}", state["frame"]["step"]);
        std::thread::sleep(Duration::from_millis(50));
    };
    let out = Command::new(HOST)
        .args(["run", "--json", "--steps", &steps.to_string()])
        .args(world)
        .output()
        .unwrap();
    assert!(out.status.success());
    let run: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "steps",
        "formations",
        "stuck",
        "mean_eval",
        "collisions_per_1000",
    ] {
        let ours = if key == "steps" {
            &frame["step"]
        } else {
            &frame[key]
        };
        assert_eq!(ours, &run[key], "{key}");
    }
    assert!(run["mean_eval"].as_f64().unwrap() > 0.0);
}
