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
//!    precomputes it) when the policy drove, a stop when idle or stopped by
//!    a fault; the calibration spin is not checked.
//!
//! It also reports state coverage (and, given training visit counts, the
//! states training never visited), the action histogram, faults and their
//! episodes, modes, tick gaps, and the damaged records and frames with their
//! byte offsets (skipped, never fatal).

use super::log_file::{Recording, SourceKind};
use super::visits::TrainingVisits;
use anyhow::{bail, Result};
use serde::Serialize;
use shared::{
    ActionId, Faults, FieldCalibration, LogFrame, MotorCommand, PolicyBlob, RobotProfile, RunMode, SensorReading, State,
};
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// Divergences, damaged entries and fault episodes listed in full (the rest
/// are counted).
pub const LISTED: usize = 10;

/// A step of the decision pipeline, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Raw times -> calibrated values.
    Calibration,
    /// Values and blob bits -> state.
    Hash,
    /// State -> action.
    Policy,
    /// Action, mode and faults -> motor commands.
    Motors,
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stage::Calibration => "calibration",
            Stage::Hash => "hash",
            Stage::Policy => "policy",
            Stage::Motors => "motors",
        })
    }
}

/// One frame whose logged decision differs from the recomputed one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Divergence {
    /// Byte offset of the frame's record or chunk in the file.
    pub offset: u64,
    /// The frame's tick.
    pub tick: u32,
    /// Every stage that diverged, pipeline order (the first is where it began).
    pub stages: Vec<Stage>,
    /// Mode.
    pub mode: RunMode,
    /// Fault flags.
    pub faults: u8,
    /// Raw RC times, left, mid, right (timer ticks).
    pub raw_times: [u16; 3],
    /// Logged calibrated values (raw Q1.15).
    pub values: [u16; 3],
    /// Recomputed values, when a calibration was known.
    pub expected_values: Option<[u16; 3]>,
    /// Blob bits: puck left, puck right, obstacle left, obstacle right.
    pub blobs: [bool; 4],
    /// Logged state.
    pub state: u16,
    /// Recomputed state.
    pub expected_state: u16,
    /// Logged action.
    pub action: u8,
    /// Recomputed action.
    pub expected_action: u8,
    /// Logged motor commands, left and right.
    pub motors: [i16; 2],
    /// Expected motor commands (none for a calibration spin or an action
    /// outside the policy's table).
    pub expected_motors: Option<[i16; 2]>,
}

/// A damaged record, or a frame that does not decode.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Damaged {
    /// Byte offset in the file.
    pub offset: u64,
    /// Length in the file.
    pub len: usize,
    /// What is wrong.
    pub error: String,
}

/// A run of consecutive frames with one fault flag set.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct FaultEpisode {
    /// The flag's name.
    pub fault: &'static str,
    /// Tick of its first frame.
    pub first_tick: u32,
    /// Tick of its last frame.
    pub last_tick: u32,
    /// Frames in the run.
    pub frames: u64,
}

/// Frames and episodes of one fault flag.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct FaultCount {
    /// The flag's name.
    pub fault: &'static str,
    /// Frames with it set.
    pub frames: u64,
    /// Runs of consecutive frames with it set.
    pub episodes: u64,
}

/// States the robot met while the policy drove.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Coverage {
    /// Distinct states.
    pub states: usize,
    /// Of the hasher's states.
    pub of: usize,
    /// Frames per state, most frequent first.
    pub frames_per_state: Vec<(u16, u64)>,
    /// States met that training never visited, with frames on each (only
    /// given training visits).
    pub untrained: Option<Vec<(u16, u64)>>,
}

