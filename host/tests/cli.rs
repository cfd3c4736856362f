//! The `host` CLI: run, render, bench, and errors that name the bad input.

use assert_cmd::Command;

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

/// Runs `host` with `args`, expects failure, returns stderr.
fn fails(args: &[&str]) -> String {
    let out = host().args(args).output().unwrap();
    assert!(!out.status.success(), "{args:?} succeeded");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn run_prints_one_json_object_with_the_summary_keys() {
    let out = host()
        .args(["run", "--steps", "2000", "--json", "--seed", "3"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "formations",
        "stuck",
        "collisions_per_1000",
        "mean_eval",
        "steps_per_second",
    ] {
        assert!(
            v.get(key).is_some_and(|x| x.is_number()),
            "missing {key}: {v}"
        );
    }
    let text = host()
        .args([
            "run",
            "--steps",
            "500",
            "--controller",
            "random",
            "--field",
            "letter:L",
        ])
        .output()
        .unwrap();
    assert!(text.status.success());
    assert!(String::from_utf8(text.stdout)
        .unwrap()
        .contains("formations"));
}

#[test]
fn bad_inputs_are_rejected_with_the_offending_value() {
    let e = fails(&["run", "--steps", "10", "--field", "/no/such/field.png"]);
    assert!(e.contains("/no/such/field.png"), "{e}");
    assert!(fails(&["run", "--field", "letter:Q"]).contains("\"Q\""));
    assert!(fails(&["run", "--robots", "0"]).contains("world.robots = 0"));
    assert!(fails(&["run", "--pucks", "100000"]).contains("100008 bodies"));
    assert!(fails(&["run", "--controller", "bogus"]).contains("bogus"));
    let e = fails(&["run", "--controller", "policy:/no/such.policy"]);
    assert!(e.contains("/no/such.policy"), "{e}");

    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.png");
    std::fs::write(&garbage, b"not an image").unwrap();
    let e = fails(&["run", "--steps", "10", "--field", garbage.to_str().unwrap()]);
    assert!(
        e.contains("garbage.png") && e.contains("cannot load field image"),
        "{e}"
    );
}

#[test]
fn render_writes_a_png_and_a_gif() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("world.png");
    let gif = dir.path().join("episode.gif");
    let ok = host()
        .args([
            "render",
            "--steps",
            "50",
            "--size",
            "200",
            "--footprints",
            "--out",
        ])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (200, 200));
    let ok = host()
        .args([
            "render", "--steps", "200", "--every", "100", "--size", "100", "--gif",
        ])
        .arg(&gif)
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
}

#[test]
fn bench_prints_steps_per_second() {
    let out = host().args(["bench", "--steps", "2000"]).output().unwrap();
    assert!(out.status.success());
    let line = String::from_utf8(out.stdout).unwrap();
    let rate = line.trim().strip_suffix(" steps/s").expect("<N> steps/s");
    assert!(rate.parse::<f64>().unwrap() > 0.0);
}

#[test]
fn host_run_takes_the_robot_sensor_model_and_names_a_bad_config() {
    let out = host()
        .args(["run", "--sensors", "robot", "--steps", "300", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.get("mean_eval").is_some_and(|x| x.is_number()));

    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("robot.json");
    std::fs::write(&config, r#"{"camera": {"fov_h_deg": 200}}"#).unwrap();
    let out = host()
        .args([
            "run",
            "--sensors",
            &format!("robot:{}", config.display()),
            "--steps",
            "10",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success());
    assert!(
        err.contains("robot.json") && err.contains("camera.fov_h_deg = 200"),
        "{err}"
    );
    let out = host().args(["run", "--sensors", "sonar"]).output().unwrap();
    assert!(String::from_utf8(out.stderr).unwrap().contains("\"sonar\""));
}

#[test]
fn output_into_a_closed_pipe_ends_quietly_without_a_panic() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let policy = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../policies/oc-heuristic.policy"
    );
    let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("host"))
        .args(["policy", "inspect", policy])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success());
    assert!(!stderr.contains("panicked"), "{stderr}");
}
