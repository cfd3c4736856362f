//! The live view's page in headless Chromium at 1,280 and 1,920 pixels
//! wide: `host view` (controls shown) and `host train --view` (the world
//! it learns in and, in a frame beside it, the exported policy acting;
//! neither takes controls, so neither shows any, from the first moment):
//! no label, button, choice or heading is cut or runs past the window's
//! edge, and a screenshot of each width shows the world painted.

#[path = "../../view/tests/browser/mod.rs"]
mod browser;
mod served;

use browser::{chromium, Browser};
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// The widths checked, each with a window height of its usual screen.
const WINDOWS: [(u32, u32); 2] = [(1280, 800), (1920, 1080)];

/// What is cut or outside the window among the panel's labels, buttons,
/// choices, inputs, table cells and headings that are shown (an empty
/// list when nothing is): a box narrower than its content, or a choice or
/// file input narrower than the browser makes it when left to fit its
/// content (its widest option; its button and text).
const CUT: &str = r##"(() => {
  const cut = [];
  const right = document.documentElement.clientWidth;
  const natural = (e) => {
    const c = e.cloneNode(true);
    c.style.width = "auto";
    c.style.position = "absolute";
    document.body.append(c);
    const width = c.getBoundingClientRect().width;
    c.remove();
    return width;
  };
  for (const e of document.querySelectorAll("#panel label, #panel button, #panel select, #panel input, #panel h2, #panel td, #beside h2")) {
    if (e.offsetParent === null) continue;
    const name = e.id || e.textContent.trim().slice(0, 40) || e.tagName;
    const box = e.getBoundingClientRect();
    if (box.right > right + 0.5) cut.push(name + ": past the window's right edge");
    if (["LABEL", "BUTTON", "TD", "H2"].includes(e.tagName) && e.scrollWidth > e.clientWidth + 1) cut.push(name + ": content wider than its box");
    if ((e.tagName === "SELECT" || e.type === "file") && natural(e) > box.width + 0.5) cut.push(name + ": narrower than its content");
  }
  return cut;
})()"##;

/// The controls shown (buttons and the settings form).
const CONTROLS_SHOWN: &str =
    "[...document.querySelectorAll('.controls')].filter((e) => e.offsetParent !== null).length";

/// A screenshot of `url` in a `width` x `height` window after `budget_ms`
/// of the browser's virtual time.
fn screenshot(url: &str, (width, height): (u32, u32), budget_ms: u32) -> image::RgbImage {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shot.png");
    let status = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--hide-scrollbars",
            "--force-device-scale-factor=1",
        ])
        .arg(format!(
            "--user-data-dir={}",
            dir.path().join("profile").display()
        ))
        .arg(format!("--window-size={width},{height}"))
        .arg(format!("--virtual-time-budget={budget_ms}"))
        .arg(format!("--screenshot={}", path.display()))
        .arg(url)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("cannot start chromium");
    assert!(status.success(), "chromium failed on {url}");
    image::open(&path).unwrap().into_rgb8()
}

/// Whether the world is painted: the screenshot's top-left `width` x
/// `height` pixels (the canvas, past its 8-pixel margin) show a robot's
/// blue.
fn painted(shot: &image::RgbImage, (width, height): (u32, u32)) -> bool {
    let robot = image::Rgb([0, 100, 200]);
    (8..(8 + height).min(shot.height()))
        .flat_map(|y| (8..(8 + width).min(shot.width())).map(move |x| (x, y)))
        .any(|(x, y)| shot.get_pixel(x, y) == &robot)
}

/// The world canvas's width and height on `page`.
fn canvas(page: &mut Browser) -> (u32, u32) {
    let size = page
        .eval("[document.getElementById('world').width, document.getElementById('world').height]");
    let side = |i: usize| size[i].as_u64().unwrap() as u32;
    (side(0), side(1))
}

fn assert_nothing_cut(page: &mut Browser, what: &str) {
    let cut = page.eval(CUT);
    assert_eq!(cut, serde_json::json!([]), "{what}: cut or outside: {cut}");
}

#[test]
fn the_live_view_lays_out_without_cut_labels_at_both_widths() {
    // the shipped policies offered, the longest names among them
    let policies = concat!(env!("CARGO_MANIFEST_DIR"), "/../policies");
    let server = served::serve(["--paused", "--policies", policies]);
    let url = format!("http://{}/", server.address);
    for window in WINDOWS {
        let mut page = Browser::open(&url, window);
        page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
        let what = format!("host view at {} x {}", window.0, window.1);
        assert_nothing_cut(&mut page, &what);
        assert_eq!(
            page.eval(CONTROLS_SHOWN),
            serde_json::json!(4),
            "{what}: its controls"
        );
        let size = canvas(&mut page);
        assert!(
            painted(&screenshot(&url, window, 3000), size),
            "{what}: the screenshot shows no world"
        );
    }
}

/// `host train --view` on a free port for a long run; the learning
/// world's address. Killed when the test ends.
struct Training(Child);

impl Drop for Training {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn a_training_view_and_its_companion_show_no_controls_and_no_cut_labels() {
    let out = tempfile::tempdir().unwrap();
    let mut child = Command::new(HOST)
        .args(["train", "--view", "127.0.0.1:0", "--steps", "100000000"])
        .args(["--robots", "4", "--pucks", "60", "--out"])
        .arg(out.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start host train --view");
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let first = lines.next().unwrap().unwrap();
    std::thread::spawn(move || lines.for_each(drop));
    let _training = Training(child);
    let urls: Vec<String> = first
        .split("http://")
        .skip(1)
        .map(|s| format!("http://{}/", s.split('/').next().unwrap()))
        .collect();
    assert_eq!(urls.len(), 2, "{first}");

    for window in WINDOWS {
        let what = format!("host train --view at {} x {}", window.0, window.1);
        let mut page = Browser::open(&urls[0], window);
        // from the first moment: no controls before the server has spoken
        page.wait_for("document.readyState !== 'loading'", 60);
        assert_eq!(page.eval(CONTROLS_SHOWN), serde_json::json!(0), "{what}");
        page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
        assert_eq!(page.eval(CONTROLS_SHOWN), serde_json::json!(0), "{what}");
        assert_nothing_cut(&mut page, &what);
        // the companion's page (another origin) at its frame's size
        page.wait_for("!document.getElementById('beside').hidden", 60);
        let frame = page.eval(
            "(() => { const f = document.getElementById('companion'); return [f.clientWidth, f.clientHeight]; })()",
        );
        let size = |i: usize| frame[i].as_u64().unwrap() as u32;
        let (w, h) = (size(0), size(1));
        assert!(w >= 300, "{what}: the companion's frame is {w} px wide");
        let mut companion = Browser::open(&urls[1], (w, h));
        companion.wait_for("document.documentElement.dataset.ready === 'true'", 60);
        let inside = format!("{what}, its companion at {w} x {h}");
        assert_eq!(
            companion.eval(CONTROLS_SHOWN),
            serde_json::json!(0),
            "{inside}"
        );
        assert_nothing_cut(&mut companion, &inside);
        let start = Instant::now();
        let size = canvas(&mut page);
        assert!(
            painted(&screenshot(&urls[0], window, 3000), size),
            "{what}: the screenshot shows no world"
        );
        assert!(start.elapsed() < Duration::from_secs(120));
    }
}
