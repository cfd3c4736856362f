//! The incrementally tracked Eval the simulation reports equals a fresh
//! evaluation of the whole world, at every step and across episode resets.

use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::{
    base::rng::SimRng, config::SimConfig, episodes::eval::eval, episodes::StepOutcome,
    fields::ScalarField, simulation::Simulation,
};
use sim::{control::Controller, control::Perception};
use std::sync::Arc;

/// Orbital construction that checks each reported Eval against a recount.
struct Checker {
    oc: OrbitalConstruction,
    every_step: bool,
    compared: u64,
    resets: u64,
}

impl Controller for Checker {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        self.oc.decide(p, turns, rng)
    }
    fn wants_eval_every_step(&self) -> bool {
        self.every_step
    }
    fn observe(&mut self, o: &StepOutcome<'_>) {
        if let Some(reported) = o.eval {
            let fresh = eval(o.world, o.field, &sim::config::Thresholds::default());
            assert_eq!(
                reported.to_bits(),
                fresh.to_bits(),
                "step {}: tracked {reported}, recount {fresh}",
                o.episode_step
            );
            self.compared += 1;
        }
        self.resets += u64::from(o.end.is_some());
    }
}

#[test]
fn tracked_eval_equals_a_recount_every_step_and_at_checks() {
    for every_step in [true, false] {
        let mut config = SimConfig::default();
        config.world.innies = 4;
        // short episodes, so that resets happen within the run
        config.episode.stuck_limit = 3_000;
        let thresholds = config.thresholds.clone();
        let mut sim = Simulation::new(config, Arc::new(ScalarField::annulus()), 11).unwrap();
        let oc = OrbitalConstruction::new(OrbitalConfig::default(), &thresholds);
        let mut checker = Checker {
            oc,
            every_step,
            compared: 0,
            resets: 0,
        };
        sim.run(&mut checker, 10_000);
        assert_eq!(checker.compared, if every_step { 10_000 } else { 100 });
        assert!(checker.resets >= 3, "the run must cross episode resets");
    }
}
