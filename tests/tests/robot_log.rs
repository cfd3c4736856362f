//! `host monitor` and `host replay` on the firmware's real serial stream:
//! the release ELF runs a session in simavr (calibration sweep, driving, a
//! silent camera, stop), its USART1 bytes go through a pseudo-terminal pair
//! to the monitor loop, which records them, survives the pseudo-terminal
//! being closed and replaced (an unplugged adapter), and the recording is
//! replayed against the embedded policy.
//!
//! No timing races: the test feeds the terminal only after the monitor
//! reports it connected, unplugs only after it has recorded every frame
//! sent so far, and the monitor stops after the number of frames sent.

use firmware::embedded;
use host::robot::log_file::{self, SourceKind};
use host::robot::monitor::{self, MonitorEvent, MonitorOptions, SerialOpener};
use host::robot::replay::{replay, ModeCounts, ReplayReport, Stage};
use serialport::{SerialPort, TTYPort};
use shared::{ActionId, Faults, LogFrame, PolicyBlob, PolicyTable, RunMode};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::{channel, Receiver};
use std::time::Duration;
use tests::zumo::{Zumo, PUCK_LEFT};

/// A guard against a hung test, not a timing assertion.
const EVENT_TIMEOUT: Duration = Duration::from_secs(60);

/// A session: boot uncalibrated, calibrate with button B, drive over
/// changing field values with a puck in view, lose the camera for a while,
/// stop. Returns the serial stream.
fn session() -> Vec<u8> {
    let mut z = Zumo::boot();
    z.run_ms(40);
    z.calibrate();
    z.show(&[PUCK_LEFT]);
    z.press_a();
    // The wheels turn while it drives (30 and 28 counts per period).
    z.set_wheel_counts_per_second([1_500, 1_400]);
    for i in 0..40u16 {
        z.set_sensor_ticks([
            Some(120 + i * 7),
            Some(380 - i * 6),
            Some(150 + (i * 37) % 200),
        ]);
        z.run_ms(20);
    }
    z.connect_pixy(false);
    z.run_ms(120);
    z.connect_pixy(true);
    z.run_ms(100);
    z.set_wheel_counts_per_second([0, 0]);
    z.press_a();
    z.run_ms(40);
    z.uart_bytes().to_vec()
}

/// The frames of a raw stream, decoded.
fn frames_of(stream: &[u8]) -> Vec<LogFrame> {
    stream
        .split(|b| *b == 0)
        .filter(|c| !c.is_empty())
        .map(|c| LogFrame::decode(c).expect("a firmware frame decodes"))
        .collect()
}

#[derive(Debug, PartialEq)]
enum Event {
    Connected,
    Frames(u64),
    Lost,
    OpenFailed,
}

fn wait_for(events: &Receiver<Event>, wanted: Event) {
    loop {
        let e = events
            .recv_timeout(EVENT_TIMEOUT)
            .unwrap_or_else(|_| panic!("no {wanted:?} from the monitor"));
        if e == wanted {
            return;
        }
    }
}

