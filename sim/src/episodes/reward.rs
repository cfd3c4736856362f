//! The reward a robot's update receives, by variant: the signal (Eval or
//! Eval') whose change is rewarded, the rule that turns the change into a
//! reward, and for `per-robot` each robot's credit.

use crate::config::SimConfig;
use crate::episodes::eval::{self, eval_prime_of, EvalPrime, PuckChange};
use crate::fields::ScalarField;
use crate::physics::Contact;
use crate::world::World;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How the step's reward is computed from the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
// Serialised by variant (an index in the binary checkpoints, whose frozen
// formats hold it so): kebab-case gives the same names as `name()`, which a
// test checks.
#[serde(rename_all = "kebab-case")]
pub enum Reward {
    /// `Eval_t - Eval_{t-1}`, minus 1 when that is not positive: the original
    /// code's rule, which produced the thesis' numbers (the default).
    Reference,
    /// `Eval_t - Eval_{t-1}` as the thesis text writes it.
    Thesis,
    /// `Eval'_t - Eval'_{t-1}` with the formula as printed in chapter 6
    /// (phi, nu from the episode settings), with the reference's -1 rule.
    Collision,
    /// `Eval'_t - Eval'_{t-1}` with the variant that grows with the robots'
    /// spread (what chapter 6's text says), with the reference's -1 rule.
    CollisionSpread,
    /// Each robot its own reward: the change of Eval of the pucks it
    /// touched in the step (a puck touched by several robots shared
    /// equally), [`robot_credit`]. A world's reward (the single-agent
    /// views') is the thesis reward.
    PerRobot,
    /// [`SUCCESS_BONUS`] in the step that forms the shape, else 0: the task
    /// itself, sparse.
    Success,
    /// `success` plus potential-based shaping on Eval, `gamma Eval(s') -
    /// Eval(s)` (with Eval of the formed, terminal state taken as 0), which
    /// leaves the optimal policy of `success` unchanged (Ng, Harada and
    /// Russell, 1999) while rewarding progress at every step.
    SuccessShaped,
}

/// What the `success` rewards pay in the step that forms the shape.
pub const SUCCESS_BONUS: f64 = 1.0;

/// One step as a reward sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// The signal before the step.
    pub before: f64,
    /// The signal after it.
    pub after: f64,
    /// Whether the step formed the shape (the episode terminates).
    pub formed: bool,
}

impl Reward {
    /// Every variant, for help texts and sweeps.
    pub const ALL: [Reward; 7] = [
        Reward::Reference,
        Reward::Thesis,
        Reward::Collision,
        Reward::CollisionSpread,
        Reward::PerRobot,
        Reward::Success,
        Reward::SuccessShaped,
    ];

    /// The CLI / config name.
    pub fn name(self) -> &'static str {
        match self {
            Reward::Reference => "reference",
            Reward::Thesis => "thesis",
            Reward::Collision => "collision",
            Reward::CollisionSpread => "collision-spread",
            Reward::PerRobot => "per-robot",
            Reward::Success => "success",
            Reward::SuccessShaped => "success-shaped",
        }
    }

    /// Whether this is one of the four rewards of the thesis and its code
    /// (the others were added for deep learners).
    pub fn from_thesis(self) -> bool {
        matches!(
            self,
            Reward::Reference | Reward::Thesis | Reward::Collision | Reward::CollisionSpread
        )
    }

    /// Whether each robot gets its own reward ([`robot_credit`]) instead
    /// of the world's.
    pub fn per_robot(self) -> bool {
        self == Reward::PerRobot
    }

    /// The signal whose change is rewarded, measured on `world`: Eval (pass
    /// it as `eval` when already computed) or Eval'.
    pub fn signal(
        self,
        world: &World,
        field: &ScalarField,
        config: &SimConfig,
        eval: Option<f64>,
    ) -> f64 {
        let variant = match self {
            Reward::Reference
            | Reward::Thesis
            | Reward::PerRobot
            | Reward::Success
            | Reward::SuccessShaped => {
                return eval.unwrap_or_else(|| eval::eval(world, field, &config.thresholds))
            }
            Reward::Collision => EvalPrime::AsWritten,
            Reward::CollisionSpread => EvalPrime::Spread,
        };
        eval_prime_of(world, field, config, variant)
    }

    /// The world's reward for a step; `gamma` is the learner's discount,
    /// which only the shaping of `success-shaped` uses.
    pub fn reward(self, step: Transition, gamma: f64) -> f64 {
        let delta = step.after - step.before;
        let bonus = if step.formed { SUCCESS_BONUS } else { 0.0 };
        match self {
            Reward::Thesis | Reward::PerRobot => delta,
            Reward::Reference | Reward::Collision | Reward::CollisionSpread => {
                if delta > 0.0 {
                    delta
                } else {
                    delta - 1.0
                }
            }
            Reward::Success => bonus,
            Reward::SuccessShaped => bonus + shaping(step, gamma),
        }
    }
}

/// Potential-based shaping with the signal as potential: `gamma Phi(s') -
/// Phi(s)`, `Phi` of the terminal (formed) state 0, so that the shaping
/// of an episode sums to `-Phi(s_0)` plus discounting's terms, whatever the
/// policy.
pub fn shaping(step: Transition, gamma: f64) -> f64 {
    let next = if step.formed { 0.0 } else { step.after };
    gamma * next - step.before
}

