//! What `host train --view` costs: rounds of `host train` runs without
//! the view, with it and no viewer, and with a viewer reading both pages'
//! streams (a WebSocket client that reads every message, as a browser's
//! socket does; a browser's painting is its own process's work and not
//! counted), in a rotated order; training steps per second as each run
//! reports them. Writes the JSON that `docs/performance.md`'s table is
//! rendered from (`tests/train_view_doc.rs` checks they agree).
//!
//! ```sh
//! cargo build --release -p host
//! cargo run --release -p host --example train_view_bench -- --out docs/train-view.json
//! cargo run -p host --example train_view_bench -- --render docs/train-view.json
//! ```

#[path = "../tests/train_view_table/mod.rs"]
mod train_view_table;

use std::io::{BufRead, BufReader, Read};
use std::net::TcpStream;
use std::process::{Command, Stdio};

const ROUNDS: usize = 5;
const STEPS: u64 = 3_000_000;
const HOST: &str = "target/release/host";

/// The runs compared: a name, whether `--view` is on, whether a viewer
/// reads, whether the 5 % target applies.
const RUNS: [(&str, bool, bool, bool); 3] = [
    ("`host train`", false, false, false),
    ("`host train --view`, no viewer", true, false, true),
    (
        "`host train --view`, a viewer reading both pages' streams",
        true,
        true,
        false,
    ),
];

/// Reads `address`'s stream until it closes.
fn read_stream(address: String) -> std::thread::JoinHandle<u64> {
    std::thread::spawn(move || {
        let Ok(stream) = TcpStream::connect(&address) else {
            return 0;
        };
        let Ok((mut socket, _)) =
            tungstenite::client(format!("ws://{address}/stream").as_str(), stream)
        else {
            return 0;
        };
        let mut messages = 0;
        while socket.read().is_ok() {
            messages += 1;
        }
        messages
    })
}

/// One run's training steps per second.
fn measure(view: bool, viewer: bool, round: usize) -> f64 {
    let out = std::env::temp_dir().join(format!("train-view-bench-{}-{round}", std::process::id()));
    let mut command = Command::new(HOST);
    command
        .args([
            "train",
            "--steps",
            &STEPS.to_string(),
            "--seed",
            "1",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::piped());
    if view {
        command.args(["--view", "127.0.0.1:0"]);
    }
    let mut child = command
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {HOST} (cargo build --release -p host): {e}"));
    let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
    let mut readers = Vec::new();
    if view {
        let mut first = String::new();
        stdout
            .read_line(&mut first)
            .expect("host train's first line");
        if viewer {
            for address in first.split("http://").skip(1) {
                let address = address.split('/').next().unwrap_or_default().to_string();
                readers.push(read_stream(address));
            }
        }
    }
    let mut report = String::new();
    stdout
        .read_to_string(&mut report)
        .expect("host train's report");
    assert!(child.wait().expect("host train").success(), "{report}");
    let messages: u64 = readers.into_iter().map(|r| r.join().unwrap_or(0)).sum();
    let _ = std::fs::remove_dir_all(&out);
    let rate = report
        .lines()
        .find_map(|l| l.strip_prefix("steps per second"))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no steps per second in {report}"));
    eprintln!(
        "round {round}: view {view}, viewer {viewer}: {rate:.0} steps/s ({messages} messages read)"
    );
    rate
}

fn run(out: &str) {
    let mut rates = vec![Vec::new(); RUNS.len()];
    for round in 0..ROUNDS {
        for k in 0..RUNS.len() {
            let which = (k + round) % RUNS.len();
            let (_, view, viewer, _) = RUNS[which];
            rates[which].push(measure(view, viewer, round));
        }
    }
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_default()
    };
    let nproc = std::thread::available_parallelism().map_or(0, |n| n.get());
    let results = serde_json::json!({
        "date": git(&["log", "-1", "--format=%cd", "--date=short"]),
        "commit": git(&["rev-parse", "--short", "HEAD"]),
        "machine": format!("the project's {nproc}-core VM"),
        "rounds": ROUNDS,
        "steps": STEPS,
        "command": "cargo run --release -p host --example train_view_bench -- --out docs/train-view.json",
        "rows": RUNS.iter().zip(&rates).map(|((name, _, _, target), rates)| serde_json::json!({
            "run": name,
            "steps_per_second": rates,
            "target": target,
        })).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&results).expect("JSON") + "\n";
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, out))
        .unwrap_or_else(|e| panic!("cannot write {out}: {e}"));
    print!("{}", train_view_table::render(&results));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1..).unwrap_or_default() {
        [flag, file] if flag == "--render" => {
            let text =
                std::fs::read_to_string(file).unwrap_or_else(|e| panic!("cannot read {file}: {e}"));
            let results: serde_json::Value =
                serde_json::from_str(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
            print!("{}", train_view_table::render(&results));
        }
        [flag, file] if flag == "--out" => run(file),
        _ => eprintln!("usage: train_view_bench --out FILE.json | --render FILE.json"),
    }
}
