//! Unicycle -> differential drive: an action's forward and angular speed
//! -> left and right motor commands.
//!
//! The simulator moves robots as unicycles (forward speed in world units
//! per step, angular speed in radians per step, positive = turning right,
//! clockwise with y down). A Zumo has two tracks: for a turn of `w` rad per
//! step the outer track runs `w * track / 2` units per step faster than the
//! centre and the inner one as much slower. A [`RobotProfile`] turns those
//! track speeds into motor commands (-400..=400, the Zumo library's range).
//!
//! This runs with `f32` on the host only: the firmware's build computes
//! every action's commands and outputs ahead of time with
//! [`RobotProfile::action_motors`] (the AVR has no FPU) and reads them from
//! the [`ActionMotors`] table it embeds; the log replay and the equivalence
//! tests compute the very same table.

use crate::action::{ActionId, ActionTable};
use serde::{Deserialize, Serialize};

/// The largest motor command magnitude (100 % duty; Timer1's TOP).
pub const MAX_MOTOR: i16 = 400;

/// Signed motor commands, -400..=400; positive drives forward.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct MotorCommand {
    /// Left track.
    pub left: i16,
    /// Right track.
    pub right: i16,
}

/// What one motor driver pin pair gets: the PWM duty (0..=400) and the
/// level of the direction pin.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MotorOutput {
    /// PWM compare value, `|command|`, 0..=400.
    pub duty: u16,
    /// Direction pin level: high = reverse, unless the motor is flipped.
    pub dir_high: bool,
}

/// Both motors' pin-level outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DriveOutputs {
    /// Left motor.
    pub left: MotorOutput,
    /// Right motor.
    pub right: MotorOutput,
}

impl DriveOutputs {
    /// Both motors stopped.
    pub const STOP: DriveOutputs = DriveOutputs {
        left: MotorOutput {
            duty: 0,
            dir_high: false,
        },
        right: MotorOutput {
            duty: 0,
            dir_high: false,
        },
    };
}

/// The motor commands and pin-level outputs of each action of a table
/// (entries past the table's length are stops).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ActionMotors {
    /// Signed commands, for the log.
    pub commands: [MotorCommand; ActionTable::MAX_ACTIONS],
    /// Pin-level outputs (duty, direction), for the board.
    pub outputs: [DriveOutputs; ActionTable::MAX_ACTIONS],
}

impl ActionMotors {
    /// The commands of `action` (a stop for an action beyond the table).
    pub const fn command(&self, action: ActionId) -> MotorCommand {
        self.commands[action.index() & (ActionTable::MAX_ACTIONS - 1)]
    }

    /// The pin-level outputs of `action` (a stop for an action beyond the table).
    pub const fn outputs(&self, action: ActionId) -> DriveOutputs {
        self.outputs[action.index() & (ActionTable::MAX_ACTIONS - 1)]
    }
}

/// A robot's drive geometry and scaling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotProfile {
    /// Distance between the two tracks' centre lines, in world units.
    pub wheel_track: f32,
    /// Motor command per world unit per second of track speed.
    pub speed_scale: f32,
    /// Length of one control step (one simulator step), in milliseconds.
    pub control_period_ms: u16,
    /// The left motor is mounted reversed: positive commands drive its
    /// direction pin high.
    pub flip_left: bool,
    /// The same for the right motor.
    pub flip_right: bool,
}

impl RobotProfile {
    /// The Zumo 32U4 bring-up profile. A robot has radius 10 world units in
    /// the simulator and about 50 mm on the floor, so 1 unit is about 5 mm;
    /// the tracks are about 85 mm apart (17 units). One step is 20 ms (the
    /// Pixy's frame period). `speed_scale` 1.5 makes the thesis' forward
    /// speed of 2 units per step (100 units/s) a command of 150 and the
    /// sharpest turn (0.3 rad/step) 341 / -41: inside the motor range, so
    /// the turn ratio the policy was trained with is kept. Both values are
    /// estimates to be measured on a real robot.
    pub const ZUMO: RobotProfile = RobotProfile {
        wheel_track: 17.0,
        speed_scale: 1.5,
        control_period_ms: 20,
        flip_left: false,
        flip_right: false,
    };

    /// Track speeds (world units per second) for a unicycle speed pair.
    pub fn track_speeds(&self, forward: f32, angular: f32) -> (f32, f32) {
        let steps_per_second = 1000.0 / f32::from(self.control_period_ms.max(1));
        let half_diff = angular * self.wheel_track / 2.0;
        (
            (forward + half_diff) * steps_per_second,
            (forward - half_diff) * steps_per_second,
        )
    }

    /// Motor commands for a forward speed (units per step) and an angular
    /// speed (radians per step, positive = right). If either track would
    /// exceed [`MAX_MOTOR`], both are scaled down by the same factor, which
    /// keeps the turning radius. Non-finite inputs give a stop.
    pub fn mix(&self, forward: f32, angular: f32) -> MotorCommand {
        let (left, right) = self.track_speeds(forward, angular);
        let (mut left, mut right) = (left * self.speed_scale, right * self.speed_scale);
        if !left.is_finite() || !right.is_finite() {
            return MotorCommand::default();
        }
        let largest = if left.abs() > right.abs() {
            left.abs()
        } else {
            right.abs()
        };
        let max = f32::from(MAX_MOTOR);
        if largest > max {
            left = left * max / largest;
            right = right * max / largest;
        }
        MotorCommand {
            left: round(left),
            right: round(right),
        }
    }

