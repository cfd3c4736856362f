//! What `host replay` reports: divergences by stage, damaged entries,
//! modes, coverage, actions and faults, as text or JSON.

use super::odometry::RobotMotion;
use serde::Serialize;
use shared::{FieldCalibration, RunMode};
use std::fmt;

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

impl Stage {
    /// Every stage, in pipeline order.
    pub const ALL: [Stage; 4] = [
        Stage::Calibration,
        Stage::Hash,
        Stage::Policy,
        Stage::Motors,
    ];
}

/// Frames per run mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ModeCounts {
    /// Waiting for a button.
    pub idle: u64,
    /// Driving (by the policy, or stopped by a fault).
    pub driving: u64,
    /// Standing still, calibrating on the display's white and black screens.
    pub calibrating: u64,
}

impl ModeCounts {
    /// Counts one frame of `mode`.
    pub fn count(&mut self, mode: RunMode) {
        match mode {
            RunMode::Idle => self.idle += 1,
            RunMode::Driving => self.driving += 1,
            RunMode::Calibrating => self.calibrating += 1,
        }
    }
}

/// Diverged frames per stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct StageCounts {
    /// At the calibration stage.
    pub calibration: u64,
    /// At the hash stage.
    pub hash: u64,
    /// At the policy stage.
    pub policy: u64,
    /// At the motors stage.
    pub motors: u64,
}

impl StageCounts {
    /// The count of one stage.
    pub fn of(&self, stage: Stage) -> u64 {
        match stage {
            Stage::Calibration => self.calibration,
            Stage::Hash => self.hash,
            Stage::Policy => self.policy,
            Stage::Motors => self.motors,
        }
    }

    /// Counts one divergence at `stage`.
    pub fn count(&mut self, stage: Stage) {
        match stage {
            Stage::Calibration => self.calibration += 1,
            Stage::Hash => self.hash += 1,
            Stage::Policy => self.policy += 1,
            Stage::Motors => self.motors += 1,
        }
    }
}

/// A frame's logged results beside the recomputed ones, stage by stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameCheck {
    /// Byte offset of the frame's record or chunk in the file.
    pub offset: u64,
    /// The frame's tick.
    pub tick: u32,
    /// Every stage that diverged, pipeline order (the first is where it
    /// began); none when the frame agrees.
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
    /// Expected motor commands.
    pub expected_motors: [i16; 2],
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
    /// Decoded frames per mode.
    pub modes: ModeCounts,
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
    /// Diverged frames per stage.
    pub diverged_by_stage: StageCounts,
    /// The first [`LISTED`] divergences.
    pub first_divergences: Vec<FrameCheck>,
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
    /// Per robot: measured against intended motion per action, and the fit.
    pub motion: Vec<RobotMotion>,
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
        self.fmt_timeline(f)?;
        self.fmt_calibrations(f)?;
        self.fmt_divergences(f)?;
        self.fmt_coverage(f)?;
        self.fmt_faults(f)?;
        self.fmt_motion(f)
    }
}

