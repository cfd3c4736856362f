//! `host shape` end to end on shapes drawn here: the image checks (the
//! dark-on-light refusal naming `--invert`, `--invert` itself, a shape too
//! small for six pucks), a tiny run whose blob `host flash --dry-run`
//! accepts and whose report `host run` reproduces, a run killed and run
//! again ending with the table of an unbroken one, and the result never
//! below its start on its validation worlds. Tiny step counts (`--scale`,
//! `--generations`) keep each run to seconds.

use assert_cmd::Command;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

/// A 64 x 64 PNG at `path`: the rectangles (x0, y0, x1, y1) drawn white on
/// black, or black on white when `dark_on_light`.
fn draw(path: &Path, rects: &[(u32, u32, u32, u32)], dark_on_light: bool) {
    let (ink, paper) = if dark_on_light { (0, 255) } else { (255, 0) };
    let img = image::GrayImage::from_fn(64, 64, |x, y| {
        let on = rects
            .iter()
            .any(|&(x0, y0, x1, y1)| (x0..x1).contains(&x) && (y0..y1).contains(&y));
        image::Luma([if on { ink } else { paper }])
    });
    img.save(path).unwrap();
}

/// An L of two thick strokes.
const L_SHAPE: [(u32, u32, u32, u32); 2] = [(14, 10, 26, 54), (14, 42, 50, 54)];

/// Runs `host shape` in `dir` with `args`; its output.
fn shape(dir: &Path, args: &[&str]) -> std::process::Output {
    host()
        .current_dir(dir)
        .arg("shape")
        .args(args)
        .output()
        .unwrap()
}

/// The tiny run's directory (kept for the process) and the image's name.
fn tiny_run() -> &'static (tempfile::TempDir, PathBuf) {
    static RUN: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    RUN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        draw(&dir.path().join("ell.png"), &L_SHAPE, false);
        let out = shape(
            dir.path(),
            &[
                "ell.png",
                "--out",
                "o",
                "--generations",
                "2",
                "--scale",
                "0.05",
            ],
        );
        succeeded(&out);
        (dir, PathBuf::from("o"))
    })
}

/// Fails with the command's stderr unless it succeeded.
fn succeeded(out: &std::process::Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn a_shape_drawn_dark_on_light_is_refused_naming_invert_and_runs_with_invert() {
    let dir = tempfile::tempdir().unwrap();
    draw(&dir.path().join("dark.png"), &L_SHAPE, true);
    let out = shape(
        dir.path(),
        &["dark.png", "--out", "o", "--generations", "1"],
    );
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("dark.png") && e.contains("dark on light") && e.contains("--invert"),
        "{e}"
    );
    let out = shape(
        dir.path(),
        &[
            "dark.png",
            "--invert",
            "--out",
            "o",
            "--generations",
            "1",
            "--scale",
            "0.01",
        ],
    );
    succeeded(&out);
    // the inverted image is the light-on-dark one, to within rounding
    let inverted = image::open(dir.path().join("o/dark.field.png"))
        .unwrap()
        .to_luma8();
    let light = dir.path().join("light.png");
    draw(&light, &L_SHAPE, false);
    assert_eq!(inverted, image::open(&light).unwrap().to_luma8());
    let report = json(&dir.path().join("o/dark.report.json"));
    assert!(report["pucks"].as_u64().unwrap() >= 6, "{report}");
}

#[test]
fn a_shape_too_small_for_six_pucks_is_refused_saying_so() {
    let dir = tempfile::tempdir().unwrap();
    draw(&dir.path().join("dot.png"), &[(30, 30, 33, 33)], false);
    let out = shape(dir.path(), &["dot.png", "--out", "o", "--generations", "1"]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("dot.png") && e.contains("fewer than the 6"),
        "{e}"
    );
    assert!(!dir.path().join("o/dot.policy").exists());
}

#[test]
fn a_tiny_run_writes_a_blob_flash_accepts_and_a_report_whose_result_host_run_reproduces() {
    let (dir, out) = tiny_run();
    let dir = dir.path();
    for file in ["ell.policy", "ell.report.md", "ell.png", "ell.search.json"] {
        assert!(dir.join(out).join(file).exists(), "{file} missing");
    }
    // from the checkout, as the firmware is built from its source
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let flash = host()
        .current_dir(&repo)
        .args(["flash", "--dry-run", "--policy"])
        .arg(dir.join(out).join("ell.policy"))
        .output()
        .unwrap();
    succeeded(&flash);
    let report = json(&dir.join(out).join("ell.report.json"));
    for key in ["pucks", "hasher", "seeds", "steps", "minutes"] {
        assert!(!report[key].is_null(), "{key} missing: {report}");
    }
    for controller in ["result", "oc", "general"] {
        for level in ["default", "2x"] {
            assert!(report[controller][level].is_f64(), "{controller} {level}");
        }
    }
    let (pucks, steps) = (report["pucks"].to_string(), report["steps"].to_string());
    let mut total = 0;
    for seed in report["seeds"].as_array().unwrap() {
        let run = host()
            .current_dir(dir)
            .args([
                "run",
                "--field",
                "ell.png",
                "--sensors",
                "robot",
                "--noise",
                "1",
            ])
            .args([
                "--pucks",
                &pucks,
                "--steps",
                &steps,
                "--seed",
                &seed.to_string(),
            ])
            .args(["--controller", "policy:o/ell.policy", "--json"])
            .output()
            .unwrap();
        succeeded(&run);
        let summary: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        total += summary["formations"].as_u64().unwrap();
    }
    let seeds = report["seeds"].as_array().unwrap().len() as f64;
    let per_million = total as f64 * 1e6 / (seeds * report["steps"].as_f64().unwrap());
    assert_eq!(report["result"]["default"].as_f64().unwrap(), per_million);
}

