//! How the robot really moved: the wheel encoder counts each log frame
//! carries (`shared::LogFrame::encoder_counts`, the period before the
//! frame) against what the policy's action asked for in that period, per
//! robot and per action, and the fit the robot sensor model reads: each
//! robot's `wheel_speed_factor` and `turn_bias`.
//!
//! A frame's counts belong to the frame before it (its motor commands drove
//! during those 20 ms) when the two are consecutive ticks of the same
//! robot and the policy drove in the earlier one. The commands' intended
//! unicycle speeds are `shared::RobotProfile::ZUMO.unicycle` of the logged
//! commands (the action table's speeds, slowed like the firmware's mix if
//! a track saturated). Measured: each track's travel is counts /
//! [`OdometrySettings::counts_per_mm`]; forward = the tracks' mean, in
//! simulator units of [`OdometrySettings::mm_per_unit`]; turning = their
//! difference / [`OdometrySettings::track_mm`], radians per control step,
//! positive = right (clockwise from above, the simulator's sign).
//!
//! The fit: `wheel_speed_factor` = the measured forward travel over the
//! intended one, summed over every interval (dimensionless, 1.0 = as
//! intended); `turn_bias` = per action, the mean measured turning rate
//! minus the intended one, averaged over the actions met (radians per
//! step, positive = right). Intervals include the motors' acceleration
//! after an action change.

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use shared::{LogFrame, RobotProfile};
use sim::base::ranges;
use std::collections::BTreeMap;
use std::path::Path;

/// Units and geometry that turn counts into simulator speeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometrySettings {
    /// Millimetres per simulator unit (a tenth of the robot radius): 6.5 for
    /// the Zumo in its 65 mm skirt on the TV arena.
    pub mm_per_unit: f64,
    /// Encoder counts per millimetre of track travel: 909.7 counts per
    /// sprocket revolution of 119 mm on 75:1 motors
    /// (`../shared/docs/hardware.md` section 9).
    pub counts_per_mm: f64,
    /// Distance between the tracks' centre lines, mm.
    pub track_mm: f64,
}

impl OdometrySettings {
    /// What a period's encoder counts (left, right) say the robot did:
    /// forward travel in simulator units and turning in radians, positive =
    /// right.
    pub fn travel(&self, counts: [i16; 2]) -> (f64, f64) {
        let [left, right] = counts.map(|c| f64::from(c) / self.counts_per_mm);
        (
            (left + right) / 2.0 / self.mm_per_unit,
            (left - right) / self.track_mm,
        )
    }
}

impl Default for OdometrySettings {
    fn default() -> OdometrySettings {
        OdometrySettings {
            mm_per_unit: 6.5,
            counts_per_mm: 909.7 / 119.0,
            track_mm: 85.0,
        }
    }
}

/// One action's measured and intended motion over a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ActionMotion {
    /// The action.
    pub action: u8,
    /// Control periods measured.
    pub periods: u64,
    /// Mean measured forward speed, units per step.
    pub forward: f64,
    /// Mean intended forward speed, units per step.
    pub intended_forward: f64,
    /// Mean measured turning rate, radians per step, positive = right.
    pub turn: f64,
    /// Mean intended turning rate.
    pub intended_turn: f64,
}

/// One robot's fit, in the file format the robot sensor model reads.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotFit {
    /// The robot's id (`host flash --robot-id`).
    pub id: u8,
    /// Measured forward speed over the intended one (1.0 = as intended).
    pub wheel_speed_factor: f64,
    /// Measured minus intended turning rate, radians per step, positive =
    /// right, mean over actions.
    pub turn_bias: f64,
}

/// A robot's motion per action and its fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotMotion {
    /// The robot's id.
    pub id: u8,
    /// Per action met, in action order.
    pub actions: Vec<ActionMotion>,
    /// The fit, when the robot moved forward in some measured period.
    pub fit: Option<RobotFit>,
}

#[derive(Clone, Copy, Debug, Default)]
struct Sums {
    periods: u64,
    forward: f64,
    intended_forward: f64,
    turn: f64,
    intended_turn: f64,
}

/// Collects measured periods frame by frame.
#[derive(Clone, Debug, Default)]
pub struct OdometryTracker {
    settings: OdometrySettings,
    previous: Option<LogFrame>,
    sums: BTreeMap<(u8, u8), Sums>,
}

