//! `host field export` and `host display`, the page checked in a real
//! headless browser (Debian's `chromium`, which `scripts/setup` installs):
//! what it shows at panel size is the exported image pixel for pixel, the
//! calibration sequence shows white, black and the field in that order for
//! the hold each, timed by the browser's virtual time (no wall-clock
//! sleeps), the grey patches show their levels, a measured gain evens out
//! the white and the field as exported, and the marks leave the robot's
//! sensors on white.

#[path = "../../view/tests/browser/mod.rs"]
mod browser;

use browser::chromium;
use image::RgbImage;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// A small screen (a 16:9 panel of 640 x 360 pixels) whose display's gamma
/// is not the light curve's, so the export pre-compensates.
const SMALL_ARENA: &str = "name = \"small\"\nscreen_px = [640, 360]\ndisplay_gamma = 1.8\n";

/// Writes [`SMALL_ARENA`] into `dir`; its path.
fn small_arena(dir: &Path) -> String {
    let path = dir.join("small.toml");
    std::fs::write(&path, SMALL_ARENA).unwrap();
    path.to_str().unwrap().to_string()
}

/// A running `host display`, stopped when dropped.
struct Display {
    child: Child,
    url: String,
    /// Kept open: the server's later lines must not meet a closed pipe.
    _stdout: BufReader<ChildStdout>,
}

impl Drop for Display {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `host display` on any free port with `args`; its first line names the address.
fn display(args: &[&str]) -> Display {
    let mut child = Command::new(HOST)
        .args(["display", "--port", "0"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("cannot start host display");
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    let url = first
        .trim()
        .strip_prefix("display: serving ")
        .unwrap_or_else(|| panic!("first line: {first:?}"));
    Display {
        url: url.to_string(),
        child,
        _stdout: stdout,
    }
}

/// What to take from the page once `budget_ms` of virtual time have passed.
enum Take<'a> {
    Screenshot(&'a Path),
    Dom,
}

/// Loads `url` in a fresh headless Chromium with a `width` x `height`
/// viewport, lets `budget_ms` of virtual time pass (the page's timers run
/// on it, without waiting in real time) and takes a screenshot or the DOM.
fn browse(url: &str, (width, height): (u32, u32), budget_ms: u32, take: Take) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut command = Command::new(chromium());
    command.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        "--force-device-scale-factor=1",
        "--force-color-profile=srgb",
    ]);
    command.arg(format!("--user-data-dir={}", profile.path().display()));
    command.arg(format!("--window-size={width},{height}"));
    command.arg(format!("--virtual-time-budget={budget_ms}"));
    match take {
        Take::Screenshot(path) => command.arg(format!("--screenshot={}", path.display())),
        Take::Dom => command.arg("--dump-dom"),
    };
    let mut child = command
        .arg(url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start chromium");
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    // A guard against a browser that hangs, not a measurement.
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "chromium failed on {url}: {status}");
            return out;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("chromium did not finish {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn screenshot(url: &str, size: (u32, u32), budget_ms: u32) -> RgbImage {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shot.png");
    browse(url, size, budget_ms, Take::Screenshot(&path));
    let shot = image::open(&path).unwrap().into_rgb8();
    assert_eq!(
        shot.dimensions(),
        size,
        "the screenshot is not the panel's size"
    );
    shot
}

/// The page's reported state: an attribute of its `<html>` element.
fn attribute(dom: &str, name: &str) -> Option<String> {
    let html = &dom[dom.find("<html")?..];
    let tag = &html[..html.find('>')?];
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(tag[start..start + tag[start..].find('"')?].to_string())
}

/// Writes the panel image with `host field export` and reads it as RGB.
fn export(dir: &Path, args: &[&str]) -> RgbImage {
    let out = dir.join("panel.png");
    let status = Command::new(HOST)
        .args(["field", "export", "--out"])
        .arg(&out)
        .args(args)
        .status()
        .unwrap();
    assert!(status.success(), "host field export {args:?}");
    image::open(&out).unwrap().into_rgb8()
}

