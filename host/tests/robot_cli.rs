//! The robot commands of the `host` CLI: replay (text and JSON, damaged
//! input), a log on the view's page (`host view --log`), flash --dry-run,
//! and their errors naming the bad input.

use assert_cmd::Command;
use host::robot::log_file::{encode_record, MAGIC, VERSION};
use shared::{FieldCalibration, LogFrame, PolicyBlob, RunMode, SensorRange};
use std::ffi::OsString;
use std::path::{Path, PathBuf};

mod served;

const CAL: FieldCalibration = FieldCalibration {
    ranges: [SensorRange {
        bright: 40,
        dark: 440,
    }; 3],
};

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .unwrap()
}

fn policy_path() -> PathBuf {
    repo().join("policies/oc-heuristic.policy")
}

/// Idle frames as the firmware logs them (no motors), the first with the
/// calibration; one record damaged on disk.
fn write_log(path: &Path) -> u64 {
    let blob = PolicyBlob::decode(&std::fs::read(policy_path()).unwrap()).unwrap();
    let mut bytes = MAGIC.to_vec();
    bytes.push(VERSION);
    let mut damaged_at = 0;
    for tick in 1..=5u32 {
        let raw = [100 + tick as u16 * 50, 240, 300];
        let values = CAL.scales().values(&raw);
        let reading = shared::SensorReading {
            left: values[0],
            mid: values[1],
            right: values[2],
            ..Default::default()
        };
        let state = blob.hasher().hash(&reading);
        let frame = LogFrame {
            tick,
            mode: RunMode::Idle,
            raw_times: raw,
            values,
            state,
            action: blob.table().action(state),
            calibration: (tick == 1).then_some(CAL),
            ..LogFrame::default()
        };
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = frame.encode(&mut buf);
        let mut record = encode_record(u64::from(tick) * 20_000, &buf[..n - 1]);
        if tick == 3 {
            damaged_at = bytes.len() as u64;
            record[10] = record[10].wrapping_add(1).max(1); // damaged, never a new delimiter
        }
        bytes.extend(record);
    }
    std::fs::write(path, bytes).unwrap();
    damaged_at
}

/// `host replay --json` of `log` against the policy.
fn replay_json(log: &Path) -> serde_json::Value {
    let out = host()
        .args(["replay", "--json", "--log"])
        .arg(log)
        .arg("--policy")
        .arg(policy_path())
        .output()
        .unwrap();
    assert!(out.status.success());
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn replay_reports_in_text_and_json_and_names_damaged_records() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.log");
    let damaged_at = write_log(&log);
    let out = host()
        .args(["replay", "--log"])
        .arg(&log)
        .arg("--policy")
        .arg(policy_path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("5 entries, 4 frames decoded"), "{text}");
    assert!(
        text.contains(&format!("at byte {damaged_at}")) && text.contains("divergences: 0 frames"),
        "{text}"
    );

    let v = replay_json(&log);
    assert_eq!(
        (
            v["frames"].as_u64(),
            v["damaged"].as_u64(),
            v["diverged"].as_u64()
        ),
        (Some(4), Some(1), Some(0))
    );
    assert_eq!(v["first_damaged"][0]["offset"].as_u64(), Some(damaged_at));
    assert_eq!(v["modes"]["idle"].as_u64(), Some(4));
    assert_eq!(v["calibration_checked"].as_u64(), Some(4));
}

/// Driving frames of robot `id`, its tracks `counts` per period, as raw capture bytes.
fn driving_capture(id: u8, motors: shared::MotorCommand, counts: [i16; 2]) -> Vec<u8> {
    let blob = PolicyBlob::decode(&std::fs::read(policy_path()).unwrap()).unwrap();
    let mut bytes = Vec::new();
    for tick in 1..=20u32 {
        let values = CAL.scales().values(&[240; 3]);
        let reading = shared::SensorReading {
            left: values[0],
            mid: values[1],
            right: values[2],
            ..Default::default()
        };
        let state = blob.hasher().hash(&reading);
        let frame = LogFrame {
            tick,
            mode: RunMode::Driving,
            raw_times: [240; 3],
            values,
            state,
            action: blob.table().action(state),
            motors,
            robot_id: id,
            encoder_counts: counts,
            choice: None,
            ..LogFrame::default()
        };
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = frame.encode(&mut buf);
        bytes.extend(&buf[..n]);
    }
    bytes
}