/// Everything `host replay` found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReplayReport {
    /// Recorded log or raw capture.
    pub source: String,
    /// Records (or chunks) in the file.
    pub entries: u64,
    /// Frames decoded.
    pub frames: u64,
    /// Damaged records and undecodable frames.
    pub damaged: u64,
    /// The first [`LISTED`] of them.
    pub first_damaged: Vec<Damaged>,
    /// Frames of another log format version (counted in `damaged` too).
    pub other_version: u64,
    /// Decoded frames per mode: idle, driving, calibrating.
    pub modes: [u64; 3],
    /// Frames in which the policy drove the motors.
    pub policy_drove: u64,
    /// First and last tick.
    pub ticks: Option<(u32, u32)>,
    /// Ticks missing between consecutive frames (lost frames).
    pub missing_ticks: u64,
    /// Times the tick went backwards (the robot restarted).
    pub restarts: u64,
    /// Host seconds from the first to the last record (recorded logs).
    pub host_seconds: Option<f64>,
    /// Frames whose calibrated values could be checked (a calibration was known).
    pub calibration_checked: u64,
    /// Calibrations seen in the log that differ from the previous one.
    pub calibrations: Vec<FieldCalibration>,
    /// Frames with any divergence.
    pub diverged: u64,
    /// Diverged frames per stage (calibration, hash, policy, motors).
    pub diverged_by_stage: [u64; 4],
    /// The first [`LISTED`] divergences.
    pub first_divergences: Vec<Divergence>,
    /// States met while the policy drove.
    pub coverage: Coverage,
    /// Frames per action while the policy drove.
    pub actions: Vec<u64>,
    /// Frames with any fault flag.
    pub fault_frames: u64,
    /// Per fault flag.
    pub faults: Vec<FaultCount>,
    /// The first [`LISTED`] fault episodes, in order of their start.
    pub first_fault_episodes: Vec<FaultEpisode>,
}

/// Recomputes every frame's decision with `policy` and summarises the run.
/// `visits`, if given, must be for the policy's hasher (the caller checks).
pub fn replay(recording: &Recording, policy: &PolicyBlob, visits: Option<&TrainingVisits>) -> ReplayReport {
    let mut r = Replayer::new(policy);
    for entry in &recording.entries {
        match &entry.frame {
            Err(e) => r.damaged(entry.offset, entry.len, e.to_string()),
            Ok(bytes) => match LogFrame::decode(bytes) {
                Ok(frame) => r.frame(entry.offset, &frame, entry.host_time_us),
                Err(e) => {
                    if matches!(e, shared::LogError::UnsupportedVersion(_)) {
                        r.other_version += 1;
                    }
                    r.damaged(entry.offset, entry.len, format!("frame: {e}"));
                }
            },
        }
    }
    r.finish(recording, visits)
}

/// Reads the files and replays: the log (recorded or raw), the policy blob
/// and optional training visits, which must be for the policy's hasher.
pub fn replay_files(log: &Path, policy: &Path, visits: Option<&Path>) -> Result<ReplayReport> {
    let blob = crate::policy_file::read(policy)?;
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
    let recording = super::log_file::read(log)?;
    Ok(replay(&recording, &blob, training.as_ref()))
}

struct Replayer<'a> {
    policy: &'a PolicyBlob,
    commands: Vec<MotorCommand>,
    calibration: Option<FieldCalibration>,
    calibrations: Vec<FieldCalibration>,
    calibration_checked: u64,
    damaged: u64,
    first_damaged: Vec<Damaged>,
    other_version: u64,
    frames: u64,
    modes: [u64; 3],
    policy_drove: u64,
    ticks: Option<(u32, u32)>,
    last_tick: Option<u32>,
    missing_ticks: u64,
    restarts: u64,
    host_times: Option<(u64, u64)>,
    diverged: u64,
    diverged_by_stage: [u64; 4],
    first_divergences: Vec<Divergence>,
    states: BTreeMap<u16, u64>,
    actions: Vec<u64>,
    fault_frames: u64,
    faults: Vec<FaultCount>,
    open_episodes: [Option<FaultEpisode>; 4],
    first_fault_episodes: Vec<FaultEpisode>,
}