/// Pixels where two images differ, and the first of them.
fn differences(a: &RgbImage, b: &RgbImage) -> (usize, Option<(u32, u32)>) {
    let mut first = None;
    let mut count = 0;
    for (x, y, p) in a.enumerate_pixels() {
        if p != b.get_pixel(x, y) {
            count += 1;
            first = first.or(Some((x, y)));
        }
    }
    (count, first)
}

fn assert_same(shot: &RgbImage, expected: &RgbImage, what: &str) {
    let (count, first) = differences(shot, expected);
    assert_eq!(
        count, 0,
        "{what}: {count} pixels differ, the first at {first:?}"
    );
}

fn uniform(img: &RgbImage, level: u8) -> bool {
    img.pixels().all(|p| p.0 == [level; 3])
}

#[test]
fn the_page_at_the_tvs_panel_size_shows_the_exported_image_pixel_for_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let expected = export(dir.path(), &["--arena", "tv75", "--field", "annulus"]);
    assert_eq!(expected.dimensions(), (3840, 2160));
    let server = display(&["--arena", "tv75", "--field", "annulus"]);
    let shot = screenshot(&format!("{}?mode=field", server.url), (3840, 2160), 500);
    assert_same(&shot, &expected, "tv75, annulus");
}

#[test]
fn a_pre_compensated_letter_on_a_small_screen_is_shown_pixel_for_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let arena = &small_arena(dir.path());
    let expected = export(dir.path(), &["--arena", arena, "--field", "letter:T"]);
    assert_eq!(expected.dimensions(), (640, 360));
    // Pre-compensated for gamma 1.8: the field's full value is white, its
    // middle values brighter than 255 v (v^(2.2 / 1.8) > v).
    assert!(expected.pixels().any(|p| p.0 == [255; 3]) && expected.pixels().any(|p| p.0 == [0; 3]));
    let server = display(&["--arena", arena, "--field", "letter:T"]);
    assert_same(
        &screenshot(&server.url, (640, 360), 500),
        &expected,
        "small, letter:T",
    );
}

#[test]
fn the_calibration_sequence_holds_white_then_black_then_shows_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let arena = &small_arena(dir.path());
    let field = export(dir.path(), &["--arena", arena, "--field", "annulus"]);
    let server = display(&["--arena", arena, "--field", "annulus", "--hold", "1.5"]);
    let url = format!("{}?mode=calibrate", server.url);

    // The page's own record, in virtual time: each screen and when it began.
    let dom = browse(&url, (640, 360), 6000, Take::Dom);
    assert_eq!(
        attribute(&dom, "data-ready").as_deref(),
        Some("true"),
        "{dom}"
    );
    let log = attribute(&dom, "data-log").expect("the page reports its screens");
    let screens: Vec<(&str, f64)> = log
        .split(' ')
        .map(|e| {
            let (screen, at) = e.split_once('@').unwrap();
            (screen, at.parse().unwrap())
        })
        .collect();
    assert_eq!(
        screens.iter().map(|s| s.0).collect::<Vec<_>>(),
        ["white", "black", "field"],
        "{log}"
    );
    let (white, black) = (screens[1].1 - screens[0].1, screens[2].1 - screens[1].1);
    // The page times both switches from the sequence's start; its clock
    // reads to a tenth of a millisecond, so a hold may read 0.1 ms short.
    for (name, held) in [("white", white), ("black", black)] {
        assert!(
            (1499.5..1520.0).contains(&held),
            "{name} held {held} ms, not the 1.5 s asked: {log}"
        );
    }
    assert!(
        screens[0].1 < 1.0,
        "white did not start the sequence: {log}"
    );

    // What the browser shows mid-way through each screen.
    assert!(uniform(&screenshot(&url, (640, 360), 700), 255), "white");
    assert!(uniform(&screenshot(&url, (640, 360), 2200), 0), "black");
    assert_same(
        &screenshot(&url, (640, 360), 3800),
        &field,
        "the field after the sequence",
    );
}

