//! Stage by stage, what the firmware should have decided for a frame's
//! logged inputs, and the frames whose logged decision differs.

use super::report::{FrameCheck, Stage, StageCounts, LISTED};
use shared::{
    ActionId, ActionMotors, ChoiceRng, FieldCalibration, FieldValue, LogFrame, MotorCommand,
    PolicyBlob, RobotProfile, Role, SensorReading, State,
};

/// What each stage should have produced from a frame's own inputs.
struct Expected {
    /// Calibrated values, when a calibration was known.
    values: Option<[FieldValue; 3]>,
    state: State,
    action: ActionId,
    /// Motor commands: the action's mix when the policy drove, else a stop
    /// (idle, calibrating standing still, or stopped by a fault).
    motors: MotorCommand,
    /// Whether the logged choice generator is consistent: logged exactly
    /// when the state had several best actions, and where the decisions
    /// before left it (unknown across a lost frame).
    choice_ok: bool,
}

/// Recomputes decisions with a policy and collects the divergences.
pub struct DecisionCheck<'a> {
    policy: &'a PolicyBlob,
    motors: ActionMotors,
    calibration: Option<FieldCalibration>,
    /// The last frame's tick and the choice generator after its decision,
    /// when known (from the last draw logged, with no frame lost since).
    after: Option<(u32, Option<ChoiceRng>)>,
    /// Calibrations logged, each differing from the one before.
    pub calibrations: Vec<FieldCalibration>,
    /// Frames whose values could be checked.
    pub calibration_checked: u64,
    /// Frames with any divergence.
    pub diverged: u64,
    /// Diverged frames per stage.
    pub by_stage: StageCounts,
    /// The first [`LISTED`] frames that diverged.
    pub first: Vec<FrameCheck>,
}

impl<'a> DecisionCheck<'a> {
    /// Checks against `policy` with the Zumo's drive mixing.
    pub fn new(policy: &'a PolicyBlob) -> DecisionCheck<'a> {
        DecisionCheck {
            policy,
            motors: RobotProfile::ZUMO.action_motors(policy.actions()),
            calibration: None,
            after: None,
            calibrations: Vec::new(),
            calibration_checked: 0,
            diverged: 0,
            by_stage: StageCounts::default(),
            first: Vec::new(),
        }
    }

    /// Checks one frame (at byte `offset`) and returns what it logged
    /// beside what each stage should have produced (no divergent stage:
    /// the robot decided as the policy does); a calibration it carries
    /// applies from this frame on.
    pub fn frame(&mut self, offset: u64, f: &LogFrame) -> FrameCheck {
        if let Some(c) = f.calibration {
            if self.calibrations.last() != Some(&c) {
                self.calibrations.push(c);
            }
            self.calibration = Some(c);
        }
        let known = match self.after {
            Some((tick, rng)) if f.tick == tick.wrapping_add(1) => rng,
            _ => None,
        };
        let mut expected = self.expected(f);
        if let (Some(rng), Some(logged)) = (known, f.choice) {
            expected.choice_ok &= rng == ChoiceRng::from_state(logged);
        }
        // a frame that did not draw leaves the generator where it was
        let after = match f.choice {
            Some(s) => {
                let mut rng = ChoiceRng::from_state(s);
                rng.pick(self.policy.sets().mask(f.state));
                Some(rng)
            }
            None => known,
        };
        self.after = Some((f.tick, after));
        if expected.values.is_some() {
            self.calibration_checked += 1;
        }
        let check = frame_check(offset, f, &expected);
        if !check.stages.is_empty() {
            self.diverged += 1;
            for s in &check.stages {
                self.by_stage.count(*s);
            }
            if self.first.len() < LISTED {
                self.first.push(check.clone());
            }
        }
        check
    }

    /// Each stage's result from the frame's logged inputs to that stage.
    fn expected(&self, f: &LogFrame) -> Expected {
        let values = self.calibration.map(|c| c.scales().values(&f.raw_times));
        // the robot's role is its id's (odd: an innie), as the firmware takes it
        let role = Role::of_robot_id(f.robot_id);
        let state = self
            .policy
            .hasher()
            .hash_as(&SensorReading::from_parts(f.values, f.blobs), role);
        let in_range = f.state.index() < self.policy.hasher().num_states();
        // the robot's pick among the state's best actions: the one, or
        // the logged generator's draw among several
        let mask = self.policy.sets().mask(f.state);
        let several = mask.count_ones() > 1;
        let action = match (in_range, f.choice) {
            (false, _) => ActionId(u8::MAX),
            (true, Some(s)) => ChoiceRng::from_state(s).pick(mask),
            (true, None) if several => ActionId(u8::MAX),
            (true, None) => self.policy.table().action(f.state),
        };
        let motors = if f.policy_drove() && f.action.index() < self.policy.actions().len() {
            self.motors.command(f.action)
        } else {
            MotorCommand::default()
        };
        Expected {
            values,
            state,
            action,
            motors,
            choice_ok: !in_range || several == f.choice.is_some(),
        }
    }
}

/// A frame's logged results beside the expected ones.
fn frame_check(offset: u64, f: &LogFrame, e: &Expected) -> FrameCheck {
    FrameCheck {
        offset,
        tick: f.tick,
        stages: divergent_stages(f, e),
        mode: f.mode,
        faults: f.faults.0,
        raw_times: f.raw_times,
        values: f.values.map(|v| v.raw()),
        expected_values: e.values.map(|v| v.map(|x| x.raw())),
        blobs: [
            f.blobs.puck_left,
            f.blobs.puck_right,
            f.blobs.obstacle_left,
            f.blobs.obstacle_right,
        ],
        state: f.state.0,
        expected_state: e.state.0,
        action: f.action.0,
        expected_action: e.action.0,
        motors: [f.motors.left, f.motors.right],
        expected_motors: [e.motors.left, e.motors.right],
    }
}

/// The stages whose logged result differs from the expected one, in order.
fn divergent_stages(f: &LogFrame, e: &Expected) -> Vec<Stage> {
    let motors_ok = e.motors == f.motors;
    [
        (Stage::Calibration, e.values.is_some_and(|v| v != f.values)),
        (Stage::Hash, e.state != f.state),
        (Stage::Policy, e.action != f.action || !e.choice_ok),
        (Stage::Motors, !motors_ok),
    ]
    .into_iter()
    .filter_map(|(stage, diverged)| diverged.then_some(stage))
    .collect()
}
