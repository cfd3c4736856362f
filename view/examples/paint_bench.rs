//! Benchmark (not a test): distinct simulation states the page paints per
//! second in headless Chromium, for the 5-robot TV world and the thesis'
//! 8-robot, 250-puck world, at real time and at 10x. Counted by the page
//! itself (`data-painted`: frames painted whose step differs from the
//! last painted). Writes the runs as JSON; `--render FILE` prints the
//! markdown table of `docs/performance.md`.
//!
//! ```sh
//! cargo run -p view --example paint_bench -- --out docs/view-paint.json
//! cargo run -p view --example paint_bench -- --render docs/view-paint.json
//! ```

#[path = "../tests/browser/mod.rs"]
mod browser;
#[path = "../tests/paint/mod.rs"]
mod paint;

use std::time::Duration;
use view::{Speed, View, ViewOptions, ViewSettings};

const SECONDS: u64 = 6;
const ROUNDS: usize = 3;

fn worlds() -> Vec<(&'static str, ViewSettings)> {
    let tv = ViewSettings::default()
        .with_query(
            "sensors=robot&arena=tv75&robots=5",
            &Default::default(),
            &[],
        )
        .expect("the TV world's settings");
    vec![
        ("5 robots, tv75, robot senses", tv),
        ("thesis: 8 robots, 250 pucks", ViewSettings::default()),
    ]
}

fn measure(settings: &ViewSettings, speed: Speed) -> (f64, f64) {
    let view = View::start(ViewOptions {
        bind: "127.0.0.1:0".parse().expect("an address"),
        settings: settings.clone(),
        policies: None,
        allowed: Default::default(),
        paused: false,
        speed,
    })
    .expect("the view starts");
    let address = view.spawn().expect("the view serves");
    let mut page = browser::Browser::open(&format!("http://{address}/"), (1100, 820));
    page.wait_for("Number(document.documentElement.dataset.painted) > 20", 60);
    let sample = |page: &mut browser::Browser| {
        let v = page.eval("[Number(document.documentElement.dataset.painted), performance.now(), Number(document.documentElement.dataset.step)]");
        (
            v[0].as_f64().unwrap_or(0.0),
            v[1].as_f64().unwrap_or(0.0),
            v[2].as_f64().unwrap_or(0.0),
        )
    };
    let (p0, t0, s0) = sample(&mut page);
    std::thread::sleep(Duration::from_secs(SECONDS));
    let (p1, t1, s1) = sample(&mut page);
    let seconds = (t1 - t0) / 1000.0;
    ((p1 - p0) / seconds, (s1 - s0) / seconds)
}

fn run(out: &str) {
    let mut rows = Vec::new();
    for (name, settings) in worlds() {
        for speed in [Speed::Real, Speed::Ten] {
            rows.push((name, settings.clone(), speed, Vec::new(), Vec::new()));
        }
    }
    for round in 0..ROUNDS {
        for (name, settings, speed, painted, steps) in rows.iter_mut() {
            let (p, s) = measure(settings, *speed);
            eprintln!("round {round}: {name}, {speed:?}: {p:.1} states painted/s, {s:.0} steps/s");
            painted.push(p);
            steps.push(s);
        }
    }
    let git = |args: &[&str]| {
        std::process::Command::new("git")
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
        "profile": if cfg!(debug_assertions) { "dev" } else { "release" },
        "rounds": ROUNDS,
        "seconds": SECONDS,
        "command": "cargo run -p view --example paint_bench -- --out docs/view-paint.json",
        "rows": rows.iter().map(|(name, _, speed, painted, steps)| serde_json::json!({
            "world": name,
            "speed": match speed { Speed::Real => "real time (50 steps/s)", Speed::Ten => "10x (500 steps/s)", Speed::Max => "max" },
            "painted_per_second": painted,
            "steps_per_second": paint::median(steps),
        })).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&results).expect("JSON") + "\n";
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, out))
        .unwrap_or_else(|e| panic!("cannot write {out}: {e}"));
    print!("{}", paint::render(&results));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1..).unwrap_or_default() {
        [flag, file] if flag == "--render" => {
            let text =
                std::fs::read_to_string(file).unwrap_or_else(|e| panic!("cannot read {file}: {e}"));
            let results: serde_json::Value =
                serde_json::from_str(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
            print!("{}", paint::render(&results));
        }
        [flag, file] if flag == "--out" => run(file),
        _ => eprintln!("usage: paint_bench --out FILE.json | --render FILE.json"),
    }
}