    /// The unicycle speeds (forward units per step, radians per step,
    /// positive = right) that a motor command asks for: [`RobotProfile::mix`]
    /// undone (before rounding and saturation, the same speeds; after
    /// saturation, the slower ones the robot is really asked to drive).
    pub fn unicycle(&self, command: MotorCommand) -> (f32, f32) {
        let steps_per_second = 1000.0 / f32::from(self.control_period_ms.max(1));
        let per_step = |c: i16| f32::from(c) / self.speed_scale / steps_per_second;
        let (left, right) = (per_step(command.left), per_step(command.right));
        ((left + right) / 2.0, (left - right) / self.wheel_track)
    }

    /// Every action's commands ([`RobotProfile::mix`] at the table's forward
    /// speed) and outputs: the table the firmware embeds.
    pub fn action_motors(&self, actions: &ActionTable) -> ActionMotors {
        let mut m = ActionMotors {
            commands: [MotorCommand::default(); ActionTable::MAX_ACTIONS],
            outputs: [DriveOutputs::STOP; ActionTable::MAX_ACTIONS],
        };
        for (i, w) in actions.angular_speeds().iter().enumerate() {
            m.commands[i] = self.mix(actions.forward_speed(), *w);
            m.outputs[i] = self.outputs(m.commands[i]);
        }
        m
    }

    /// Pin-level outputs for a command: duty `|command|` clamped to 400,
    /// direction pin high for reverse, inverted for a flipped motor (as the
    /// Pololu Zumo library does).
    pub fn outputs(&self, command: MotorCommand) -> DriveOutputs {
        DriveOutputs {
            left: output(command.left, self.flip_left),
            right: output(command.right, self.flip_right),
        }
    }
}

impl Default for RobotProfile {
    /// [`RobotProfile::ZUMO`].
    fn default() -> RobotProfile {
        RobotProfile::ZUMO
    }
}

fn output(command: i16, flip: bool) -> MotorOutput {
    MotorOutput {
        duty: command.unsigned_abs().min(MAX_MOTOR as u16),
        dir_high: (command < 0) != flip,
    }
}

/// Rounds half away from zero (`f32::round` needs std).
fn round(v: f32) -> i16 {
    let r = if v >= 0.0 { v + 0.5 } else { v - 0.5 };
    r as i16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_ahead_is_equal_tracks() {
        let c = RobotProfile::ZUMO.mix(2.0, 0.0);
        assert_eq!(
            c,
            MotorCommand {
                left: 150,
                right: 150
            }
        );
    }

    #[test]
    fn turning_right_speeds_up_the_left_track() {
        let c = RobotProfile::ZUMO.mix(2.0, 0.3);
        // 2 +- 0.3 x 8.5 = 4.55 / -0.55 units per step, x 50 x 1.5
        assert_eq!(
            c,
            MotorCommand {
                left: 341,
                right: -41
            }
        );
        let c = RobotProfile::ZUMO.mix(2.0, -0.15);
        assert_eq!(
            c,
            MotorCommand {
                left: 54,
                right: 246
            }
        );
    }

    #[test]
    fn unicycle_undoes_the_mix() {
        let p = RobotProfile::ZUMO;
        let (v, w) = p.unicycle(p.mix(2.0, 0.3));
        assert!((v - 2.0).abs() < 0.01 && (w - 0.3).abs() < 0.001, "{v} {w}");
        assert_eq!(
            p.unicycle(MotorCommand {
                left: 150,
                right: 150
            }),
            (2.0, 0.0)
        );
    }

    #[test]
    fn saturation_keeps_the_ratio() {
        let p = RobotProfile {
            speed_scale: 10.0,
            ..RobotProfile::ZUMO
        };
        let c = p.mix(2.0, 0.3);
        assert_eq!(c.left, 400);
        // -0.55 / 4.55 x 400 = -48.35
        assert_eq!(c.right, -48);
        assert_eq!(p.mix(f32::NAN, 0.0), MotorCommand::default());
    }

    #[test]
    fn every_action_gets_its_mix_and_outputs_and_missing_actions_stop() {
        let actions = ActionTable::new(&[0.3, -0.15], 2.0).unwrap();
        let m = RobotProfile::ZUMO.action_motors(&actions);
        assert_eq!(
            m.command(ActionId(0)),
            MotorCommand {
                left: 341,
                right: -41
            }
        );
        assert_eq!(
            m.command(ActionId(1)),
            MotorCommand {
                left: 54,
                right: 246
            }
        );
        assert_eq!(
            m.outputs(ActionId(0)).right,
            MotorOutput {
                duty: 41,
                dir_high: true
            }
        );
        assert_eq!(m.command(ActionId(2)), MotorCommand::default());
        assert_eq!(m.outputs(ActionId(3)), DriveOutputs::STOP);
        // An id beyond the table's four slots wraps into them, never panics.
        assert_eq!(m.command(ActionId(4)), m.command(ActionId(0)));
    }

    #[test]
    fn outputs_follow_the_pololu_direction_rule() {
        let p = RobotProfile::ZUMO;
        let o = p.outputs(MotorCommand {
            left: -120,
            right: 300,
        });
        assert_eq!(
            o.left,
            MotorOutput {
                duty: 120,
                dir_high: true
            }
        );
        assert_eq!(
            o.right,
            MotorOutput {
                duty: 300,
                dir_high: false
            }
        );
        let flipped = RobotProfile {
            flip_right: true,
            ..p
        };
        assert!(
            flipped
                .outputs(MotorCommand {
                    left: 0,
                    right: 300
                })
                .right
                .dir_high
        );
        assert_eq!(
            p.outputs(MotorCommand {
                left: i16::MIN,
                right: 0
            })
            .left
            .duty,
            400
        );
        assert_eq!(p.outputs(MotorCommand::default()), DriveOutputs::STOP);
    }
}
