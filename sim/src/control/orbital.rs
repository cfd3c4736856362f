//! Orbital construction, the thesis' Algorithm 2.

use crate::base::rng::SimRng;
use crate::config::Thresholds;
use crate::control::{Controller, Perception};
use crate::physics::body::RobotKind;
use serde::{Deserialize, Serialize};
use shared::{FieldValue, SensorReading};

/// Orbital construction's constants.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OrbitalConfig {
    /// omega_max, radians per step.
    pub max_angular: f32,
    /// phi, the gentle-turn factor of omega_max.
    pub gentle_factor: f32,
}

impl Default for OrbitalConfig {
    /// The thesis: 0.3 and 0.3.
    fn default() -> OrbitalConfig {
        OrbitalConfig {
            max_angular: 0.3,
            gentle_factor: 0.3,
        }
    }
}

/// Algorithm 2 for innies and outies. Field values are compared in the
/// readings' fixed point, thresholds converted to it once.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitalConstruction {
    config: OrbitalConfig,
    outie_threshold: FieldValue,
    innie_threshold: FieldValue,
}

impl OrbitalConstruction {
    /// The controller with the given constants; outies orbit at T_o,
    /// innies at T_i.
    pub fn new(config: OrbitalConfig, thresholds: &Thresholds) -> OrbitalConstruction {
        OrbitalConstruction {
            config,
            outie_threshold: FieldValue::from_f32(thresholds.outie as f32),
            innie_threshold: FieldValue::from_f32(thresholds.innie as f32),
        }
    }

    /// One robot's angular speed:
    /// 1. left obstacle: turn right at omega_max;
    /// 2. orbiting clockwise (right >= mid >= left): an innie with a puck on
    ///    its right turns right, an outie with a puck on its left turns left,
    ///    both at omega_max; otherwise a gentle turn (phi omega_max) right if
    ///    mid is below the robot's threshold, left if not;
    /// 3. mid the highest: turn left at omega_max;
    /// 4. otherwise turn right at omega_max.
    pub fn turn(&self, r: &SensorReading, kind: RobotKind) -> f32 {
        let max = self.config.max_angular;
        if r.obstacle_left {
            return max;
        }
        if r.right >= r.mid && r.mid >= r.left {
            let (threshold, push) = match kind {
                RobotKind::Innie => (self.innie_threshold, r.puck_right.then_some(max)),
                RobotKind::Outie => (self.outie_threshold, r.puck_left.then_some(-max)),
            };
            if let Some(w) = push {
                return w;
            }
            let gentle = self.config.gentle_factor * max;
            return if r.mid < threshold { gentle } else { -gentle };
        }
        if r.mid >= r.right && r.mid >= r.left {
            -max
        } else {
            max
        }
    }
}

impl Controller for OrbitalConstruction {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], _rng: &mut SimRng) {
        for ((turn, reading), robot) in turns.iter_mut().zip(p.readings).zip(p.robots) {
            *turn = self.turn(reading, robot.kind);
        }
    }
}