impl ReplayReport {
    /// Source, ticks, modes and damaged entries.
    fn fmt_timeline(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "source: {}, {} entries, {} frames decoded",
            self.source, self.entries, self.frames
        )?;
        if let Some((first, last)) = self.ticks {
            write!(
                f,
                "ticks: {first}..{last}, {} missing, {} restarts",
                self.missing_ticks, self.restarts
            )?;
            match self.host_seconds {
                Some(s) => writeln!(f, ", {s:.1} s of host time")?,
                None => writeln!(f)?,
            }
        }
        let m = self.modes;
        writeln!(
            f,
            "modes: idle {}, driving {} (policy drove {}), calibrating {}",
            m.idle, m.driving, self.policy_drove, m.calibrating
        )?;
        writeln!(
            f,
            "damaged: {} (other format version: {})",
            self.damaged, self.other_version
        )?;
        for d in &self.first_damaged {
            writeln!(f, "  at byte {} ({} bytes): {}", d.offset, d.len, d.error)?;
        }
        Ok(())
    }

    /// The calibrations logged and how many frames they checked.
    fn fmt_calibrations(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
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
        Ok(())
    }

    /// Divergences per stage and the first ones in full.
    fn fmt_divergences(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let by_stage: Vec<String> = Stage::ALL
            .iter()
            .map(|s| format!("{s} {}", self.diverged_by_stage.of(*s)))
            .collect();
        writeln!(
            f,
            "divergences: {} frames ({})",
            self.diverged,
            by_stage.join(", ")
        )?;
        for d in &self.first_divergences {
            let stages: Vec<String> = d.stages.iter().map(|s| s.to_string()).collect();
            writeln!(
                f,
                "  tick {} at byte {}: {} diverged; {:?} faults {}; raw {:?} values {:?}{} blobs {:?}; state {} (expected {}), action {} (expected {}), motors {:?} (expected {:?})",
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
                d.expected_motors,
            )?;
        }
        Ok(())
    }

    /// States met (and untrained ones) and the action histogram.
    fn fmt_coverage(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.coverage;
        write!(
            f,
            "coverage: {} of {} states met while the policy drove",
            c.states, c.of
        )?;
        match &c.untrained {
            Some(u) => {
                let frames: u64 = u.iter().map(|(_, n)| n).sum();
                writeln!(
                    f,
                    "; {} never visited in training ({} frames)",
                    u.len(),
                    frames
                )?;
                if !u.is_empty() {
                    let list: Vec<String> = u
                        .iter()
                        .take(20)
                        .map(|(s, n)| format!("{s} ({n})"))
                        .collect();
                    writeln!(f, "  untrained states (frames): {}", list.join(", "))?;
                }
            }
            None => writeln!(f, " (pass --visits to compare with training)")?,
        }
        if !c.frames_per_state.is_empty() {
            let list: Vec<String> = c
                .frames_per_state
                .iter()
                .take(10)
                .map(|(s, n)| format!("{s} ({n})"))
                .collect();
            writeln!(f, "  most met states (frames): {}", list.join(", "))?;
        }
        let actions: Vec<String> = self
            .actions
            .iter()
            .enumerate()
            .map(|(a, n)| format!("{a}: {n} ({:.1}%)", percent(*n, self.policy_drove)))
            .collect();
        writeln!(f, "actions while the policy drove: {}", actions.join(", "))
    }

    /// Measured and intended motion per robot and action, and the fit.
    fn fmt_motion(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.motion.is_empty() {
            return writeln!(f, "motion: no period measured (the policy never drove between two consecutive frames)");
        }
        for r in &self.motion {
            writeln!(f, "motion of robot {} (wheel encoders; forward in units per step, turning in rad per step, + = right):", r.id)?;
            for a in &r.actions {
                writeln!(
                    f,
                    "  action {}: {} periods, forward {:.3} (intended {:.3}), turning {:+.4} (intended {:+.4})",
                    a.action, a.periods, a.forward, a.intended_forward, a.turn, a.intended_turn
                )?;
            }
            match r.fit {
                Some(fit) => writeln!(
                    f,
                    "  fit: wheel_speed_factor {:.4}, turn_bias {:+.5}",
                    fit.wheel_speed_factor, fit.turn_bias
                )?,
                None => writeln!(f, "  fit: none (no forward motion asked for)")?,
            }
        }
        Ok(())
    }

    /// Fault frames and episodes.
    fn fmt_faults(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "faults: {} frames", self.fault_frames)?;
        for c in self.faults.iter().filter(|c| c.frames > 0) {
            write!(
                f,
                "; {}: {} frames in {} episodes",
                c.fault, c.frames, c.episodes
            )?;
        }
        writeln!(f)?;
        for e in &self.first_fault_episodes {
            writeln!(
                f,
                "  {} ticks {}..{} ({} frames)",
                e.fault, e.first_tick, e.last_tick, e.frames
            )?;
        }
        Ok(())
    }
}