#[test]
fn the_cards_orbital_construction_is_what_host_run_gives_for_oc() {
    // the annulus, where OC forms within a tiny run's steps
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "annulus",
        "--out",
        "o",
        "--generations",
        "1",
        "--scale",
        "0.05",
    ];
    succeeded(&shape(dir.path(), &args));
    let report = json(&dir.path().join("o/annulus.report.json"));
    let (pucks, steps) = (report["pucks"].to_string(), report["steps"].to_string());
    let mut total = 0;
    for world in report["worlds"].as_array().unwrap() {
        if world["controller"] != "oc" {
            continue;
        }
        let run = host()
            .current_dir(dir.path())
            .args(["run", "--field", "annulus", "--sensors", "robot"])
            .args(["--noise", &world["noise"].to_string(), "--pucks", &pucks])
            .args(["--steps", &steps, "--seed", &world["seed"].to_string()])
            .args(["--controller", "oc", "--json"])
            .output()
            .unwrap();
        succeeded(&run);
        let summary: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        assert_eq!(summary["formations"], world["formations"], "{world}");
        total += summary["formations"].as_u64().unwrap();
    }
    assert!(total > 0, "OC forms on the annulus: {report}");
}

#[test]
fn the_result_never_forms_fewer_than_its_start_on_its_validation_worlds() {
    let (dir, out) = tiny_run();
    let log = json(&dir.path().join(out).join("ell.search.json"));
    let (start, result) = (&log["start_validation"], &log["result_validation"]);
    assert!(
        result["balance"].as_f64().unwrap() >= start["balance"].as_f64().unwrap(),
        "{start} -> {result}"
    );
    // the validation worlds are scored at the run's noise and twice it
    assert_eq!(log["search"]["also_noise"], serde_json::json!([2.0]));
    let validation = log["validation_seeds"].as_array().unwrap();
    let report = json(&dir.path().join(out).join("ell.report.json"));
    for seed in report["seeds"].as_array().unwrap() {
        assert!(
            !validation.contains(seed),
            "report seed {seed} validated on"
        );
        assert_eq!(seed.as_u64().unwrap() % 2, 1, "fitness seeds are even");
    }
}

#[test]
fn the_start_is_the_best_scoring_of_the_three_and_the_result_keeps_its_hasher() {
    let (dir, out) = tiny_run();
    let state = json(&dir.path().join(out).join("ell.shape.json"));
    let start = &state["start"];
    let key = |name: &str| {
        let s = &start[name];
        (
            s["balance"].as_f64().unwrap_or(f64::MIN),
            s["eval"].as_f64().unwrap_or(f64::MIN),
        )
    };
    let chosen = start["chosen"].as_str().unwrap();
    let field = chosen.replace('-', "_");
    for other in ["general", "oc", "oc_role"] {
        assert!(key(&field) >= key(other), "{start}");
    }
    let hasher = if chosen == "oc-role" {
        "original-role"
    } else {
        "original"
    };
    assert_eq!(start["hasher"], hasher);
    let card = json(&dir.path().join(out).join("ell.report.json"));
    assert_eq!(card["hasher"], hasher);
}

#[test]
fn a_run_killed_mid_search_and_run_again_ends_with_the_table_of_an_unbroken_run() {
    let args = [
        "ell.png",
        "--out",
        "o",
        "--generations",
        "4",
        "--scale",
        "0.02",
    ];
    let unbroken = tempfile::tempdir().unwrap();
    draw(&unbroken.path().join("ell.png"), &L_SHAPE, false);
    assert!(shape(unbroken.path(), &args).status.success());
    let broken = tempfile::tempdir().unwrap();
    draw(&broken.path().join("ell.png"), &L_SHAPE, false);
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("host"))
        .current_dir(broken.path())
        .arg("shape")
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let state = broken.path().join("o/ell.shape.json");
    let finished = |p: &Path| -> usize {
        std::fs::read(p)
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
            .map_or(0, |s| s["generations"].as_array().map_or(0, Vec::len))
    };
    while finished(&state) == 0 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before a generation"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let at_kill = finished(&state);
    assert!(
        (1..4).contains(&at_kill),
        "killed after {at_kill} generations"
    );
    assert!(!broken.path().join("o/ell.policy").exists());
    let resumed = shape(broken.path(), &args);
    assert!(resumed.status.success());
    let said = String::from_utf8_lossy(&resumed.stdout);
    assert!(
        said.contains(&format!("resumed after {at_kill} generations")),
        "{said}"
    );
    let table = |d: &Path| std::fs::read(d.join("o/ell.policy")).unwrap();
    assert_eq!(table(broken.path()), table(unbroken.path()));
    assert_eq!(finished(&state), 4);
}

#[test]
fn host_train_ends_by_saying_what_it_trained_for_and_pointing_to_host_shape() {
    let dir = tempfile::tempdir().unwrap();
    let out = host()
        .current_dir(dir.path())
        .args(["train", "--steps", "2000", "--out", "t"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let line = |start: &str| {
        text.lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no {start} line in:\n{text}"))
            .to_string()
    };
    assert!(
        line("trained for").ends_with("annulus, sensors disc, arena thesis"),
        "{text}"
    );
    assert!(line("for the robot").contains("host shape IMAGE"), "{text}");
}