/// Each robot's `per-robot` reward for a step, into `credit` (one per
/// robot): the Eval change of every puck whose distance to the band
/// changed (`changes`, the step's [`PuckChange`]s) goes to the robots
/// that touched it in the step (`world`'s contacts), in equal shares;
/// pucks no robot touched (pushed by other pucks) are credited to none.
/// `touching` is scratch space.
pub fn robot_credit(
    world: &World,
    changes: &[PuckChange],
    credit: &mut [f64],
    touching: &mut Vec<u32>,
) {
    credit.fill(0.0);
    let robots = world.robots().len() as u32;
    for change in changes {
        touching.clear();
        for contact in world.contacts() {
            let Contact::Bodies(a, b) = *contact else {
                continue;
            };
            let robot = match (a == change.body, b == change.body) {
                (true, false) if b < robots => b,
                (false, true) if a < robots => a,
                _ => continue,
            };
            if !touching.contains(&robot) {
                touching.push(robot);
            }
        }
        let share = change.eval_change / touching.len().max(1) as f64;
        for &robot in touching.iter() {
            credit[robot as usize] += share;
        }
    }
}

impl fmt::Display for Reward {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Reward {
    type Err = String;

    fn from_str(s: &str) -> Result<Reward, String> {
        Reward::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Reward::ALL.iter().map(|r| r.name()).collect();
                format!("unknown reward {s:?}: expected {}", names.join(", "))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(before: f64, after: f64, formed: bool) -> Transition {
        Transition {
            before,
            after,
            formed,
        }
    }

    #[test]
    fn reference_subtracts_one_from_non_positive_rewards() {
        let r = |reward: Reward, before, after| reward.reward(step(before, after, false), 0.9);
        assert_eq!(r(Reward::Reference, 0.5, 0.75), 0.25);
        assert_eq!(r(Reward::Reference, 0.5, 0.5), -1.0);
        assert_eq!(r(Reward::Reference, 0.75, 0.5), -1.25);
        assert_eq!(r(Reward::Thesis, 0.75, 0.5), -0.25);
        assert_eq!(r(Reward::Thesis, 0.5, 0.5), 0.0);
        assert_eq!(r(Reward::PerRobot, 0.75, 0.5), -0.25);
    }

    #[test]
    fn success_pays_the_bonus_only_when_the_shape_forms_and_shaping_adds_gamma_phi_next_minus_phi()
    {
        assert_eq!(Reward::Success.reward(step(0.5, 0.75, false), 0.9), 0.0);
        assert_eq!(Reward::Success.reward(step(0.9, 0.95, true), 0.9), 1.0);
        // 0.5 x 0.75 - 0.5 = -0.125
        let shaped = Reward::SuccessShaped.reward(step(0.5, 0.75, false), 0.5);
        assert_eq!(shaped, -0.125);
        // formed: the terminal state's potential is 0, so 1 + 0 - 0.9
        let formed = Reward::SuccessShaped.reward(step(0.9, 0.95, true), 0.5);
        assert!((formed - 0.1).abs() < 1e-12, "{formed}");
    }

    /// Robots 0 and 1 both driving into puck 3 (body 5), robot 2 into puck
    /// 4 (body 6) far away; puck 5 (body 7) alone.
    fn pushed_scene() -> World {
        use crate::base::vec2::Vec2;
        use crate::physics::body::RobotKind;
        let config = SimConfig::default();
        let robots = [
            (Vec2::new(100.0, 100.0), 0.0, RobotKind::Outie),
            (
                Vec2::new(140.0, 100.0),
                std::f64::consts::PI,
                RobotKind::Outie,
            ),
            (Vec2::new(400.0, 400.0), 0.0, RobotKind::Outie),
        ];
        let pucks = [
            Vec2::new(120.0, 100.0),
            Vec2::new(419.0, 400.0),
            Vec2::new(700.0, 700.0),
        ];
        let mut world = World::scene(&config, &robots, &pucks, 1);
        world.step(&[0.0; 3]);
        world
    }

    #[test]
    fn a_pucks_eval_change_goes_to_the_robots_that_touched_it_in_equal_shares() {
        let world = pushed_scene();
        let change = |body, eval_change| PuckChange { body, eval_change };
        let mut credit = [9.0; 3];
        let mut touching = Vec::new();
        // body 3 touched by robots 0 and 1, body 4 by robot 2, body 5 by none
        let changes = [change(3, 0.25), change(4, -0.125), change(5, 0.5)];
        robot_credit(&world, &changes, &mut credit, &mut touching);
        assert_eq!(credit, [0.125, 0.125, -0.125]);
        robot_credit(&world, &[], &mut credit, &mut touching);
        assert_eq!(credit, [0.0; 3], "no change, no credit");
    }

    #[test]
    fn names_round_trip() {
        for r in Reward::ALL {
            assert_eq!(r.name().parse::<Reward>(), Ok(r));
        }
        assert!("eval".parse::<Reward>().is_err());
        for r in Reward::ALL {
            assert_eq!(
                serde_json::to_string(&r).unwrap(),
                format!("\"{}\"", r.name())
            );
        }
    }
}