/// A fresh pseudo-terminal pair; `link` points at its terminal end, as a
/// udev `/dev/serial/by-id` link points at whichever tty the adapter got.
fn plug(link: &Path) -> TTYPort {
    let (master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    let name = slave.name().expect("the terminal end's path");
    drop(slave);
    let tmp = link.with_extension("new");
    std::os::unix::fs::symlink(&name, &tmp).unwrap();
    std::fs::rename(&tmp, link).unwrap();
    master
}

/// Monitors `stream` through two successive pseudo-terminals (the first
/// unplugged after `split` bytes) and returns the recorded log's path.
fn record_through_ptys(
    stream: &[u8],
    split: usize,
    dir: &Path,
) -> (std::path::PathBuf, monitor::LiveStatus) {
    let total = stream.iter().filter(|b| **b == 0).count() as u64;
    let first_part = stream[..split].iter().filter(|b| **b == 0).count() as u64;
    let link = dir.join("robot");
    let out = dir.join("run.log");
    let mut master = plug(&link);

    let (tx, events) = channel();
    let port = link.display().to_string();
    let out_path = out.clone();
    let monitor = std::thread::spawn(move || {
        let mut log = log_file::LogWriter::create(&out_path, false).unwrap();
        let mut opener = SerialOpener {
            port,
            baud: monitor::DEFAULT_BAUD,
        };
        let options = MonitorOptions {
            max_frames: Some(total),
            reopen_interval: Duration::from_millis(20),
        };
        monitor::run(
            &mut opener,
            &mut log,
            &options,
            &AtomicBool::new(false),
            &mut |e| {
                let _ = tx.send(match e {
                    MonitorEvent::Connected => Event::Connected,
                    MonitorEvent::Frame(s) => Event::Frames(s.frames),
                    MonitorEvent::Lost(_) => Event::Lost,
                    MonitorEvent::OpenFailed(_) => Event::OpenFailed,
                });
            },
        )
        .unwrap()
    });

    wait_for(&events, Event::Connected);
    let writer = std::thread::spawn({
        let part = stream[..split].to_vec();
        move || {
            master.write_all(&part).unwrap();
            master
        }
    });
    wait_for(&events, Event::Frames(first_part));
    drop(writer.join().unwrap()); // unplugged
    wait_for(&events, Event::Lost);
    let mut master = plug(&link);
    wait_for(&events, Event::Connected);
    let rest = stream[split..].to_vec();
    let writer = std::thread::spawn(move || {
        master.write_all(&rest).unwrap();
        master
    });
    let status = monitor.join().unwrap();
    drop(writer.join().unwrap());
    (out, status)
}

#[test]
fn monitor_records_the_firmware_over_a_pty_across_unplugging_and_replay_finds_no_divergence() {
    let stream = session();
    let frames = frames_of(&stream);
    assert!(frames.len() > 80, "{} frames", frames.len());
    // Unplug between two frames, in the middle of driving.
    let driving = frames
        .iter()
        .position(|f| f.mode == RunMode::Driving)
        .expect("the robot drove");
    let split = stream
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == 0)
        .nth(driving + 10)
        .unwrap()
        .0
        + 1;

    let dir = tempfile::tempdir().unwrap();
    let (log, status) = record_through_ptys(&stream, split, dir.path());
    assert_eq!(
        (status.frames, status.decode_errors, status.disconnects),
        (frames.len() as u64, 0, 1)
    );

    let recording = log_file::read(&log).unwrap();
    assert_eq!(recording.kind, SourceKind::Recorded);
    let recorded: Vec<&[u8]> = recording
        .entries
        .iter()
        .map(|e| e.frame.as_deref().unwrap())
        .collect();
    let sent: Vec<&[u8]> = stream
        .split(|b| *b == 0)
        .filter(|c| !c.is_empty())
        .collect();
    assert_eq!(recorded, sent, "the log holds exactly the bytes sent");

    let policy = PolicyBlob::decode(embedded::POLICY_BLOB).unwrap();
    let report = replay(&recording, &policy, None, Default::default());
    check_report(&report, &frames);
    println!("{report}");

    // The raw serial stream, replayed as a capture, says the same.
    let raw = replay(
        &log_file::parse(&stream).unwrap(),
        &policy,
        None,
        Default::default(),
    );
    assert_eq!(raw.source, SourceKind::RawCapture.to_string());
    assert_eq!(
        (raw.frames, raw.diverged, raw.first_fault_episodes.clone()),
        (report.frames, 0, report.first_fault_episodes.clone())
    );

    // Another policy: the replay catches every decision it would change.
    let mut table = PolicyTable::new(policy.hasher());
    for (s, a) in policy.table().entries() {
        table.set(s, ActionId((a.0 + 1) % policy.actions().len() as u8));
    }
    let other = PolicyBlob::new(*policy.actions(), table, policy.provenance().clone()).unwrap();
    let r = replay(&recording, &other, None, Default::default());
    assert_eq!(r.diverged, report.frames);
    assert_eq!(r.diverged_by_stage.of(Stage::Policy), report.frames);
    assert_eq!(r.diverged_by_stage.of(Stage::Hash), 0);
}

fn check_report(r: &ReplayReport, frames: &[LogFrame]) {
    assert_eq!(
        (r.frames, r.damaged, r.diverged),
        (frames.len() as u64, 0, 0),
        "{r}"
    );
    assert_eq!((r.missing_ticks, r.restarts), (0, 0));
    // Every frame's values were re-derived from its raw times: the first
    // frame carries the start-up calibration, the procedure's follows it.
    assert_eq!(r.calibration_checked, r.frames);
    assert_eq!(r.calibrations.len(), 2, "{:?}", r.calibrations);
    assert_eq!(r.calibrations[0], firmware::config::UNCALIBRATED);
    for (range, offset) in r.calibrations[1].ranges.iter().zip([0, 10, 20]) {
        assert!(
            range.bright.abs_diff(100 + offset) <= 2 && range.dark.abs_diff(400 + offset) <= 2,
            "{range:?}"
        );
    }
    let count = |m: RunMode| frames.iter().filter(|f| f.mode == m).count() as u64;
    assert_eq!(
        r.modes,
        ModeCounts {
            idle: count(RunMode::Idle),
            driving: count(RunMode::Driving),
            calibrating: count(RunMode::Calibrating)
        }
    );
    assert!(r.modes.calibrating >= 14 && r.policy_drove >= 40, "{r}");
    // The encoders' counts: robot 0, every period the policy drove, 30 and 28 counts.
    assert_eq!(r.motion.len(), 1, "{r}");
    assert_eq!(r.motion[0].id, 0);
    let measured: u64 = r.motion[0].actions.iter().map(|a| a.periods).sum();
    assert!(
        measured + 3 >= r.policy_drove && measured > 30,
        "{measured} of {} periods measured",
        r.policy_drove
    );
    let fit = r.motion[0].fit.expect("a fit");
    assert!(
        fit.wheel_speed_factor > 0.0 && fit.turn_bias > 0.0,
        "{fit:?}"
    );
    let mut actions = vec![0u64; r.actions.len()];
    let mut states = std::collections::BTreeSet::new();
    for f in frames.iter().filter(|f| f.policy_drove()) {
        actions[f.action.index()] += 1;
        states.insert(f.state);
    }
    assert_eq!(r.actions, actions);
    assert_eq!(r.coverage.states, states.len());
    assert!(states.iter().all(|s| s.index() < r.coverage.of));
    // Before calibrating: no calibration; the silent camera: one episode.
    let silent: Vec<&LogFrame> = frames
        .iter()
        .filter(|f| f.faults.contains(Faults::CAMERA_SILENT))
        .collect();
    assert!(!silent.is_empty());
    let episodes: Vec<_> = r
        .first_fault_episodes
        .iter()
        .filter(|e| e.fault == "camera silent")
        .collect();
    assert_eq!(episodes.len(), 1, "{:?}", r.first_fault_episodes);
    assert_eq!(
        (episodes[0].first_tick, episodes[0].last_tick),
        (silent[0].tick, silent.last().unwrap().tick)
    );
    assert!(r
        .first_fault_episodes
        .iter()
        .any(|e| e.fault == "no calibration" && e.first_tick == 1));
}