#[test]
fn grey_patches_show_their_levels_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let server = display(&["--arena", &small_arena(dir.path())]);
    let patches = screenshot(&format!("{}?mode=grey", server.url), (640, 360), 500);
    let levels = [0, 32, 64, 96, 128, 160, 192, 224, 255];
    for (k, level) in levels.into_iter().enumerate() {
        // The middle of patch k of a 3 x 3 grid, row by row.
        let (x, y) = (
            (k % 3) as u32 * 640 / 3 + 107,
            (k / 3) as u32 * 360 / 3 + 60,
        );
        assert_eq!(
            patches.get_pixel(x, y).0,
            [level; 3],
            "patch {k} at ({x}, {y})"
        );
    }
    let one = screenshot(
        &format!("{}?mode=grey&level=77", server.url),
        (640, 360),
        500,
    );
    assert!(uniform(&one, 77), "level 77 full-screen");
}

/// A measured gain (`host field gain`'s file): the top-left point 10 %
/// dimmer than the rest.
fn gain_file(dir: &Path) -> String {
    let path = dir.join("gain.toml");
    let mut gains = ["1.0"; 12];
    gains[0] = "0.9";
    let text = format!("columns = 4\nrows = 3\ngains = [{}]\n", gains.join(", "));
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn with_a_measured_gain_the_calibrations_white_and_the_field_are_evened_out_as_exported() {
    let dir = tempfile::tempdir().unwrap();
    let (arena, gain) = (&small_arena(dir.path()), &gain_file(dir.path()));
    let white = export(dir.path(), &["--arena", arena, "--white", "--gain", gain]);
    // dimmer wherever the panel is brighter than its dimmest point
    assert_eq!(white.get_pixel(0, 0).0, [255; 3]);
    assert!(white.get_pixel(639, 359).0[0] < 255);
    let field = export(
        dir.path(),
        &["--arena", arena, "--field", "annulus", "--gain", gain],
    );
    let plain = export(dir.path(), &["--arena", arena, "--field", "annulus"]);
    assert!(differences(&field, &plain).0 > 0);
    let server = display(&[
        "--arena", arena, "--field", "annulus", "--hold", "1.5", "--gain", gain,
    ]);
    let url = format!("{}?mode=calibrate", server.url);
    assert_same(
        &screenshot(&url, (640, 360), 700),
        &white,
        "white, evened out",
    );
    assert!(uniform(&screenshot(&url, (640, 360), 2200), 0), "black");
    assert_same(
        &screenshot(&url, (640, 360), 3800),
        &field,
        "the field, evened out",
    );
}

#[test]
fn the_marks_screen_is_white_where_the_robots_sensors_stand_with_a_cross_under_its_centre() {
    let dir = tempfile::tempdir().unwrap();
    // tv75's 1,650 x 928 mm on 640 x 360 pixels: 0.388 pixels per mm
    let server = display(&["--arena", &small_arena(dir.path()), "--marks", "4x3"]);
    let shot = screenshot(&format!("{}?mode=marks", server.url), (640, 360), 500);
    let px_per_mm = 640.0 / 1650.0;
    for k in 0..12 {
        let (x, y) = ((k % 4) as f64 * 160.0 + 80.0, (k / 4) as f64 * 120.0 + 60.0);
        let at = |dx_mm: f64, dy_mm: f64| {
            shot.get_pixel(
                (x + dx_mm * px_per_mm) as u32,
                (y + dy_mm * px_per_mm) as u32,
            )
            .0
        };
        assert!(
            at(0.0, 0.0)[0] < 200,
            "mark {}: no cross at its centre",
            k + 1
        );
        // the sensors of a robot facing the top: left and right 45
        // degrees off its heading on its 65 mm back, mid 80 mm ahead
        for (dx, dy) in [(-46.0, -46.0), (46.0, -46.0), (0.0, -80.0)] {
            assert_eq!(
                at(dx, dy),
                [255; 3],
                "mark {}: a sensor's place at ({dx}, {dy}) mm",
                k + 1
            );
        }
    }
}

/// One raw HTTP/1.0 request; the status code and body.
fn request(url: &str, method: &str, path: &str) -> (u16, Vec<u8>) {
    let address = url.trim_start_matches("http://").trim_end_matches('/');
    let mut stream = TcpStream::connect(address).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.0\r\nHost: {address}\r\n\r\n"
    )
    .unwrap();
    let mut reply = Vec::new();
    stream.read_to_end(&mut reply).unwrap();
    let split = reply
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("headers end");
    let head = String::from_utf8_lossy(&reply[..split]).to_string();
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{head}"));
    (status, reply[split + 4..].to_vec())
}

