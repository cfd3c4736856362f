//! `host render`: with `--band` the pucks in the target band are drawn in
//! their own colour; it prints what it wrote with the step, Eval and the
//! formations; `--until-formed` draws the world as the shape forms.

use std::path::Path;
use std::process::Command;

const HOST: &str = env!("CARGO_BIN_EXE_host");

fn render(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(HOST)
        .current_dir(dir)
        .arg("render")
        .args(args)
        .output()
        .expect("cannot run host");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn count(png: &Path, colour: image::Rgb<u8>) -> usize {
    let img = image::open(png).unwrap().into_rgb8();
    img.pixels().filter(|p| **p == colour).count()
}

#[test]
fn the_band_draws_the_pucks_in_it_apart_from_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let steps = ["--steps", "20000", "--size", "400"];
    let text = render(d, &[&steps[..], &["--band", "--out", "band.png"]].concat());
    assert!(text.contains("the pucks in it green"), "{text}");
    render(d, &[&steps[..], &["--out", "plain.png"]].concat());
    let (in_band, out_of_band) = (sim::render::PUCK_IN_BAND, sim::render::PUCK);
    let band = d.join("band.png");
    assert!(count(&band, in_band) > 0, "no puck drawn as in the band");
    assert!(
        count(&band, out_of_band) > 0,
        "every puck drawn as in the band"
    );
    let plain = d.join("plain.png");
    assert_eq!(
        count(&plain, in_band),
        0,
        "without --band pucks are all red"
    );
}

#[test]
fn render_prints_the_file_the_step_eval_and_formations() {
    let dir = tempfile::tempdir().unwrap();
    let text = render(
        dir.path(),
        &["--steps", "3000", "--size", "100", "--out", "w.png"],
    );
    assert!(
        text.starts_with("wrote w.png (100 x 100): step 3000, Eval 0."),
        "{text}"
    );
    assert!(text.contains("formations so far 0"), "{text}");
    let gif = render(
        dir.path(),
        &["--steps", "300", "--size", "100", "--gif", "a.gif"],
    );
    assert!(
        gif.starts_with("wrote a.gif (101 frames, one every 3 steps): at the end step 300"),
        "{gif}"
    );
}

#[test]
fn until_formed_draws_the_moment_the_shape_forms_or_says_it_never_did() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // orbital construction forms the annulus about 10,000 steps in
    let text = render(
        d,
        &[
            "--until-formed",
            "--band",
            "--size",
            "200",
            "--out",
            "f.png",
        ],
    );
    assert!(text.contains("the shape formed at step"), "{text}");
    assert!(text.contains("formations so far 1"), "{text}");
    let eval: f64 = text
        .split("Eval ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no Eval in {text}"));
    let threshold = sim::config::EpisodeConfig::default().success_eval;
    assert!(
        eval > threshold,
        "the world drawn has Eval {eval}, not above the success threshold {threshold}: not the formed one"
    );
    let never = render(
        d,
        &[
            "--until-formed",
            "--steps",
            "500",
            "--size",
            "100",
            "--out",
            "n.png",
        ],
    );
    assert!(
        never.contains("no formation in 500 steps; the world at the end"),
        "{never}"
    );
}