#[test]
fn replay_fits_each_robots_wheel_speed_and_turn_bias_into_one_file_for_the_swarm() {
    let dir = tempfile::tempdir().unwrap();
    let fit = dir.path().join("fit.json");
    let straight = shared::MotorCommand {
        left: 150,
        right: 150,
    }; // 2 units per step
       // Robot 1: 2 units x 6.5 mm x 2 counts/mm = 26 counts per track: as intended, drifting right.
       // Robot 2: 10 % slow.
    for (id, counts) in [(1u8, [27i16, 25]), (2, [23, 24])] {
        let log = dir.path().join(format!("robot{id}.bin"));
        std::fs::write(&log, driving_capture(id, straight, counts)).unwrap();
        let out = host()
            .args([
                "replay",
                "--counts-per-mm",
                "2",
                "--track-mm",
                "100",
                "--fit-profile",
            ])
            .arg(&fit)
            .arg("--log")
            .arg(&log)
            .arg("--policy")
            .arg(policy_path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(
            text.contains(&format!("motion of robot {id}")) && text.contains("intended 2.000"),
            "{text}"
        );
    }
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&fit).unwrap()).unwrap();
    let robots = v["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 2);
    let get = |i: usize, k: &str| robots[i][k].as_f64().unwrap();
    assert_eq!(robots[0]["id"].as_u64(), Some(1));
    assert!((get(0, "wheel_speed_factor") - 1.0).abs() < 1e-3, "{v}");
    // (27 - 25) counts / 2 per mm / 100 mm = 0.01 rad per step to the right.
    assert!((get(0, "turn_bias") - 0.01).abs() < 1e-4, "{v}");
    assert!(
        (get(1, "wheel_speed_factor") - 23.5 / 26.0).abs() < 1e-3,
        "{v}"
    );
    assert!((get(1, "turn_bias") + 0.005).abs() < 1e-4, "{v}");
    assert_eq!(
        robots[0].as_object().unwrap().keys().collect::<Vec<_>>(),
        ["id", "turn_bias", "wheel_speed_factor"]
    );
}

/// `host view --log LOG --policy POLICY ARGS`.
fn view_log(log: &Path, args: &[&str]) -> served::Served {
    let mut all = vec![OsString::from("--log"), log.into(), "--policy".into()];
    all.push(policy_path().into());
    all.extend(args.iter().map(OsString::from));
    served::serve(all)
}

fn get(address: &str, path: &str) -> (u16, Vec<u8>) {
    served::request(address, "GET", path)
}

#[test]
fn view_log_serves_every_frame_checked_as_replay_checks_it_and_the_dead_reckoned_track() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.log");
    write_log(&log);
    let served = view_log(&log, &[]);
    let (status, body) = get(&served.address, "/recording.json");
    assert_eq!(status, 200);
    let doc: serde_json::Value = serde_json::from_slice(&body).unwrap();
    let replayed = replay_json(&log);
    let frames = doc["playback"]["frames"].as_array().unwrap();
    assert_eq!(Some(frames.len() as u64), replayed["frames"].as_u64());
    assert_eq!(doc["playback"]["damaged"], replayed["damaged"]);
    assert_eq!(doc["playback"]["diverged"], replayed["diverged"]);
    assert!(frames.iter().all(|f| f["stages"] == serde_json::json!([])));
    // tv75 unless told: its arena, its robots' wedge
    assert_eq!(doc["world"]["arena"][0].as_f64().unwrap().round(), 254.0);
    assert!(doc["world"]["outline"].is_array());
    assert_eq!(doc["log"], "run.log");
    let (status, png) = get(&served.address, "/field.png");
    assert_eq!((status, &png[1..4]), (200, &b"PNG"[..]));
    let (status, page) = get(&served.address, "/");
    assert!(status == 200 && String::from_utf8_lossy(&page).contains("recording.json"));
    assert_eq!(get(&served.address, "/state.json").0, 404);

    // a robot driving straight: 26 counts at 2 per mm and 6.5 mm per unit
    // is 2 units a period, from the arena's centre
    let capture = dir.path().join("drive.bin");
    let straight = shared::MotorCommand {
        left: 150,
        right: 150,
    };
    std::fs::write(&capture, driving_capture(1, straight, [26, 26])).unwrap();
    let served = view_log(&capture, &["--counts-per-mm", "2", "--arena", "thesis"]);
    let doc: serde_json::Value =
        serde_json::from_slice(&get(&served.address, "/recording.json").1).unwrap();
    let frames = doc["playback"]["frames"].as_array().unwrap();
    let pose = |k: usize| -> Vec<f64> {
        frames[k]["pose"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    assert_eq!(frames.len(), 20);
    assert_eq!(pose(0), [402.0, 400.0, 0.0]);
    assert!(
        (pose(19)[0] - 440.0).abs() < 1e-9 && pose(19)[1] == 400.0,
        "{:?}",
        pose(19)
    );
}

#[test]
fn view_log_errors_name_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let not_a_log = dir.path().join("notes.txt");
    std::fs::write(&not_a_log, "hello").unwrap();
    let out = host()
        .args(["view", "--port", "0", "--log"])
        .arg(&not_a_log)
        .arg("--policy")
        .arg(policy_path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("notes.txt"), "{err}");
    let out = host()
        .args(["view", "--port", "0", "--log"])
        .arg(&not_a_log)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--policy"), "{err}");
}