#[test]
fn the_server_listens_on_loopback_and_serves_only_its_page_and_images() {
    let dir = tempfile::tempdir().unwrap();
    let arena = &small_arena(dir.path());
    let server = display(&["--arena", arena, "--field", "letter:L"]);
    assert!(
        server.url.starts_with("http://127.0.0.1:"),
        "{}",
        server.url
    );
    let (status, page) = request(&server.url, "GET", "/");
    assert_eq!(status, 200);
    let page = String::from_utf8(page).unwrap();
    let loads_elsewhere =
        page.contains("src=\"http") || page.contains("href=\"http") || page.contains("//cdn");
    assert!(
        page.contains("<script>") && !loads_elsewhere,
        "the page loads nothing from elsewhere"
    );
    let (status, png) = request(&server.url, "GET", "/field.png");
    assert_eq!(status, 200);
    let exported = export(dir.path(), &["--arena", arena, "--field", "letter:L"]);
    assert_eq!(image::load_from_memory(&png).unwrap().into_rgb8(), exported);
    let (status, settings) = request(&server.url, "GET", "/settings.json?x=1");
    assert_eq!(status, 200);
    let settings: serde_json::Value = serde_json::from_slice(&settings).unwrap();
    assert_eq!(
        (settings["panel"][0].as_u64(), settings["hold_ms"].as_u64()),
        (Some(640), Some(3000))
    );
    for path in [
        "/../Cargo.toml",
        "/etc/passwd",
        "/field.png.bak",
        "/display.html",
    ] {
        assert_eq!(request(&server.url, "GET", path).0, 404, "{path}");
    }
    assert_eq!(request(&server.url, "POST", "/").0, 405);
}

#[test]
fn bad_settings_are_refused_naming_the_input() {
    let fails = |args: &[&str]| {
        let out = Command::new(HOST).args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(&["display", "--hold", "0.1", "--port", "0"]);
    assert!(e.contains("--hold 0.1 s") && e.contains("140 ms"), "{e}");
    // the value as given, not as milliseconds clamped to 32 bits
    let e = fails(&["display", "--hold", "1e9", "--port", "0"]);
    assert!(e.contains("--hold 1e9 s: outside"), "{e}");
    let e = fails(&["display", "--arena", "thesis", "--port", "0"]);
    assert!(
        e.contains("--arena thesis") && e.contains("screen arena"),
        "{e}"
    );
    let e = fails(&["display", "--bind", "localhost:x"]);
    assert!(e.contains("localhost:x"), "{e}");
    let e = fails(&[
        "field",
        "export",
        "--field",
        "/no/such.png",
        "--out",
        "/tmp/never-written.png",
    ]);
    assert!(e.contains("/no/such.png"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "screen_px = [0, 10]\n").unwrap();
    let e = fails(&[
        "field",
        "export",
        "--arena",
        bad.to_str().unwrap(),
        "--out",
        "/tmp/never-written.png",
    ]);
    assert!(e.contains("bad.toml") && e.contains("screen_px[0]"), "{e}");
}
