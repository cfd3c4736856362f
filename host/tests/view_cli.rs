//! `host view` against `host run`: the view's simulation, stepped to step
//! N, has what `host run --steps N` reports for the same settings (the
//! page's own tests are the view crate's, `view/tests/page.rs`).

mod served;

use served::{request, serve};
use std::process::Command;
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

#[test]
fn the_views_state_at_step_n_is_what_host_run_reports_after_n_steps() {
    let world = [
        "--robots", "5", "--pucks", "60", "--seed", "3", "--field", "letter:L",
    ];
    let served = serve(["--paused"].iter().chain(&world));
    let steps = 3000;
    let (status, body) = request(
        &served.address,
        "POST",
        &format!("/control?action=step&steps={steps}"),
    );
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
    let deadline = Instant::now() + Duration::from_secs(120);
    let frame = loop {
        let (_, body) = request(&served.address, "GET", "/state.json");
        let state: serde_json::Value = serde_json::from_slice(&body).unwrap();
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
