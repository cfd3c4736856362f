//! How the robots really move, for domain randomisation: each robot's own
//! wheel speed and turning bias, drawn per episode (or measured on real
//! robots: `host replay --fit-profile`), the control period's jitter, and
//! dropped periods in which a robot keeps its last turn. Without noise
//! ([`ActuationNoise::NONE`], the default) robots move exactly as commanded.
//!
//! Per robot and step, with `f` the robot's wheel speed factor and `b` its
//! turning bias (radians per step), `p = 1 + jitter` the period's length
//! relative to the nominal one and `w` the commanded turn (the previous
//! step's if the period is dropped): the robot turns `(w + b) p` and drives
//! `forward_speed f p`.

use crate::base::noise::{self, Place, Purpose};
use crate::base::ranges;
use crate::config::validate::{check, ConfigError};
use serde::{Deserialize, Serialize};

/// A robot's measured motion (`host replay --fit-profile`'s names).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotMotion {
    /// Measured over intended forward speed (1.0: as intended).
    pub wheel_speed_factor: f64,
    /// Measured minus intended turning rate, radians per step (positive:
    /// right).
    pub turn_bias: f64,
}

impl RobotMotion {
    /// Moving exactly as commanded.
    pub(crate) const EXACT: RobotMotion = RobotMotion {
        wheel_speed_factor: 1.0,
        turn_bias: 0.0,
    };
}

/// The actuation noise models; every field is optional in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ActuationNoise {
    /// Each robot's wheel speed factor is drawn per episode uniformly in
    /// `1 +- speed_spread`.
    pub speed_spread: f64,
    /// Each robot's turning bias is drawn per episode uniformly in
    /// `+- turn_bias`, radians per step.
    pub turn_bias: f64,
    /// Standard deviation of a period's length, relative to the nominal 20 ms.
    pub period_jitter: f64,
    /// Probability that a robot's period is dropped (it keeps its last turn).
    pub drop_period: f64,
    /// Measured robots: robot `i` moves as `robots[i % len]` instead of a
    /// draw (the other models still apply).
    pub robots: Vec<RobotMotion>,
}

impl Default for ActuationNoise {
    /// [`ActuationNoise::NONE`].
    fn default() -> ActuationNoise {
        ActuationNoise::NONE
    }
}

impl ActuationNoise {
    /// No noise: robots move exactly as commanded.
    pub const NONE: ActuationNoise = ActuationNoise {
        speed_spread: 0.0,
        turn_bias: 0.0,
        period_jitter: 0.0,
        drop_period: 0.0,
        robots: Vec::new(),
    };

    /// The default noise (`--randomise`), each figure's source in
    /// `docs/robot-sensors.md`: wheel speeds +-10 % (Zumo units differ
    /// about 10 % at one PWM), turning bias +-0.005 rad per step (a 2 %
    /// difference between the two tracks), period jitter 1 %, and 1 % of
    /// periods dropped.
    pub fn randomised() -> ActuationNoise {
        ActuationNoise {
            speed_spread: 0.1,
            turn_bias: 0.005,
            period_jitter: 0.01,
            drop_period: 0.01,
            robots: Vec::new(),
        }
    }

    /// This noise with every amount times `k` (measured robots kept).
    pub fn scaled(&self, k: f64) -> ActuationNoise {
        ActuationNoise {
            speed_spread: self.speed_spread * k,
            turn_bias: self.turn_bias * k,
            period_jitter: self.period_jitter * k,
            drop_period: (self.drop_period * k).min(1.0),
            robots: self.robots.clone(),
        }
    }

    /// Whether robots move exactly as commanded.
    pub fn is_none(&self) -> bool {
        *self == ActuationNoise::NONE
    }

