//! `host bench`: the standard configuration's speed, single-threaded.
//!
//! A step is everything a run does per step: every robot's sensors, the
//! controller, physics, and Eval at the default check interval.

use crate::run_summary::run_timed;
use sim::scenario::{Arena, Scenario};
use sim::BroadPhase;
use anyhow::Result;

/// Which configuration to measure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BenchVariant {
    /// All-pairs contact and sensor checks instead of the grid.
    pub naive: bool,
    /// 64 robots and 1,000 pucks in an arena enlarged to the standard
    /// density (800 x sqrt(1064 / 258) = 1625 units), instead of 8 and 250.
    pub scale: bool,
}

impl BenchVariant {
    /// The scenario measured: annulus, orbital construction, seed 1.
    pub fn scenario(self) -> Scenario {
        let mut s = Scenario {
            broad_phase: if self.naive { BroadPhase::Naive } else { BroadPhase::Grid },
            ..Scenario::default()
        };
        if self.scale {
            s.robots = Some(64);
            s.pucks = Some(1000);
            let standard = (8 + 250) as f64;
            s.arena = Arena::Square((800.0 * (1064.0 / standard).sqrt()).round());
        }
        s
    }
}

/// Runs `steps` steps of the variant and returns steps per second.
pub fn run(variant: BenchVariant, steps: u64) -> Result<f64> {
    let (mut sim, mut controller) = variant.scenario().build()?;
    Ok(run_timed(&mut sim, &mut controller, steps).steps_per_second)
}