#[test]
fn replay_and_monitor_errors_name_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.log");
    write_log(&log);
    let fails = |cmd: &mut Command| {
        let out = cmd.output().unwrap();
        assert!(!out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(
        host()
            .args(["replay", "--log", "/no/such.log", "--policy"])
            .arg(policy_path()),
    );
    assert!(e.contains("/no/such.log"), "{e}");
    let e = fails(
        host()
            .args(["replay", "--log"])
            .arg(&log)
            .args(["--policy", "/no/such.policy"]),
    );
    assert!(e.contains("/no/such.policy"), "{e}");
    let visits = dir.path().join("visits.json");
    std::fs::write(
        &visits,
        format!(r#"{{"hasher": "bits7", "visits": {:?}}}"#, vec![1; 128]),
    )
    .unwrap();
    let e = fails(
        host()
            .args(["replay", "--log"])
            .arg(&log)
            .arg("--policy")
            .arg(policy_path())
            .arg("--visits")
            .arg(&visits),
    );
    assert!(e.contains("visits.json") && e.contains("bits7"), "{e}");
    let mut other_version = MAGIC.to_vec();
    other_version.push(VERSION + 1);
    let future = dir.path().join("future.log");
    std::fs::write(&future, other_version).unwrap();
    let e = fails(
        host()
            .args(["replay", "--log"])
            .arg(&future)
            .arg("--policy")
            .arg(policy_path()),
    );
    assert!(
        e.contains("future.log") && e.contains("format version 2 is not supported"),
        "{e}"
    );

    // 5,000 random bytes: no frame decodes, which is an error.
    let noise = dir.path().join("noise.bin");
    let mut x = 12345u32;
    let bytes: Vec<u8> = (0..5000)
        .map(|_| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            (x >> 16) as u8
        })
        .collect();
    std::fs::write(&noise, bytes).unwrap();
    let e = fails(
        host()
            .args(["replay", "--log"])
            .arg(&noise)
            .arg("--policy")
            .arg(policy_path()),
    );
    assert!(
        e.contains("no frame in") && e.contains("noise.bin") && e.contains("decodes"),
        "{e}"
    );

    let e = fails(
        host()
            .args(["monitor", "--port", "/dev/null-port", "--out"])
            .arg(&log),
    );
    assert!(e.contains("already exists") && e.contains("run.log"), "{e}");
    let e = fails(host().args(["monitor", "--out", "x.log"]));
    assert!(e.contains("--port"), "{e}");
}

#[test]
fn flash_dry_run_prints_the_exact_commands_and_validates_first() {
    let out = host()
        .current_dir(repo().join("host"))
        .args([
            "flash",
            "--dry-run",
            "--port",
            "/dev/ttyACM0",
            "--robot-id",
            "3",
            "--policy",
        ])
        .arg(policy_path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let repo = repo();
    let crc =
        shared::FirmwareIdentity::policy_crc_of(&std::fs::read(policy_path()).unwrap()).unwrap();
    let expected = format!(
        "env -u CARGO_TARGET_DIR FIRMWARE_POLICY={} FIRMWARE_HASHER=original FIRMWARE_ROBOT_ID=3 \
         FIRMWARE_OUT={}/target/flash/{crc:08x}-robot3 {}/scripts/build-firmware\n\
         # check that the hex embeds policy CRC {crc:08x} and robot id 3, then the 1200-baud touch: open /dev/ttyACM0 at \
         1200 baud and drop DTR (the robot resets into its bootloader; if /dev/ttyACM0 does not exist or the touch fails, \
         double-press the robot's reset button: its bootloader waits 8 s); once the bootloader's port appears \
         (a port new since the touch, or /dev/ttyACM0 back):\n\
         avrdude -p atmega32u4 -c avr109 -P /dev/ttyACM0 -b 57600 -D -U flash:w:{}/target/flash/{crc:08x}-robot3/firmware.hex:i\n",
        policy_path().display(),
        repo.display(),
        repo.display(),
        repo.display()
    );
    assert_eq!(String::from_utf8(out.stdout).unwrap(), expected);

    let dir = tempfile::tempdir().unwrap();
    let fails = |cmd: &mut Command| {
        let out = cmd.output().unwrap();
        assert!(!out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let e = fails(
        host()
            .current_dir(dir.path())
            .args(["flash", "--dry-run", "--policy"])
            .arg(policy_path()),
    );
    assert!(e.contains("must run inside a zumo-swarm checkout"), "{e}");
    let e = fails(
        host()
            .current_dir(&repo)
            .args([
                "flash",
                "--dry-run",
                "--hasher",
                "original-obstacle",
                "--policy",
            ])
            .arg(policy_path()),
    );
    assert!(
        e.contains("uses hasher original") && e.contains("original-obstacle"),
        "{e}"
    );
    let bad = dir.path().join("bad.policy");
    std::fs::write(&bad, b"not a policy").unwrap();
    let e = fails(
        host()
            .current_dir(&repo)
            .args(["flash", "--dry-run", "--policy"])
            .arg(&bad),
    );
    assert!(
        e.contains("bad.policy") && e.contains("not a policy blob"),
        "{e}"
    );
    let e = fails(
        host()
            .current_dir(&repo)
            .args(["flash", "--hasher", "eleven", "--policy"])
            .arg(policy_path()),
    );
    assert!(e.contains("\"eleven\""), "{e}");
}
