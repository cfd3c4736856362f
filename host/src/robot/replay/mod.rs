//! `host replay`: checks every frame of a recording against the policy the
//! robot should be running, with the same `shared` code the firmware runs,
//! one stage at a time, each from the frame's own logged inputs:
//!
//! 1. calibration: the raw RC times -> calibrated values
//!    (`shared::FieldCalibration`, with the calibration the robot logged;
//!    frames before the first one are not checked at this stage);
//! 2. hash: the logged values and blob bits -> state (`shared::StateHasher`,
//!    the policy's hasher);
//! 3. policy: the logged state -> action (the policy's table);
//! 4. motors: what the frame's mode and faults say was applied: the
//!    action's mix (`shared::RobotProfile::ZUMO`, as `firmware/build.rs`
//!    precomputes it) when the policy drove, a stop when idle, calibrating
//!    (the robot stands still) or stopped by a fault
//!    ([`decisions`]).
//!
//! It also reports state coverage (and, given training visit counts, the
//! states training never visited), the action histogram, faults and their
//! episodes ([`faults`]), modes and tick gaps ([`timeline`]), how each
//! robot moved per action against what the action asked for, from the
//! wheel encoders, and its wheel speed factor and turn bias
//! ([`odometry`]), and the damaged records and frames with their byte
//! offsets (skipped, never fatal unless no frame decodes); the report,
//! text or JSON, is [`report`]'s.

pub mod decisions;
pub mod faults;
pub mod odometry;
pub mod playback;
pub mod report;
pub mod timeline;

pub use report::{
    Coverage, Damaged, FaultCount, FaultEpisode, FrameCheck, ModeCounts, ReplayReport, Stage,
    StageCounts, LISTED,
};

use super::log_file::{self, Entry, Recording, SourceKind};
use super::visits::TrainingVisits;
use anyhow::{bail, Result};
use decisions::DecisionCheck;
use faults::FaultTracker;
use odometry::{OdometrySettings, OdometryTracker};
use shared::{LogFrame, PolicyBlob, State};
use sim::base::ranges;
use std::collections::BTreeMap;
use std::path::Path;
use timeline::Timeline;

/// Recomputes every frame's decision with `policy` and summarises the run.
/// `visits`, if given, must be for the policy's hasher (the caller checks).
pub fn replay(
    recording: &Recording,
    policy: &PolicyBlob,
    visits: Option<&TrainingVisits>,
    odometry: OdometrySettings,
) -> ReplayReport {
    let mut r = Replayer::new(policy, odometry);
    recording.entries.iter().for_each(|e| r.entry(e));
    r.finish(recording.kind, visits)
}

/// Reads the files and replays: the log (recorded or raw), the policy blob
/// and optional training visits, which must be for the policy's hasher.
/// Fails, naming the log, when no frame in it decodes.
pub fn replay_files(
    log: &Path,
    policy: &Path,
    visits: Option<&Path>,
    odometry: OdometrySettings,
) -> Result<ReplayReport> {
    let blob = sim::control::policy_file::read(policy)?;
    let training = match visits {
        Some(path) => {
            let v = TrainingVisits::read(path)?;
            if v.hasher() != blob.hasher() {
                bail!(
                    "visits file {} counts states of hasher {} but policy file {} uses {}",
                    path.display(),
                    v.hasher(),
                    policy.display(),
                    blob.hasher()
                );
            }
            Some(v)
        }
        None => None,
    };
    // entry by entry, as read: memory does not grow with the log
    let mut r = Replayer::new(&blob, odometry);
    let kind = log_file::read_each(log, &ranges::LOG_FILE, &mut |e| r.entry(&e))?;
    let report = r.finish(kind, training.as_ref());
    if report.frames == 0 {
        let versions = if report.other_version > 0 {
            format!(
                ", {} of them of another log format version (this host reads version {})",
                report.other_version,
                LogFrame::VERSION
            )
        } else {
            String::new()
        };
        bail!(
            "no frame in {} decodes ({}, {} entries, {} damaged{versions}): is it a log of this robot firmware's serial line?",
            log.display(),
            report.source,
            report.entries,
            report.damaged
        );
    }
    Ok(report)
}