impl OdometryTracker {
    /// A tracker with `settings`.
    pub fn new(settings: OdometrySettings) -> OdometryTracker {
        OdometryTracker {
            settings,
            previous: None,
            sums: BTreeMap::new(),
        }
    }

    /// Adds one decoded frame, in log order.
    pub fn frame(&mut self, f: &LogFrame) {
        if let Some(p) = self.previous.replace(*f) {
            if f.tick == p.tick.wrapping_add(1) && f.robot_id == p.robot_id && p.policy_drove() {
                self.add(&p, f.encoder_counts);
            }
        }
    }

    fn add(&mut self, p: &LogFrame, counts: [i16; 2]) {
        let s = self.settings;
        let (intended_forward, intended_turn) = RobotProfile::ZUMO.unicycle(p.motors);
        let (forward, turn) = s.travel(counts);
        let sums = self.sums.entry((p.robot_id, p.action.0)).or_default();
        sums.periods += 1;
        sums.forward += forward;
        sums.turn += turn;
        sums.intended_forward += f64::from(intended_forward);
        sums.intended_turn += f64::from(intended_turn);
    }

    /// Every robot's motion and fit, by id.
    pub fn finish(&self) -> Vec<RobotMotion> {
        let mut robots: BTreeMap<u8, Vec<(u8, Sums)>> = BTreeMap::new();
        for ((id, action), sums) in &self.sums {
            robots.entry(*id).or_default().push((*action, *sums));
        }
        robots
            .into_iter()
            .map(|(id, actions)| {
                let n = |s: &Sums| s.periods as f64;
                let motion: Vec<ActionMotion> = actions
                    .iter()
                    .map(|(action, s)| ActionMotion {
                        action: *action,
                        periods: s.periods,
                        forward: s.forward / n(s),
                        intended_forward: s.intended_forward / n(s),
                        turn: s.turn / n(s),
                        intended_turn: s.intended_turn / n(s),
                    })
                    .collect();
                let intended: f64 = actions.iter().map(|(_, s)| s.intended_forward).sum();
                let measured: f64 = actions.iter().map(|(_, s)| s.forward).sum();
                let fit = (intended > 0.0).then(|| RobotFit {
                    id,
                    wheel_speed_factor: measured / intended,
                    turn_bias: motion.iter().map(|a| a.turn - a.intended_turn).sum::<f64>()
                        / motion.len() as f64,
                });
                RobotMotion {
                    id,
                    actions: motion,
                    fit,
                }
            })
            .collect()
    }
}

/// The fit file: `{"robots": [{"id": N, "wheel_speed_factor": f, "turn_bias": f}, ...]}`,
/// one entry per robot, by id.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitFile {
    /// Every robot's fit.
    pub robots: Vec<RobotFit>,
}

impl FitFile {
    /// Adds or replaces the entries of `fits`' robots, keeping the others; by id.
    pub fn merge(&mut self, fits: impl IntoIterator<Item = RobotFit>) {
        for fit in fits {
            self.robots.retain(|r| r.id != fit.id);
            self.robots.push(fit);
        }
        self.robots.sort_by_key(|r| r.id);
    }
}