impl<'a> Replayer<'a> {
    fn new(policy: &'a PolicyBlob) -> Replayer<'a> {
        let actions = policy.actions();
        let commands = actions.angular_speeds().iter().map(|w| RobotProfile::ZUMO.mix(actions.forward_speed(), *w)).collect();
        Replayer {
            policy,
            commands,
            calibration: None,
            calibrations: Vec::new(),
            calibration_checked: 0,
            damaged: 0,
            first_damaged: Vec::new(),
            other_version: 0,
            frames: 0,
            modes: [0; 3],
            policy_drove: 0,
            ticks: None,
            last_tick: None,
            missing_ticks: 0,
            restarts: 0,
            host_times: None,
            diverged: 0,
            diverged_by_stage: [0; 4],
            first_divergences: Vec::new(),
            states: BTreeMap::new(),
            actions: vec![0; actions.len()],
            fault_frames: 0,
            faults: Faults::NAMED.iter().map(|(_, name)| FaultCount { fault: name, frames: 0, episodes: 0 }).collect(),
            open_episodes: [None, None, None, None],
            first_fault_episodes: Vec::new(),
        }
    }

    fn damaged(&mut self, offset: u64, len: usize, error: String) {
        self.damaged += 1;
        if self.first_damaged.len() < LISTED {
            self.first_damaged.push(Damaged { offset, len, error });
        }
    }

    fn frame(&mut self, offset: u64, f: &LogFrame, host_time_us: Option<u64>) {
        self.frames += 1;
        if let Some(t) = host_time_us {
            self.host_times = Some(self.host_times.map_or((t, t), |(first, _)| (first, t)));
        }
        self.ticks = Some(self.ticks.map_or((f.tick, f.tick), |(first, _)| (first, f.tick)));
        if let Some(last) = self.last_tick {
            if f.tick > last {
                self.missing_ticks += u64::from(f.tick - last - 1);
            } else {
                self.restarts += 1;
            }
        }
        self.last_tick = Some(f.tick);
        self.modes[match f.mode {
            RunMode::Idle => 0,
            RunMode::Driving => 1,
            RunMode::Calibrating => 2,
        }] += 1;
        if let Some(c) = f.calibration {
            if self.calibrations.last() != Some(&c) {
                self.calibrations.push(c);
            }
            self.calibration = Some(c);
        }
        self.check(offset, f);
        if f.policy_drove() {
            self.policy_drove += 1;
            *self.states.entry(f.state.0).or_default() += 1;
            if let Some(n) = self.actions.get_mut(f.action.index()) {
                *n += 1;
            }
        }
        self.faults_of(f);
    }

    fn check(&mut self, offset: u64, f: &LogFrame) {
        let mut stages = Vec::new();
        let expected_values = self.calibration.map(|c| c.scales().values(&f.raw_times));
        if let Some(v) = expected_values {
            self.calibration_checked += 1;
            if v != f.values {
                stages.push(Stage::Calibration);
            }
        }
        let reading = SensorReading {
            left: f.values[0],
            mid: f.values[1],
            right: f.values[2],
            puck_left: f.blobs.puck_left,
            puck_right: f.blobs.puck_right,
            obstacle_left: f.blobs.obstacle_left,
            obstacle_right: f.blobs.obstacle_right,
        };
        let expected_state = self.policy.hasher().hash(&reading);
        if expected_state != f.state {
            stages.push(Stage::Hash);
        }
        let in_range = f.state.index() < self.policy.hasher().num_states();
        let expected_action = if in_range { self.policy.table().action(f.state) } else { ActionId(u8::MAX) };
        if expected_action != f.action {
            stages.push(Stage::Policy);
        }
        let expected_motors = match f.mode {
            RunMode::Calibrating => None,
            _ if f.policy_drove() => self.commands.get(f.action.index()).copied(),
            _ => Some(MotorCommand::default()),
        };
        let motors_ok = match expected_motors {
            Some(m) => m == f.motors,
            None => f.mode == RunMode::Calibrating,
        };
        if !motors_ok {
            stages.push(Stage::Motors);
        }
        if stages.is_empty() {
            return;
        }
        self.diverged += 1;
        for s in &stages {
            self.diverged_by_stage[*s as usize] += 1;
        }
        if self.first_divergences.len() < LISTED {
            self.first_divergences.push(Divergence {
                offset,
                tick: f.tick,
                stages,
                mode: f.mode,
                faults: f.faults.0,
                raw_times: f.raw_times,
                values: f.values.map(|v| v.raw()),
                expected_values: expected_values.map(|v| v.map(|x| x.raw())),
                blobs: [f.blobs.puck_left, f.blobs.puck_right, f.blobs.obstacle_left, f.blobs.obstacle_right],
                state: f.state.0,
                expected_state: expected_state.0,
                action: f.action.0,
                expected_action: expected_action.0,
                motors: [f.motors.left, f.motors.right],
                expected_motors: expected_motors.map(|m| [m.left, m.right]),
            });
        }
    }

    fn faults_of(&mut self, f: &LogFrame) {
        if !f.faults.is_empty() {
            self.fault_frames += 1;
        }
        for (i, (flag, name)) in Faults::NAMED.iter().enumerate() {
            if f.faults.contains(*flag) {
                self.faults[i].frames += 1;
                match &mut self.open_episodes[i] {
                    Some(e) => {
                        e.last_tick = f.tick;
                        e.frames += 1;
                    }
                    open @ None => {
                        self.faults[i].episodes += 1;
                        *open = Some(FaultEpisode { fault: name, first_tick: f.tick, last_tick: f.tick, frames: 1 });
                    }
                }
            } else if let Some(e) = self.open_episodes[i].take() {
                self.close_episode(e);
            }
        }
    }

    fn close_episode(&mut self, e: FaultEpisode) {
        // Episodes close in end order; keep the first LISTED by start.
        self.first_fault_episodes.push(e);
        self.first_fault_episodes.sort_by_key(|e| e.first_tick);
        self.first_fault_episodes.truncate(LISTED);
    }

    fn finish(mut self, recording: &Recording, visits: Option<&TrainingVisits>) -> ReplayReport {
        for i in 0..self.open_episodes.len() {
            if let Some(e) = self.open_episodes[i].take() {
                self.close_episode(e);
            }
        }
        let mut frames_per_state: Vec<(u16, u64)> = self.states.iter().map(|(s, n)| (*s, *n)).collect();
        frames_per_state.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let untrained = visits.map(|v| frames_per_state.iter().filter(|(s, _)| v.of(State(*s)) == 0).copied().collect());
        ReplayReport {
            source: recording.kind.to_string(),
            entries: recording.entries.len() as u64,
            frames: self.frames,
            damaged: self.damaged,
            first_damaged: self.first_damaged,
            other_version: self.other_version,
            modes: self.modes,
            policy_drove: self.policy_drove,
            ticks: self.ticks,
            missing_ticks: self.missing_ticks,
            restarts: self.restarts,
            host_seconds: match (recording.kind, self.host_times) {
                (SourceKind::Recorded, Some((first, last))) => Some(last.saturating_sub(first) as f64 / 1e6),
                _ => None,
            },
            calibration_checked: self.calibration_checked,
            calibrations: self.calibrations,
            diverged: self.diverged,
            diverged_by_stage: self.diverged_by_stage,
            first_divergences: self.first_divergences,
            coverage: Coverage {
                states: frames_per_state.len(),
                of: self.policy.hasher().num_states(),
                frames_per_state,
                untrained,
            },
            actions: self.actions,
            fault_frames: self.fault_frames,
            faults: self.faults,
            first_fault_episodes: self.first_fault_episodes,
        }
    }
}

fn percent(part: u64, whole: u64) -> f64 {
    if whole == 0 {
        0.0
    } else {
        part as f64 * 100.0 / whole as f64
    }
}

impl fmt::Display for ReplayReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "source: {}, {} entries, {} frames decoded", self.source, self.entries, self.frames)?;
        if let Some((first, last)) = self.ticks {
            write!(f, "ticks: {first}..{last}, {} missing, {} restarts", self.missing_ticks, self.restarts)?;
            match self.host_seconds {
                Some(s) => writeln!(f, ", {s:.1} s of host time")?,
                None => writeln!(f)?,
            }
        }
        writeln!(
            f,
            "modes: idle {}, driving {} (policy drove {}), calibrating {}",
            self.modes[0], self.modes[1], self.policy_drove, self.modes[2]
        )?;
        writeln!(f, "damaged: {} (other format version: {})", self.damaged, self.other_version)?;
        for d in &self.first_damaged {
            writeln!(f, "  at byte {} ({} bytes): {}", d.offset, d.len, d.error)?;
        }
        writeln!(
            f,
            "calibration: {} distinct logged, values checked in {} of {} frames",
            self.calibrations.len(),
            self.calibration_checked,
            self.frames
        )?;
        for c in &self.calibrations {
            let r = c.ranges;
            writeln!(
                f,
                "  bright..dark ticks: left {}..{}, mid {}..{}, right {}..{}",
                r[0].bright, r[0].dark, r[1].bright, r[1].dark, r[2].bright, r[2].dark
            )?;
        }
        writeln!(
            f,
            "divergences: {} frames (calibration {}, hash {}, policy {}, motors {})",
            self.diverged, self.diverged_by_stage[0], self.diverged_by_stage[1], self.diverged_by_stage[2], self.diverged_by_stage[3]
        )?;
        for d in &self.first_divergences {
            let stages: Vec<String> = d.stages.iter().map(|s| s.to_string()).collect();
            writeln!(
                f,
                "  tick {} at byte {}: {} diverged; {:?} faults {}; raw {:?} values {:?}{} blobs {:?}; state {} (expected {}), action {} (expected {}), motors {:?} (expected {})",
                d.tick,
                d.offset,
                stages.join(", "),
                d.mode,
                d.faults,
                d.raw_times,
                d.values,
                d.expected_values.map(|v| format!(" (expected {v:?})")).unwrap_or_default(),
                d.blobs,
                d.state,
                d.expected_state,
                d.action,
                d.expected_action,
                d.motors,
                d.expected_motors.map_or("no check".to_string(), |m| format!("{m:?}")),
            )?;
        }
        let c = &self.coverage;
        write!(f, "coverage: {} of {} states met while the policy drove", c.states, c.of)?;
        match &c.untrained {
            Some(u) => {
                let frames: u64 = u.iter().map(|(_, n)| n).sum();
                writeln!(f, "; {} never visited in training ({} frames)", u.len(), frames)?;
                if !u.is_empty() {
                    let list: Vec<String> = u.iter().take(20).map(|(s, n)| format!("{s} ({n})")).collect();
                    writeln!(f, "  untrained states (frames): {}", list.join(", "))?;
                }
            }
            None => writeln!(f, " (pass --visits to compare with training)")?,
        }
        if !c.frames_per_state.is_empty() {
            let list: Vec<String> = c.frames_per_state.iter().take(10).map(|(s, n)| format!("{s} ({n})")).collect();
            writeln!(f, "  most met states (frames): {}", list.join(", "))?;
        }
        let actions: Vec<String> = self
            .actions
            .iter()
            .enumerate()
            .map(|(a, n)| format!("{a}: {n} ({:.1}%)", percent(*n, self.policy_drove)))
            .collect();
        writeln!(f, "actions while the policy drove: {}", actions.join(", "))?;
        write!(f, "faults: {} frames", self.fault_frames)?;
        for c in self.faults.iter().filter(|c| c.frames > 0) {
            write!(f, "; {}: {} frames in {} episodes", c.fault, c.frames, c.episodes)?;
        }
        writeln!(f)?;
        for e in &self.first_fault_episodes {
            writeln!(f, "  {} ticks {}..{} ({} frames)", e.fault, e.first_tick, e.last_tick, e.frames)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::log_file::{self, encode_record, HEADER_LEN, MAGIC, VERSION};
    use shared::{ActionTable, BlobSummary, FieldValue, PolicyTable, Provenance, SensorRange, StateHasher};

    const CAL: FieldCalibration = FieldCalibration { ranges: [SensorRange { bright: 40, dark: 440 }; 3] };

    fn policy() -> PolicyBlob {
        let mut table = PolicyTable::new(StateHasher::Original);
        for s in 0..256u16 {
            table.set(State(s), ActionId((s % 4) as u8));
        }
        let actions = ActionTable::new(&[0.0, 0.3, -0.3, 0.15], 2.0).unwrap();
        PolicyBlob::new(actions, table, Provenance::new("annulus", "test", 0, 0).unwrap()).unwrap()
    }

    /// A frame as the firmware would log it for these raw times and blobs.
    fn firmware_frame(p: &PolicyBlob, tick: u32, mode: RunMode, faults: Faults, raw: [u16; 3], puck_left: bool) -> LogFrame {
        let values = CAL.scales().values(&raw);
        let blobs = BlobSummary { puck_left, ..BlobSummary::default() };
        let reading = SensorReading { left: values[0], mid: values[1], right: values[2], puck_left, ..SensorReading::default() };
        let state = p.hasher().hash(&reading);
        let action = p.table().action(state);
        let mut f = LogFrame { tick, mode, faults, raw_times: raw, values, blobs, blocks: u8::from(puck_left), state, action, ..LogFrame::default() };
        if f.policy_drove() {
            f.motors = RobotProfile::ZUMO.mix(2.0, p.actions().angular_speeds()[action.index()]);
        }
        f.calibration = (tick % 50 == 1).then_some(CAL);
        f
    }

    fn session(p: &PolicyBlob) -> Vec<LogFrame> {
        let mut frames = Vec::new();
        for tick in 1..=120u32 {
            let mode = if tick <= 10 { RunMode::Idle } else { RunMode::Driving };
            let faults = if (60..65).contains(&tick) { Faults::CAMERA_SILENT } else { Faults::NONE };
            let raw = [40 + (tick * 7 % 400) as u16, 40 + (tick * 13 % 400) as u16, 40 + (tick * 3 % 400) as u16];
            frames.push(firmware_frame(p, tick, mode, faults, raw, tick % 3 == 0));
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
        replay(&log_file::parse(bytes).unwrap(), p, None)
    }

    #[test]
    fn a_faithful_robot_has_no_divergences_and_its_run_is_summarised() {
        let p = policy();
        let frames = session(&p);
        let r = report_of(&log_of(&frames), &p);
        assert_eq!((r.frames, r.damaged, r.diverged), (120, 0, 0), "{r}");
        assert_eq!(r.modes, [10, 110, 0]);
        assert_eq!(r.policy_drove, 105);
        assert_eq!(r.calibration_checked, 120);
        assert_eq!(r.calibrations, vec![CAL]);
        assert_eq!((r.ticks, r.missing_ticks, r.restarts), (Some((1, 120)), 0, 0));
        assert!(r.host_seconds.is_some_and(|s| (s - 2.38).abs() < 1e-9), "{:?}", r.host_seconds);
        let mut actions = vec![0u64; 4];
        let mut states = BTreeMap::new();
        for f in frames.iter().filter(|f| f.policy_drove()) {
            actions[f.action.index()] += 1;
            *states.entry(f.state.0).or_insert(0u64) += 1;
        }
        assert_eq!(r.actions, actions);
        assert_eq!(r.coverage.states, states.len());
        assert_eq!(r.faults[2], FaultCount { fault: "camera silent", frames: 5, episodes: 1 });
        assert_eq!(r.first_fault_episodes, vec![FaultEpisode { fault: "camera silent", first_tick: 60, last_tick: 64, frames: 5 }]);
        let text = r.to_string();
        assert!(text.contains("divergences: 0 frames") && text.contains("camera silent: 5 frames in 1 episodes"), "{text}");
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
        frames[5].motors = MotorCommand { left: 100, right: 100 }; // idle but moving
        let r = report_of(&log_of(&frames), &p);
        assert_eq!(r.diverged, 5, "{r}");
        let by_tick = |t: u32| r.first_divergences.iter().find(|d| d.tick == t).unwrap().clone();
        assert_eq!(by_tick(21).stages[0], Stage::Calibration);
        assert_eq!(by_tick(21).raw_times, frames[20].raw_times);
        assert_eq!(by_tick(21).expected_values, Some(CAL.scales().values(&frames[20].raw_times).map(|v| v.raw())));
        assert_eq!(by_tick(31).stages[0], Stage::Hash);
        assert_eq!(by_tick(41).stages, vec![Stage::Policy, Stage::Motors]);
        assert_eq!(by_tick(51).stages, vec![Stage::Motors]);
        assert_eq!(by_tick(6).stages, vec![Stage::Motors]);
        assert_eq!(by_tick(6).expected_motors, Some([0, 0]));
        assert!(r.to_string().contains("tick 41 at byte"));
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
        assert_eq!(r.diverged_by_stage[..3], [0, 0, 120]);
    }

    #[test]
    fn training_visits_mark_untrained_states() {
        let p = policy();
        let frames = session(&p);
        let first = frames.iter().find(|f| f.policy_drove()).unwrap().state;
        let mut counts = vec![0u64; 256];
        counts[first.index()] = 9;
        let visits = TrainingVisits::new(StateHasher::Original, counts).unwrap();
        let r = replay(&log_file::parse(&log_of(&frames)).unwrap(), &p, Some(&visits));
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
                assert!(d.error.contains("truncated") && d.offset >= HEADER_LEN as u64, "{len}: {d:?}");
            }
        }
        for i in HEADER_LEN..bytes.len() {
            for bit in 0..8 {
                let mut bad = bytes.clone();
                bad[i] ^= 1 << bit;
                let r = report_of(&bad, &p);
                assert_eq!(r.diverged, 0, "byte {i} bit {bit}: a damaged frame was taken for a real one");
                assert!(r.frames >= 4 && r.damaged >= 1, "byte {i} bit {bit}: {r}");
            }
        }
        // Raw captures: the robot's own CRC finds flipped bits.
        let raw: Vec<u8> = frames.iter().flat_map(|f| [encoded(f), vec![0]].concat()).collect();
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
        assert!(r.first_damaged[0].error.contains("version 1 is not supported"), "{:?}", r.first_damaged);
    }
}
