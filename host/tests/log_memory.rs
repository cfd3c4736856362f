//! The memory of the log tools stays as `docs/ranges.md` promises:
//! `host replay` reads a log entry by entry (its memory does not grow with
//! the log), `host view --log` holds the page's document and little else,
//! and refuses a log longer than the viewed log file size. Peak memory is
//! the children's maximum resident set size (`getrusage`), so this file
//! holds one test, whose children are the only ones measured, and it
//! holds nothing large itself before a measured child starts.

#![cfg(target_os = "linux")]

use host::robot::log_file::{encode_record, MAGIC, VERSION};
use shared::{FieldCalibration, LogFrame, RunMode, SensorRange};
use std::ffi::OsStr;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

mod served;

const MB: u64 = 1024 * 1024;

fn policy_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies/oc-heuristic.policy")
}

/// A recorded log of at least `bytes` bytes: 2,000 idle frames, every
/// 50th with a calibration, over and over; returns the number of records.
fn write_log(path: &Path, bytes: u64) -> u64 {
    let calibration = FieldCalibration {
        ranges: [SensorRange {
            bright: 40,
            dark: 440,
        }; 3],
    };
    let mut block = Vec::new();
    for tick in 1..=2000u32 {
        let frame = LogFrame {
            tick,
            mode: RunMode::Idle,
            raw_times: [40 + (tick * 7 % 400) as u16, 240, 300],
            calibration: (tick % 50 == 1).then_some(calibration),
            ..LogFrame::default()
        };
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = frame.encode(&mut buf);
        block.extend(encode_record(u64::from(tick) * 20_000, &buf[..n - 1]));
    }
    // written block by block: a child's peak counts this process's at its
    // start (Linux notes the peak of the memory it leaves at exec)
    let mut log = std::fs::File::create(path).unwrap();
    log.write_all(&MAGIC).unwrap();
    log.write_all(&[VERSION]).unwrap();
    let (mut written, mut records) = (MAGIC.len() as u64 + 1, 0);
    while written < bytes {
        log.write_all(&block).unwrap();
        written += block.len() as u64;
        records += 2000;
    }
    records
}

/// The largest resident set of any child waited for so far, bytes.
fn children_peak() -> u64 {
    // SAFETY: getrusage only writes the struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        assert_eq!(libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage), 0);
        usage
    };
    usage.ru_maxrss as u64 * 1024
}

#[test]
fn replay_streams_a_log_and_the_view_holds_its_document_and_refuses_a_longer_log() {
    let dir = tempfile::tempdir().unwrap();
    let policy = policy_path();

    // host replay of a 64 MiB log: a few megabytes, whatever the log's size
    let long = dir.path().join("long.log");
    let records = write_log(&long, 64 * MB);
    let out = Command::new(env!("CARGO_BIN_EXE_host"))
        .args(["replay", "--log"])
        .arg(&long)
        .arg("--policy")
        .arg(&policy)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains(&format!("{records} entries, {records} frames decoded")),
        "{text}"
    );
    let replay = children_peak();
    assert!(
        replay < 32 * MB,
        "host replay of 64 MiB held {replay} bytes"
    );

    // host view --log of a 24 MiB log: the document and little else
    let viewed = dir.path().join("viewed.log");
    write_log(&viewed, 24 * MB);
    let document = {
        let view = served::serve([
            OsStr::new("--log"),
            viewed.as_os_str(),
            OsStr::new("--policy"),
            policy.as_os_str(),
        ]);
        let (status, body) = served::request(&view.address, "GET", "/recording.json");
        assert_eq!(status, 200);
        assert!(body.starts_with(b"{\"log\":\"viewed.log\""));
        body.len() as u64
    };
    let view = children_peak();
    assert!(
        view < document + 48 * MB,
        "host view --log held {view} bytes for a document of {document}"
    );

    // a log longer than the view's limit is refused, naming the limit
    let longer = dir.path().join("longer.log");
    let file = std::fs::File::create(&longer).unwrap();
    file.set_len(sim::base::ranges::VIEW_LOG_FILE.max as u64 + 1)
        .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_host"))
        .args(["view", "--port", "0", "--log"])
        .arg(&longer)
        .arg("--policy")
        .arg(&policy)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("longer.log") && e.contains("the most a viewed log file is"),
        "{e}"
    );
}
