//! `host field gain`: a robot's logs at the display's marks, as the
//! firmware would write them over a panel of known gain, give that gain
//! back; logs that cannot give it are refused, naming the log and why.

use assert_cmd::Command;
use shared::calibration::RC_TICK_US;
use shared::{Faults, FieldCalibration, LogFrame, RunMode};
use sim::base::gain_grid::GainGrid;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::flat_field::Stance;
use sim::sensors::photo::PhotoSensorConfig;
use std::path::{Path, PathBuf};

/// Control periods logged per mark.
const FRAMES: usize = 100;

/// A panel dimmer towards its right and bottom, 0.85 to 1 of full white.
fn panel() -> GainGrid {
    GainGrid {
        columns: 4,
        rows: 3,
        gains: (0..12)
            .map(|k| 1.0 - 0.03 * (k % 4) as f64 - 0.02 * (k / 4) as f64)
            .collect(),
    }
}

/// The calibration the robot stores: the model's sensors on full white
/// and black.
fn calibration() -> FieldCalibration {
    let photo = PhotoSensorConfig::default();
    let ticks = |us: f64| ((us + photo.poll_latency_us) / f64::from(RC_TICK_US)) as u16;
    FieldCalibration {
        ranges: photo.response.map(|r| shared::SensorRange {
            bright: ticks(r.bright_us),
            dark: ticks(r.dark_us),
        }),
    }
}

/// A raw capture of the robot standing in mark `k` on full white over
/// [`panel`]: its idle frames' ticks dithered over one tick (as the RC
/// jitter does), a calibration every 50 frames, and a few driving frames
/// that must not count.
fn mark_log(dir: &Path, k: usize, faults: Faults) -> PathBuf {
    let (arena, photo) = (ArenaSpec::tv75(), PhotoSensorConfig::default());
    let stance = Stance::of(&arena, &photo);
    let (panel, size) = (panel(), arena.size());
    let centre = panel.point(k, size);
    let mut bytes = vec![];
    for n in 0..FRAMES + 5 {
        let driving = n >= FRAMES;
        let dither = (n as f64 + 0.5) / FRAMES as f64 - 0.5;
        let raw_times = std::array::from_fn(|i| {
            let gain = panel.at(centre + stance.sensor_offsets[i], size);
            let value = gain.powf(1.0 / f64::from(shared::calibration::LIGHT_GAMMA));
            let us = photo.response[i].discharge_us(value, photo.gamma);
            let ticks = (us + photo.poll_latency_us) / f64::from(RC_TICK_US) + dither;
            if driving {
                ticks as u16 / 2
            } else {
                ticks as u16
            }
        });
        let frame = LogFrame {
            tick: n as u32,
            mode: if driving {
                RunMode::Driving
            } else {
                RunMode::Idle
            },
            faults,
            raw_times,
            calibration: (n % 50 == 0).then(calibration),
            ..LogFrame::default()
        };
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let len = frame.encode(&mut buf);
        bytes.extend_from_slice(&buf[..len]);
    }
    let path = dir.join(format!("mark-{:02}.bin", k + 1));
    std::fs::write(&path, bytes).unwrap();
    path
}

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

#[test]
fn logs_at_every_mark_give_the_panels_gain_back_within_a_third_of_a_percent() {
    let dir = tempfile::tempdir().unwrap();
    let logs: Vec<PathBuf> = (0..12)
        .map(|k| mark_log(dir.path(), k, Faults::default()))
        .collect();
    let out = dir.path().join("gain.toml");
    let assert = host()
        .args(["field", "gain", "--out"])
        .arg(&out)
        .args(&logs)
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    assert!(stdout.contains("at 4x3 marks"), "{stdout}");
    let fitted = host::flat_field::read(&out).unwrap();
    let truth = panel();
    let mean = truth.gains.iter().sum::<f64>() / 12.0;
    for (k, (f, t)) in fitted.gains.iter().zip(&truth.gains).enumerate() {
        assert!(
            (f - t / mean).abs() < 0.003,
            "mark {}: {f} for {}",
            k + 1,
            t / mean
        );
    }
    // the file is what the display reads: it evens out the export
    let png = dir.path().join("white.png");
    host()
        .args(["field", "export", "--white", "--gain"])
        .arg(&out)
        .arg("--out")
        .arg(&png)
        .assert()
        .success();
    let white = image::open(&png).unwrap().into_luma8();
    let (w, h) = white.dimensions();
    // brightest at the top-left, where the panel is brightest
    assert!(white.get_pixel(0, 0)[0] < white.get_pixel(w - 1, h - 1)[0]);
    assert_eq!(white.get_pixel(w - 1, h - 1)[0], 255);
}

#[test]
fn missing_marks_an_uncalibrated_robot_and_a_bad_gain_file_are_refused_naming_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gain.toml");
    let logs: Vec<PathBuf> = (0..11)
        .map(|k| mark_log(dir.path(), k, Faults::default()))
        .collect();
    let stderr = |args: &[&std::ffi::OsStr]| {
        let assert = host().args(args).assert().failure();
        String::from_utf8_lossy(&assert.get_output().stderr).to_string()
    };
    let mut args: Vec<&std::ffi::OsStr> = ["field", "gain", "--out"]
        .iter()
        .map(std::ffi::OsStr::new)
        .collect();
    args.push(out.as_os_str());
    let mut eleven = args.clone();
    eleven.extend(logs.iter().map(|p| p.as_os_str()));
    let e = stderr(&eleven);
    assert!(e.contains("11 logs given, the 4x3 marks need 12"), "{e}");

    let uncalibrated = mark_log(dir.path(), 11, Faults::NO_CALIBRATION);
    let mut twelve = eleven.clone();
    twelve.push(uncalibrated.as_os_str());
    let e = stderr(&twelve);
    assert!(
        e.contains("mark-12.bin (mark 12): the robot has no calibration"),
        "{e}"
    );
    assert!(!out.exists(), "nothing written");

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "columns = 4\nrows = 3\ngains = [1.0, 0.0]\n").unwrap();
    let png = dir.path().join("x.png");
    let e = stderr(&[
        "field".as_ref(),
        "export".as_ref(),
        "--gain".as_ref(),
        bad.as_os_str(),
        "--out".as_ref(),
        png.as_os_str(),
    ]);
    assert!(e.contains("bad.toml") && e.contains("2 gains given"), "{e}");
    let e = stderr(&[
        "field".as_ref(),
        "gain".as_ref(),
        "--marks".as_ref(),
        "4x1".as_ref(),
    ]);
    assert!(
        e.contains("gain.rows = 1: outside its plausible range [2, 32]"),
        "{e}"
    );
}