    /// Checks every amount against its range; the error names the setting.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ranges::SPEED_SPREAD.check(self.speed_spread)?;
        ranges::TURN_BIAS.check(self.turn_bias)?;
        check(
            "world.actuation.turn_bias",
            self.turn_bias,
            self.turn_bias >= 0.0,
            "must not be negative (biases are drawn in +- this)",
        )?;
        ranges::RELATIVE_NOISE.check_as("world.actuation.period_jitter", self.period_jitter)?;
        ranges::PROBABILITY.check_as("world.actuation.drop_period", self.drop_period)?;
        for (i, r) in self.robots.iter().enumerate() {
            ranges::WHEEL_SPEED_FACTOR.check_as(
                &format!("world.actuation.robots[{i}].wheel_speed_factor"),
                r.wheel_speed_factor,
            )?;
            ranges::TURN_BIAS.check_as(
                &format!("world.actuation.robots[{i}].turn_bias"),
                r.turn_bias,
            )?;
        }
        Ok(())
    }

    /// Robot `robot`'s motion in episode `episode` of the world seeded with `seed`.
    pub fn motion(&self, seed: u64, episode: u64, robot: usize) -> RobotMotion {
        if let Some(measured) = self.robots.get(robot % self.robots.len().max(1)) {
            return *measured;
        }
        if self.speed_spread == 0.0 && self.turn_bias == 0.0 {
            return RobotMotion::EXACT;
        }
        let mut rng = noise::stream(seed, Purpose::RobotMotion, episode, robot as u64);
        RobotMotion {
            wheel_speed_factor: 1.0 + noise::symmetric(&mut rng, self.speed_spread),
            turn_bias: noise::symmetric(&mut rng, self.turn_bias),
        }
    }

    /// Robot `robot`'s period at step `step`: its length relative to the
    /// nominal one, and whether it is dropped.
    pub fn period(&self, seed: u64, step: u64, robot: usize) -> (f64, bool) {
        self.period_at(noise::place(seed, Purpose::Period, step), robot)
    }

    /// [`Self::period`] with the step's [`Purpose::Period`] place, which
    /// every robot's period of the step shares.
    pub(crate) fn period_at(&self, step: Place, robot: usize) -> (f64, bool) {
        if self.period_jitter == 0.0 && self.drop_period == 0.0 {
            return (1.0, false);
        }
        let mut rng = step.stream(robot as u64);
        let length = 1.0 + self.period_jitter * noise::normal(&mut rng);
        (length, noise::chance(&mut rng, self.drop_period))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_noise_moves_exactly_and_measured_robots_override_the_draws() {
        let none = ActuationNoise::NONE;
        assert_eq!(none.motion(1, 0, 3), RobotMotion::EXACT);
        assert_eq!(none.period(1, 10, 3), (1.0, false));
        let measured = ActuationNoise {
            robots: vec![
                RobotMotion {
                    wheel_speed_factor: 0.9,
                    turn_bias: 0.01,
                },
                RobotMotion::EXACT,
            ],
            ..ActuationNoise::randomised()
        };
        assert_eq!(measured.motion(1, 4, 2).wheel_speed_factor, 0.9);
        assert_eq!(measured.motion(1, 4, 3), RobotMotion::EXACT);
    }

    #[test]
    fn draws_stay_in_their_ranges_are_seeded_and_change_per_episode() {
        let n = ActuationNoise::randomised();
        let m = n.motion(5, 2, 1);
        assert_eq!(m, n.motion(5, 2, 1));
        assert_ne!(m, n.motion(5, 3, 1));
        assert_ne!(m, n.motion(6, 2, 1));
        let factors: Vec<f64> = (0..2000)
            .map(|e| n.motion(5, e, 0).wheel_speed_factor)
            .collect();
        assert!(factors.iter().all(|f| (0.9..=1.1).contains(f)));
        assert!(factors.iter().any(|f| *f < 0.92) && factors.iter().any(|f| *f > 1.08));
        let drops = (0..20_000).filter(|s| n.period(5, *s, 0).1).count();
        assert!(
            (150..250).contains(&drops),
            "{drops} of 20,000 periods dropped at 1 %"
        );
        let lengths: Vec<f64> = (0..20_000).map(|s| n.period(5, s, 0).0).collect();
        let sd = (lengths.iter().map(|l| (l - 1.0) * (l - 1.0)).sum::<f64>() / 20_000.0).sqrt();
        assert!((sd - 0.01).abs() < 0.001, "{sd}");
        let twice = n.scaled(2.0);
        assert_eq!((twice.speed_spread, twice.drop_period), (0.2, 0.02));
    }

    #[test]
    fn bad_amounts_are_named() {
        let bad = ActuationNoise {
            speed_spread: 1.5,
            ..ActuationNoise::NONE
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("world.actuation.speed_spread"));
        let bad = ActuationNoise {
            robots: vec![RobotMotion {
                wheel_speed_factor: 0.0,
                turn_bias: 0.0,
            }],
            ..ActuationNoise::NONE
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("robots[0].wheel_speed_factor"));
        assert!(ActuationNoise::randomised().validate().is_ok());
    }
}