#[path = "../../view/tests/browser/mod.rs"]
mod browser;

/// Shows frame `k` as a user scrubbing the timeline would.
fn scrub(b: &mut browser::Browser, k: usize) {
    b.eval(&format!(
        "(() => {{ const t = document.getElementById('timeline'); t.value = {k}; t.dispatchEvent(new Event('input')); }})()"
    ));
}

#[test]
fn the_log_plays_on_the_view_s_page_with_the_decisions_replay_reports() {
    let stream = session();
    let frames = frames_of(&stream);
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("capture.bin");
    std::fs::write(&log, &stream).unwrap();
    let policy = PolicyBlob::decode(embedded::POLICY_BLOB).unwrap();
    let embedded_file = dir.path().join("embedded.policy");
    std::fs::write(&embedded_file, embedded::POLICY_BLOB).unwrap();
    // another policy, each action one on: every decision of the log differs
    let mut table = PolicyTable::new(policy.hasher());
    for (s, a) in policy.table().entries() {
        table.set(s, ActionId((a.0 + 1) % policy.actions().len() as u8));
    }
    let other = PolicyBlob::new(*policy.actions(), table, policy.provenance().clone()).unwrap();
    let other_file = dir.path().join("other.policy");
    std::fs::write(&other_file, other.encode()).unwrap();
    let scenario = sim::scenario::Scenario {
        arena: sim::scenario::Arena::Screen(Box::new(sim::scenario::arena::ArenaSpec::tv75())),
        ..Default::default()
    };
    let recording = log_file::parse(&stream).unwrap();
    for (file, blob) in [(&embedded_file, &policy), (&other_file, &other)] {
        let report = replay(&recording, blob, None, Default::default());
        let played =
            host::robot::log_view::log_view(&log, file, &scenario, Default::default()).unwrap();
        assert_eq!(
            (played.frames as u64, played.diverged),
            (report.frames, report.diverged)
        );
        let address = view::RecordingView::listen(
            "127.0.0.1:0".parse().unwrap(),
            played.document,
            played.field_png,
        )
        .unwrap()
        .spawn()
        .unwrap();
        let mut b = browser::Browser::open(&format!("http://{address}/"), (1200, 800));
        b.wait_for("document.documentElement.dataset.ready === 'true'", 60);
        assert_eq!(b.data("frames"), frames.len().to_string());
        for (k, f) in frames.iter().enumerate() {
            scrub(&mut b, k);
            assert_eq!(
                [
                    b.data("index"),
                    b.data("tick"),
                    b.data("state"),
                    b.data("action")
                ],
                [
                    k,
                    f.tick as usize,
                    usize::from(f.state.0),
                    usize::from(f.action.0)
                ]
                .map(|v| v.to_string()),
                "frame {k}"
            );
            // what replay says of the frame: the embedded policy agrees
            // everywhere, the other one differs at the policy stage alone
            let (stages, expected) = if report.diverged == 0 {
                ("", f.action.0)
            } else {
                ("policy", (f.action.0 + 1) % policy.actions().len() as u8)
            };
            assert_eq!(
                (b.data("stages"), b.data("expectedAction")),
                (stages.to_string(), expected.to_string()),
                "frame {k}"
            );
        }
        // the next-divergence key finds one exactly when replay does
        scrub(&mut b, 0);
        b.eval("document.dispatchEvent(new KeyboardEvent('keydown', { key: 'd' }))");
        let expected = if report.diverged == 0 { "0" } else { "1" };
        assert_eq!(b.data("index"), expected);
        // played at 100x from the start, it runs through to the last frame
        scrub(&mut b, 0);
        b.eval("document.getElementById('speed').value = '100'; document.getElementById('play').click()");
        let last = frames.len() - 1;
        b.wait_for(
            &format!("document.documentElement.dataset.index === '{last}'"),
            60,
        );
    }
}