/// Everything gathered while reading a recording.
struct Replayer<'a> {
    policy: &'a PolicyBlob,
    decisions: DecisionCheck<'a>,
    timeline: Timeline,
    faults: FaultTracker,
    odometry: OdometryTracker,
    damaged: u64,
    first_damaged: Vec<Damaged>,
    other_version: u64,
    /// Frames, states and actions while the policy drove.
    policy_drove: u64,
    states: BTreeMap<u16, u64>,
    actions: Vec<u64>,
    /// Entries read.
    entries: u64,
}

impl<'a> Replayer<'a> {
    fn new(policy: &'a PolicyBlob, odometry: OdometrySettings) -> Replayer<'a> {
        Replayer {
            policy,
            decisions: DecisionCheck::new(policy),
            timeline: Timeline::default(),
            faults: FaultTracker::default(),
            odometry: OdometryTracker::new(odometry),
            damaged: 0,
            first_damaged: Vec::new(),
            other_version: 0,
            policy_drove: 0,
            states: BTreeMap::new(),
            actions: vec![0; policy.actions().len()],
            entries: 0,
        }
    }

    /// Adds one entry of the recording: a frame, or a damaged one.
    fn entry(&mut self, entry: &Entry) {
        self.entries += 1;
        match &entry.frame {
            Err(e) => self.damaged(entry.offset, entry.len, e.to_string()),
            Ok(bytes) => match LogFrame::decode(bytes) {
                Ok(frame) => self.frame(entry.offset, &frame, entry.host_time_us),
                Err(e) => {
                    if matches!(e, shared::LogError::UnsupportedVersion(_)) {
                        self.other_version += 1;
                    }
                    self.damaged(entry.offset, entry.len, format!("frame: {e}"));
                }
            },
        }
    }

    fn damaged(&mut self, offset: u64, len: usize, error: String) {
        self.damaged += 1;
        if self.first_damaged.len() < LISTED {
            self.first_damaged.push(Damaged { offset, len, error });
        }
    }

    fn frame(&mut self, offset: u64, f: &LogFrame, host_time_us: Option<u64>) {
        self.timeline.frame(f, host_time_us);
        self.decisions.frame(offset, f);
        if f.policy_drove() {
            self.policy_drove += 1;
            *self.states.entry(f.state.0).or_default() += 1;
            if let Some(n) = self.actions.get_mut(f.action.index()) {
                *n += 1;
            }
        }
        self.faults.frame(f);
        self.odometry.frame(f);
    }

    /// States met while the policy drove, most frequent first, and those
    /// training never visited.
    fn coverage(&self, visits: Option<&TrainingVisits>) -> Coverage {
        let mut frames_per_state: Vec<(u16, u64)> =
            self.states.iter().map(|(s, n)| (*s, *n)).collect();
        frames_per_state.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let untrained = visits.map(|v| {
            frames_per_state
                .iter()
                .filter(|(s, _)| v.of(State(*s)) == 0)
                .copied()
                .collect()
        });
        Coverage {
            states: frames_per_state.len(),
            of: self.policy.hasher().num_states(),
            frames_per_state,
            untrained,
        }
    }

    fn finish(mut self, kind: SourceKind, visits: Option<&TrainingVisits>) -> ReplayReport {
        self.faults.finish();
        let coverage = self.coverage(visits);
        let (t, d, f) = (self.timeline, self.decisions, self.faults);
        ReplayReport {
            source: kind.to_string(),
            entries: self.entries,
            frames: t.frames,
            damaged: self.damaged,
            first_damaged: self.first_damaged,
            other_version: self.other_version,
            modes: t.modes,
            policy_drove: self.policy_drove,
            ticks: t.ticks,
            missing_ticks: t.missing_ticks,
            restarts: t.restarts,
            host_seconds: match (kind, t.host_times) {
                (SourceKind::Recorded, Some((first, last))) => {
                    Some(last.saturating_sub(first) as f64 / 1e6)
                }
                _ => None,
            },
            calibration_checked: d.calibration_checked,
            calibrations: d.calibrations,
            diverged: d.diverged,
            diverged_by_stage: d.by_stage,
            first_divergences: d.first,
            coverage,
            actions: self.actions,
            fault_frames: f.fault_frames,
            faults: f.faults,
            first_fault_episodes: f.first_episodes,
            motion: self.odometry.finish(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::log_file::{self, encode_record, HEADER_LEN, MAGIC, VERSION};
    use shared::{
        ActionId, ActionTable, BlobSummary, ChoiceRng, Faults, FieldCalibration, FieldValue,
        MotorCommand, PolicyTable, Provenance, RobotProfile, RunMode, SensorRange, SensorReading,
        State, StateHasher,
    };
    use std::collections::BTreeMap;

    const CAL: FieldCalibration = FieldCalibration {
        ranges: [SensorRange {
            bright: 40,
            dark: 440,
        }; 3],
    };

    fn policy() -> PolicyBlob {
        let mut table = PolicyTable::new(StateHasher::Original);
        for s in 0..256u16 {
            table.set(State(s), ActionId((s % 4) as u8));
        }
        let actions = ActionTable::new(&[0.0, 0.3, -0.3, 0.15], 2.0).unwrap();
        PolicyBlob::new(
            actions,
            table,
            Provenance::new("annulus", "test", 0, 0).unwrap(),
        )
        .unwrap()
    }

    /// A frame as the firmware would log it for these raw times and blobs.
    fn firmware_frame(
        p: &PolicyBlob,
        choice: &mut ChoiceRng,
        tick: u32,
        mode: RunMode,
        faults: Faults,
        raw: [u16; 3],
        puck_left: bool,
    ) -> LogFrame {
        let values = CAL.scales().values(&raw);
        let blobs = BlobSummary {
            puck_left,
            ..BlobSummary::default()
        };
        let reading = SensorReading::from_parts(values, blobs);
        let state = p.hasher().hash(&reading);
        let before = choice.state();
        let action = choice.pick(p.sets().mask(state));
        let drew = choice.state() != before;
        let mut f = LogFrame {
            tick,
            mode,
            faults,
            raw_times: raw,
            values,
            blobs,
            blocks: u8::from(puck_left),
            state,
            action,
            choice: drew.then_some(before),
            ..LogFrame::default()
        };
        if f.policy_drove() {
            f.motors = RobotProfile::ZUMO.mix(2.0, p.actions().angular_speeds()[action.index()]);
        }
        f.calibration = (tick % 50 == 1).then_some(CAL);
        f
    }

    fn session(p: &PolicyBlob) -> Vec<LogFrame> {
        let mut frames = Vec::new();
        let mut choice = ChoiceRng::for_robot(0);
        for tick in 1..=120u32 {
            let mode = if tick <= 10 {
                RunMode::Idle
            } else {
                RunMode::Driving
            };
            let faults = if (60..65).contains(&tick) {
                Faults::CAMERA_SILENT
            } else {
                Faults::NONE
            };
            let raw = [
                40 + (tick * 7 % 400) as u16,
                40 + (tick * 13 % 400) as u16,
                40 + (tick * 3 % 400) as u16,
            ];
            frames.push(firmware_frame(
                p,
                &mut choice,
                tick,
                mode,
                faults,
                raw,
                tick % 3 == 0,
            ));
        }
        frames
    }

    fn encoded(f: &LogFrame) -> Vec<u8> {
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = f.encode(&mut buf);
        buf[..n - 1].to_vec()
    }

    fn log_of(frames: &[LogFrame]) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.push(VERSION);
        for (i, f) in frames.iter().enumerate() {
            bytes.extend(encode_record(1_000_000 + 20_000 * i as u64, &encoded(f)));
        }
        bytes
    }

    fn report_of(bytes: &[u8], p: &PolicyBlob) -> ReplayReport {
        replay(
            &log_file::parse(bytes).unwrap(),
            p,
            None,
            Default::default(),
        )
    }

    #[test]
    fn a_faithful_robot_has_no_divergences_and_its_run_is_summarised() {
        let p = policy();
        let frames = session(&p);
        let r = report_of(&log_of(&frames), &p);
        assert_eq!((r.frames, r.damaged, r.diverged), (120, 0, 0), "{r}");
        assert_eq!(
            r.modes,
            ModeCounts {
                idle: 10,
                driving: 110,
                calibrating: 0
            }
        );
        assert_eq!(r.policy_drove, 105);
        assert_eq!(r.calibration_checked, 120);
        assert_eq!(r.calibrations, vec![CAL]);
        assert_eq!(
            (r.ticks, r.missing_ticks, r.restarts),
            (Some((1, 120)), 0, 0)
        );
        assert!(
            r.host_seconds.is_some_and(|s| (s - 2.38).abs() < 1e-9),
            "{:?}",
            r.host_seconds
        );
        let mut actions = vec![0u64; 4];
        let mut states = BTreeMap::new();
        for f in frames.iter().filter(|f| f.policy_drove()) {
            actions[f.action.index()] += 1;
            *states.entry(f.state.0).or_insert(0u64) += 1;
        }
        assert_eq!(r.actions, actions);
        assert_eq!(r.coverage.states, states.len());
        assert_eq!(
            r.faults[2],
            FaultCount {
                fault: "camera silent",
                frames: 5,
                episodes: 1
            }
        );
        assert_eq!(
            r.first_fault_episodes,
            vec![FaultEpisode {
                fault: "camera silent",
                first_tick: 60,
                last_tick: 64,
                frames: 5
            }]
        );
        let text = r.to_string();
        assert!(
            text.contains("divergences: 0 frames")
                && text.contains("camera silent: 5 frames in 1 episodes"),
            "{text}"
        );
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["diverged"], 0);
        assert_eq!(json["coverage"]["untrained"], serde_json::Value::Null);
    }

    #[test]
    fn each_stage_is_caught_with_the_raw_values() {
        let p = policy();
        let mut frames = session(&p);
        frames[20].values[1] = FieldValue::from_raw(frames[20].values[1].raw() ^ 0x1000); // calibration (and likely hash)
        frames[30].state = State(frames[30].state.0 ^ 0x10); // hash (and policy: action of another state)
        frames[40].action = ActionId((frames[40].action.0 + 1) % 4); // policy and motors
        frames[50].motors.left += 1; // motors
        frames[5].motors = MotorCommand {
            left: 100,
            right: 100,
        }; // idle but moving
        let r = report_of(&log_of(&frames), &p);
        assert_eq!(r.diverged, 5, "{r}");
        let by_tick = |t: u32| {
            r.first_divergences
                .iter()
                .find(|d| d.tick == t)
                .unwrap()
                .clone()
        };
        assert_eq!(by_tick(21).stages[0], Stage::Calibration);
        assert_eq!(by_tick(21).raw_times, frames[20].raw_times);
        assert_eq!(
            by_tick(21).expected_values,
            Some(CAL.scales().values(&frames[20].raw_times).map(|v| v.raw()))
        );
        assert_eq!(by_tick(31).stages[0], Stage::Hash);
        assert_eq!(by_tick(41).stages, vec![Stage::Policy, Stage::Motors]);
        assert_eq!(by_tick(51).stages, vec![Stage::Motors]);
        assert_eq!(by_tick(6).stages, vec![Stage::Motors]);
        assert_eq!(by_tick(6).expected_motors, [0, 0]);
        assert!(r.to_string().contains("tick 41 at byte"));
    }

    /// `policy()` with every state's set widened to two or more actions.
    fn tied_policy() -> PolicyBlob {
        let p = policy();
        let mut sets = shared::ActionSets::new(StateHasher::Original);
        for (state, mask) in p.sets().masks() {
            let next = (mask.trailing_zeros() + 1 + u32::from(state.0 / 4 % 2)) % 4;
            sets.set(state, mask | 1 << next);
        }
        PolicyBlob::with_sets(*p.actions(), sets, p.provenance().clone()).unwrap()
    }

    #[test]
    fn replay_rechecks_every_decision_sampled_among_tied_actions() {
        let p = tied_policy();
        let mut frames = session(&p);
        // the robot drew: its generator moved on every frame
        assert!(frames.iter().all(|f| f.choice.is_some()));
        let r = report_of(&log_of(&frames), &p);
        assert_eq!((r.frames, r.diverged), (120, 0), "{r}");
        // another of the state's best actions than the generator's pick
        let i = 40;
        let mask = p.sets().mask(frames[i].state);
        let other = (0..4u8)
            .find(|&a| mask & (1 << a) != 0 && a != frames[i].action.0)
            .unwrap();
        frames[i].action = ActionId(other);
        // a generator that jumps (the draw itself agrees with its state)
        let j = 70;
        let mut jumped = ChoiceRng::from_state(frames[j].choice.unwrap() ^ 0x8000);
        frames[j].choice = Some(jumped.state());
        frames[j].action = jumped.pick(p.sets().mask(frames[j].state));
        // a tied state decided without a logged draw
        frames[90].choice = None;
        let r = report_of(&log_of(&frames), &p);
        let ticks: Vec<u32> = r.first_divergences.iter().map(|d| d.tick).collect();
        // 41: the wrong pick; 71: the jump; 72: the frame after the jump;
        // 91: no draw logged; 92: the generator moved without a logged draw
        assert_eq!(ticks, vec![41, 71, 72, 91, 92], "{r}");
        assert!(r
            .first_divergences
            .iter()
            .all(|d| d.stages[0] == Stage::Policy));
    }

    #[test]
    fn another_policy_diverges_at_the_policy_stage() {
        let p = policy();
        let frames = session(&p);
        let mut other = PolicyTable::new(StateHasher::Original);
        for s in 0..256u16 {
            other.set(State(s), ActionId(((s + 1) % 4) as u8));
        }
        let q = PolicyBlob::new(*p.actions(), other, p.provenance().clone()).unwrap();
        let r = report_of(&log_of(&frames), &q);
        assert_eq!(r.diverged, 120);
        assert_eq!(
            r.diverged_by_stage,
            StageCounts {
                policy: 120,
                motors: r.diverged_by_stage.motors,
                ..StageCounts::default()
            }
        );
    }

    #[test]
    fn training_visits_mark_untrained_states() {
        let p = policy();
        let frames = session(&p);
        let first = frames.iter().find(|f| f.policy_drove()).unwrap().state;
        let mut counts = vec![0u64; 256];
        counts[first.index()] = 9;
        let visits = TrainingVisits::new(StateHasher::Original, counts).unwrap();
        let r = replay(
            &log_file::parse(&log_of(&frames)).unwrap(),
            &p,
            Some(&visits),
            Default::default(),
        );
        let untrained = r.coverage.untrained.clone().unwrap();
        assert_eq!(untrained.len(), r.coverage.states - 1);
        assert!(!untrained.iter().any(|(s, _)| *s == first.0));
    }

    #[test]
    fn every_truncation_and_every_bit_flip_is_reported_and_skipped() {
        let p = policy();
        let frames: Vec<LogFrame> = session(&p).into_iter().take(6).collect();
        let bytes = log_of(&frames);
        for len in HEADER_LEN..bytes.len() {
            let r = report_of(&bytes[..len], &p);
            assert!(r.damaged <= 1 && r.diverged == 0, "{len}: {r}");
            assert!(r.frames + r.damaged == r.entries);
            if let Some(d) = r.first_damaged.first() {
                assert!(
                    d.error.contains("truncated") && d.offset >= HEADER_LEN as u64,
                    "{len}: {d:?}"
                );
            }
        }
        for i in HEADER_LEN..bytes.len() {
            for bit in 0..8 {
                let mut bad = bytes.clone();
                bad[i] ^= 1 << bit;
                let r = report_of(&bad, &p);
                assert_eq!(
                    r.diverged, 0,
                    "byte {i} bit {bit}: a damaged frame was taken for a real one"
                );
                assert!(r.frames >= 4 && r.damaged >= 1, "byte {i} bit {bit}: {r}");
            }
        }
        // Raw captures: the robot's own CRC finds flipped bits.
        let raw: Vec<u8> = frames
            .iter()
            .flat_map(|f| [encoded(f), vec![0]].concat())
            .collect();
        for i in 0..raw.len() {
            let mut bad = raw.clone();
            bad[i] ^= 0x04;
            let r = report_of(&bad, &p);
            assert_eq!(r.diverged, 0, "byte {i}");
            assert!(r.frames >= 4, "byte {i}: {r}");
        }
    }

    #[test]
    fn frames_of_another_version_are_counted_with_their_offset() {
        let p = policy();
        let frames = session(&p);
        let mut raw = vec![1u8, 0, 0, 0, 0, 0];
        let crc = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740).checksum(&raw[..4]);
        raw[4..].copy_from_slice(&crc.to_le_bytes());
        let mut v1 = vec![0u8; 16];
        let n = cobs::encode(&raw, &mut v1);
        let mut bytes = log_of(&frames[..2]);
        let offset = bytes.len() as u64;
        bytes.extend(encode_record(5, &v1[..n]));
        bytes.extend(&log_of(&frames[2..3])[HEADER_LEN..]);
        let r = report_of(&bytes, &p);
        assert_eq!((r.frames, r.damaged, r.other_version), (3, 1, 1));
        assert_eq!(r.first_damaged[0].offset, offset);
        assert!(
            r.first_damaged[0]
                .error
                .contains("version 1 is not supported"),
            "{:?}",
            r.first_damaged
        );
    }
}
