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
    assert!(fails(&["run", "--robots", "0"]).contains("robots = 0: outside"));
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
            "--band",
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
    let img = image::open(&png).unwrap().into_rgb8();
    assert_eq!((img.width(), img.height()), (200, 200));
    assert!(
        img.pixels().any(|p| *p == sim::render::BAND),
        "--band draws the target band's outline"
    );
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

/// Runs `host` with `args`, expects exit code 1 (a refusal, not an abort
/// or a hang), returns stderr.
fn refused(args: &[&str]) -> String {
    let out = host()
        .args(args)
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    stderr
}

#[test]
fn implausible_settings_are_refused_naming_the_key_the_value_and_the_range() {
    // Eval of no pucks is 1: every check would count as a formation
    let e = refused(&["run", "--pucks", "0", "--steps", "2000"]);
    assert!(
        e.contains("pucks = 0: outside its plausible range [1, 100000]"),
        "{e}"
    );

    let dir = tempfile::tempdir().unwrap();
    let arena = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path.display().to_string()
    };
    // 17 GB of broad-phase grid, 7.1 TB of observe's top-down image
    let huge = arena("huge.toml", "screen_mm = [1e7, 1e7]\n");
    let in_range = "arena.screen_mm[0] = 10000000: outside its plausible range [100, 10000] mm";
    for args in [
        vec!["run", "--arena", &huge, "--steps", "10"],
        vec!["render", "--arena", &huge, "--out", "x.png"],
        vec!["train", "--arena", &huge, "--steps", "10"],
        vec![
            "observe",
            "--arena",
            &huge,
            "--photo",
            "x.jpg",
            "--corners",
            "10,10,390,10,390,290,10,290",
        ],
    ] {
        let e = refused(&args);
        assert!(
            e.contains(in_range) && e.contains("huge.toml"),
            "{args:?}: {e}"
        );
    }
    // a robot radius in metres: 108 GB in observe
    let metres = arena("metres.toml", "robot_radius_mm = 0.065\n");
    let e = refused(&["run", "--arena", &metres, "--steps", "10"]);
    assert!(
        e.contains("arena.robot_radius_mm = 0.065: outside its plausible range [5, 500] mm"),
        "{e}"
    );
    // never ends: 1e300 times the thesis' step counts
    let out = dir.path().join("experiment");
    let e = refused(&[
        "experiment",
        "annulus",
        "--scale",
        "1e300",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        e.contains("--scale 1e300: outside its plausible range [1e-6, 10]"),
        "{e}"
    );
    let fast = arena("fast.toml", "forward_speed = 1e30\n");
    let e = refused(&["run", "--arena", &fast, "--steps", "10"]);
    assert!(e.contains("arena.forward_speed = 1e30: outside"), "{e}");

    let robot = dir.path().join("robot.json");
    std::fs::write(
        &robot,
        r#"{"field": {"mounts": [{"forward_mm": 1e300, "right_mm": 0}, {"forward_mm": 0, "right_mm": 0}, {"forward_mm": 0, "right_mm": 0}]}}"#,
    )
    .unwrap();
    let sensors = format!("robot:{}", robot.display());
    let e = refused(&["run", "--sensors", &sensors, "--steps", "10"]);
    assert!(
        e.contains("field.mounts[0].forward_mm")
            && e.contains("= 1e300: outside its plausible range [-500, 500] mm"),
        "{e}"
    );
    std::fs::write(&robot, r#"{"field": {"gamma": 1e300}}"#).unwrap();
    let e = refused(&["run", "--sensors", &sensors, "--steps", "10"]);
    assert!(
        e.contains("field.gamma = 1e300: outside its plausible range [0.5, 4]"),
        "{e}"
    );
}

#[test]
fn a_settings_error_says_invalid_simulation_settings_at_most_once() {
    let e = refused(&["train", "--robots", "0", "--steps", "10"]);
    assert!(e.contains("robots = 0: outside"), "{e}");
    assert!(e.matches("invalid simulation settings").count() <= 1, "{e}");
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("a.toml");
    std::fs::write(&arena, "pucks = 0\n").unwrap();
    let e = refused(&["train", "--arena", arena.to_str().unwrap(), "--steps", "10"]);
    assert!(e.contains("arena.pucks = 0: outside"), "{e}");
    assert!(e.matches("invalid simulation settings").count() <= 1, "{e}");
}

#[test]
fn an_output_file_is_written_only_into_a_folder_that_exists_and_never_over_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let export = |out: &str| {
        host()
            .current_dir(dir.path())
            .args(["field", "export", "--arena", "tv75", "--out", out])
            .output()
            .unwrap()
    };
    let out = export("no/such/x.png");
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cannot write no/such/x.png: the folder no/such does not exist"),
        "{e}"
    );
    assert!(!dir.path().join("no").exists(), "the folder was created");
    std::fs::create_dir(dir.path().join("folder")).unwrap();
    let out = export("folder");
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(e.matches("folder").count(), 2, "said once: {e}");
    assert!(e.contains("cannot write folder: it is a folder"), "{e}");
}

#[cfg(unix)]
#[test]
fn a_file_larger_than_its_format_allows_is_refused_without_being_read_whole() {
    let policy = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../policies/oc-heuristic.policy"
    );
    for args in [
        vec!["policy", "inspect", "/dev/zero"],
        vec!["replay", "--log", "/dev/zero", "--policy", policy],
        vec!["train", "--config", "/dev/zero", "--steps", "10"],
    ] {
        let e = refused(&args);
        assert!(
            e.contains("/dev/zero") && e.contains("larger than"),
            "{args:?}: {e}"
        );
    }
}