/// Writes the fits of `robots` into the fit file at `path`: an existing
/// file keeps its other robots' entries (so the logs of a whole swarm merge
/// into one file); atomically. Fails, naming the file, when the existing
/// file is not a fit file or no robot has a fit.
pub fn merge_into_file(path: &Path, robots: &[RobotMotion]) -> Result<FitFile> {
    let fits: Vec<RobotFit> = robots.iter().filter_map(|r| r.fit).collect();
    if fits.is_empty() {
        bail!(
            "no fit for {}: the log has no period in which the policy drove the robot forward with encoder counts              (log format version {} or later, driving)",
            path.display(),
            LogFrame::VERSION
        );
    }
    let mut file = match ranges::read_file(path, &ranges::SETTINGS_FILE) {
        Ok(bytes) => serde_json::from_slice::<FitFile>(&bytes).with_context(|| {
            format!(
                "{} exists but is not a fit file ({{\"robots\": [...]}}); nothing was written",
                path.display()
            )
        })?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => FitFile::default(),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    file.merge(fits);
    let json = serde_json::to_string_pretty(&file).context("cannot encode the fit")? + "\n";
    crate::atomic::write(path, json.as_bytes())?;
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::{ActionId, MotorCommand, RunMode};

    fn frame(tick: u32, action: u8, motors: MotorCommand, counts: [i16; 2]) -> LogFrame {
        LogFrame {
            tick,
            mode: RunMode::Driving,
            action: ActionId(action),
            motors,
            encoder_counts: counts,
            choice: None,
            robot_id: 3,
            ..LogFrame::default()
        }
    }

    #[test]
    fn counts_are_measured_against_the_command_that_drove_them() {
        let s = OdometrySettings {
            mm_per_unit: 5.0,
            counts_per_mm: 2.0,
            track_mm: 100.0,
        };
        let mut t = OdometryTracker::new(s);
        let straight = MotorCommand {
            left: 150,
            right: 150,
        }; // 2 units/step
           // 2 units x 5 mm x 2 counts/mm = 20 counts per track: as intended; then 10 % slow.
           // A frame's counts are the period before it: the previous frame's action.
        t.frame(&frame(1, 0, straight, [0, 0]));
        t.frame(&frame(2, 0, straight, [20, 20]));
        t.frame(&frame(3, 1, straight, [18, 18]));
        t.frame(&frame(4, 1, straight, [20, 20]));
        // A gap in the ticks: the counts of tick 6 are not tick 4's.
        t.frame(&frame(6, 1, straight, [99, 0]));
        let robots = t.finish();
        assert_eq!(robots.len(), 1);
        let a = &robots[0].actions;
        assert_eq!(
            (a[0].action, a[0].periods, a[0].intended_forward),
            (0, 2, 2.0)
        );
        assert!((a[0].forward - 1.9).abs() < 1e-9 && a[0].turn == 0.0);
        assert_eq!((a[1].action, a[1].periods, a[1].forward), (1, 1, 2.0));
        let fit = robots[0].fit.unwrap();
        assert_eq!(fit.id, 3);
        assert!((fit.wheel_speed_factor - 5.8 / 6.0).abs() < 1e-9);
        assert_eq!(fit.turn_bias, 0.0);
    }

    #[test]
    fn a_right_drift_is_a_positive_turn_bias_and_merging_keeps_other_robots() {
        let s = OdometrySettings {
            mm_per_unit: 5.0,
            counts_per_mm: 2.0,
            track_mm: 100.0,
        };
        let mut t = OdometryTracker::new(s);
        let straight = MotorCommand {
            left: 150,
            right: 150,
        };
        t.frame(&frame(1, 0, straight, [0, 0]));
        // Left 10 mm further than right: 0.1 rad to the right.
        t.frame(&frame(2, 0, straight, [30, 10]));
        let fit = t.finish()[0].fit.unwrap();
        assert!((fit.turn_bias - 0.1).abs() < 1e-9, "{fit:?}");
        let mut file = FitFile {
            robots: vec![
                RobotFit {
                    id: 9,
                    wheel_speed_factor: 1.1,
                    turn_bias: 0.0,
                },
                RobotFit { id: 3, ..fit },
            ],
        };
        file.merge([RobotFit {
            turn_bias: 0.2,
            ..fit
        }]);
        assert_eq!(
            file.robots
                .iter()
                .map(|r| (r.id, r.turn_bias))
                .collect::<Vec<_>>(),
            [(3, 0.2), (9, 0.0)]
        );
        let json = serde_json::to_string(&file).unwrap();
        assert!(
            json.starts_with(r#"{"robots":[{"id":3,"wheel_speed_factor":"#),
            "{json}"
        );

        // Into a file: a new one, then merged, then a foreign file refused by name.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.json");
        let motion = |id: u8| RobotMotion {
            id,
            actions: Vec::new(),
            fit: Some(RobotFit { id, ..fit }),
        };
        merge_into_file(&path, &[motion(3)]).unwrap();
        let merged = merge_into_file(&path, &[motion(1)]).unwrap();
        assert_eq!(
            merged.robots.iter().map(|r| r.id).collect::<Vec<_>>(),
            [1, 3]
        );
        let read: FitFile = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        assert_eq!(read, merged);
        std::fs::write(&path, "[1, 2]").unwrap();
        let e = format!("{:#}", merge_into_file(&path, &[motion(1)]).unwrap_err());
        assert!(
            e.contains("fit.json") && e.contains("not a fit file"),
            "{e}"
        );
        let e = merge_into_file(
            &dir.path().join("new.json"),
            &[RobotMotion {
                id: 1,
                actions: Vec::new(),
                fit: None,
            }],
        );
        assert!(e.unwrap_err().to_string().contains("no fit"));
    }
}
