//! The global reward every robot's update receives, by variant: the signal
//! (Eval or Eval') whose change is rewarded, and the rule that turns the
//! change into a reward.

use crate::config::SimConfig;
use crate::episodes::eval::{self, eval_prime, EvalPrime};
use crate::fields::ScalarField;
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
}

impl Reward {
    /// Every variant, for help texts and sweeps.
    pub const ALL: [Reward; 4] = [
        Reward::Reference,
        Reward::Thesis,
        Reward::Collision,
        Reward::CollisionSpread,
    ];

    /// The CLI / config name.
    pub fn name(self) -> &'static str {
        match self {
            Reward::Reference => "reference",
            Reward::Thesis => "thesis",
            Reward::Collision => "collision",
            Reward::CollisionSpread => "collision-spread",
        }
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
            Reward::Reference | Reward::Thesis => {
                return eval.unwrap_or_else(|| eval::eval(world, field, &config.thresholds))
            }
            Reward::Collision => EvalPrime::AsWritten,
            Reward::CollisionSpread => EvalPrime::Spread,
        };
        eval_prime(
            world,
            field,
            &config.thresholds,
            variant,
            config.episode.phi,
            config.episode.nu,
        )
    }

    /// The reward for a change of signal from `before` to `after`.
    pub fn reward(self, before: f64, after: f64) -> f64 {
        let delta = after - before;
        match self {
            Reward::Thesis => delta,
            Reward::Reference | Reward::Collision | Reward::CollisionSpread => {
                if delta > 0.0 {
                    delta
                } else {
                    delta - 1.0
                }
            }
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
        Reward::ALL.into_iter().find(|r| r.name() == s).ok_or_else(|| {
            format!("unknown reward {s:?}: expected reference, thesis, collision or collision-spread")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_subtracts_one_from_non_positive_rewards() {
        assert_eq!(Reward::Reference.reward(0.5, 0.75), 0.25);
        assert_eq!(Reward::Reference.reward(0.5, 0.5), -1.0);
        assert_eq!(Reward::Reference.reward(0.75, 0.5), -1.25);
        assert_eq!(Reward::Thesis.reward(0.75, 0.5), -0.25);
        assert_eq!(Reward::Thesis.reward(0.5, 0.5), 0.0);
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
