//! Whole simulations: determinism, checkpoints, Eval, and the control that
//! orbital construction builds the annulus where random turning does not.

use shared::ActionTable;
use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::control::random::RandomTurns;
use sim::scenario::{ControllerChoice, Scenario};
use sim::{
    base::rng::SimRng, base::vec2::Vec2, config::SimConfig, episodes::eval::eval,
    episodes::eval::eval_prime, episodes::eval::EvalPrime, episodes::StepOutcome,
    fields::ScalarField, simulation::Simulation, world::World,
};
use sim::{control::Controller, control::Perception};
use sim::{physics::body::RobotKind, simulation::SimulationState};
use std::sync::Arc;

fn standard(seed: u64) -> Simulation {
    let mut config = SimConfig::default();
    config.world.innies = 4;
    Simulation::new(config, Arc::new(ScalarField::annulus()), seed).unwrap()
}

fn oc() -> OrbitalConstruction {
    OrbitalConstruction::new(OrbitalConfig::default(), &Default::default())
}

fn final_state(sim: &Simulation) -> String {
    serde_json::to_string(sim.state()).unwrap()
}

#[test]
fn same_seed_same_trajectory_even_beside_other_threads() {
    let run = |seed| {
        let mut sim = standard(seed);
        sim.run(&mut RandomTurns::new(ActionTable::default()), 3000);
        final_state(&sim)
    };
    let alone = run(5);
    let threads: Vec<_> = [5, 6, 5]
        .into_iter()
        .map(|s| std::thread::spawn(move || run(s)))
        .collect();
    let results: Vec<String> = threads.into_iter().map(|t| t.join().unwrap()).collect();
    assert!(results[0] == alone && results[2] == alone);
    assert!(results[1] != alone, "another seed gives another trajectory");
}

#[test]
fn a_caller_driving_the_step_api_gets_the_controller_loops_trajectory() {
    // A short stuck limit, so that episodes end and reset within the run.
    let short = || {
        let mut config = SimConfig::default();
        config.world.innies = 4;
        config.episode.stuck_limit = 1500;
        Simulation::new(config, Arc::new(ScalarField::annulus()), 2).unwrap()
    };
    let mut driven = short();
    let mut controller = oc();
    driven.run(&mut controller, 6000);
    let ends = driven.totals().formations + driven.totals().stuck;
    assert!(
        ends >= 3,
        "episodes should end and reset within the run: {:?}",
        driven.totals()
    );

    let mut external = short();
    let policy = oc();
    let mut turns = vec![0.0f32; external.world().robots().len()];
    let mut external_ends = 0;
    for _ in 0..6000 {
        for ((turn, reading), robot) in turns
            .iter_mut()
            .zip(external.readings())
            .zip(external.world().robots())
        {
            *turn = policy.turn(reading, robot.kind);
        }
        let report = external.advance(&turns, false);
        if report.end.is_some() {
            external_ends += 1;
            external.reset_episode();
        }
    }
    assert_eq!(external_ends, ends);
    assert!(final_state(&external) == final_state(&driven));
}

#[test]
fn a_checkpoint_resumes_bit_exactly() {
    let mut straight = standard(3);
    let mut controller = oc();
    straight.run(&mut controller, 4000);

    let mut first = standard(3);
    first.run(&mut controller, 1500);
    let saved = serde_json::to_string(first.state()).unwrap();
    let state: SimulationState = serde_json::from_str(&saved).unwrap();
    let sensors = sim::sensors::disc::DiscSensors::new(
        &state.config.sensors,
        state.config.world.robot_radius,
    );
    let mut resumed = Simulation::resume(state, Arc::new(ScalarField::annulus()), sensors);
    resumed.run(&mut controller, 2500);
    assert!(final_state(&resumed) == final_state(&straight));
}

#[test]
fn eval_is_one_in_the_band_and_falls_outside_it() {
    let c = SimConfig::default();
    let f = ScalarField::annulus();
    let robot = (Vec2::new(20.0, 20.0), 0.0, RobotKind::Outie);
    // cell (22, 32) is 10 cells from the centre: 1 - 10 / 45.25 = 0.779, in [0.6, 0.8]
    let ring = World::scene(&c, &[robot], &[Vec2::new(22.0 * 12.5 + 1.0, 400.0)], 1);
    assert_eq!(eval(&ring, &f, &c.thresholds), 1.0);
    // the centre cell, 1.0: distance 0.2 above T_i, normalised by max(0.6, 0.2)
    let centre = World::scene(&c, &[robot], &[Vec2::new(400.0, 400.0)], 1);
    assert!((eval(&centre, &f, &c.thresholds) - (1.0 - 0.2 / 0.6)).abs() < 1e-6);

    // two robots on cells equally far from the centre: the as-written
    // robot term is exactly 1 (no pucks: Eval 1)
    let robots = [
        (Vec2::new(200.0, 400.0), 0.0, RobotKind::Outie),
        (Vec2::new(600.0, 400.0), 0.0, RobotKind::Outie),
    ];
    let two = World::scene(&c, &robots, &[], 1);
    assert_eq!(
        eval_prime(&two, &f, &c.thresholds, EvalPrime::AsWritten, 0.6, 0.4),
        1.0
    );
    // 400 apart in an 800 arena: spread term 400 / (800 sqrt 2)
    let spread = eval_prime(&two, &f, &c.thresholds, EvalPrime::Spread, 0.6, 0.4);
    assert!(
        (spread - (0.6 + 0.4 * 400.0 / (800.0 * 2f64.sqrt()))).abs() < 1e-9,
        "{spread}"
    );
}

/// Counts what a controller is told.
struct Recorder<C> {
    inner: C,
    every_step: bool,
    evals: u64,
    ends: u64,
}

impl<C: Controller> Controller for Recorder<C> {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        self.inner.decide(p, turns, rng)
    }
    fn wants_eval_every_step(&self) -> bool {
        self.every_step
    }
    fn observe(&mut self, o: &StepOutcome<'_>) {
        self.evals += u64::from(o.eval.is_some());
        self.ends += u64::from(o.end.is_some());
    }
}

#[test]
fn eval_is_reported_at_checks_or_every_step_on_request() {
    for every_step in [false, true] {
        let mut sim = standard(2);
        let mut rec = Recorder {
            inner: oc(),
            every_step,
            evals: 0,
            ends: 0,
        };
        sim.run(&mut rec, 1000);
        assert_eq!(rec.evals, if every_step { 1000 } else { 10 });
        assert_eq!(
            sim.totals().eval_checks,
            10,
            "the mean uses the checks only"
        );
    }
}

/// The control: orbital construction forms the annulus within a run length
/// where random turning forms nothing; each formation resets the episode.
#[test]
fn orbital_construction_forms_the_annulus_and_random_does_not() {
    const STEPS: u64 = 40_000;
    let run = |controller| {
        let scenario = Scenario {
            controller,
            ..Scenario::default()
        };
        let (mut sim, mut c) = scenario.build().unwrap();
        let mut rec = Recorder {
            inner: &mut c,
            every_step: false,
            evals: 0,
            ends: 0,
        };
        sim.run(&mut rec, STEPS);
        (sim.totals().clone(), rec.ends)
    };
    let (oc, oc_ends) = run(ControllerChoice::Orbital);
    let (random, _) = run(ControllerChoice::Random);
    assert!(
        oc.formations >= 1,
        "orbital construction formed nothing in {STEPS} steps"
    );
    assert_eq!(
        oc_ends,
        oc.formations + oc.stuck,
        "every ended episode was reported"
    );
    assert_eq!(random.formations, 0);
    assert!(oc.mean_eval() > random.mean_eval());
}

/// The annulus with 4 innies, seed 4, checks every `interval` steps against
/// `threshold`, and `more` episode settings.
fn checked(
    interval: u64,
    threshold: f64,
    more: impl FnOnce(&mut sim::config::EpisodeConfig),
) -> Simulation {
    let mut config = SimConfig::default();
    config.world.innies = 4;
    config.episode.check_interval = interval;
    config.episode.success_eval = threshold;
    more(&mut config.episode);
    Simulation::new(config, Arc::new(ScalarField::annulus()), 4).unwrap()
}

/// OC on the annulus with a threshold no Eval reaches: the success signal
/// (Eval, or Eval' as printed) at each of `checks` checks every `interval`
/// steps, the first entry being the episode's start.
fn signals_at_checks(interval: u64, checks: usize) -> Vec<(f64, f64)> {
    let mut sim = checked(interval, 1.0, |_| {});
    let mut controller = oc();
    let measure = |sim: &Simulation| {
        let c = sim.config();
        let prime = eval_prime(
            sim.world(),
            sim.field(),
            &c.thresholds,
            EvalPrime::AsWritten,
            c.episode.phi,
            c.episode.nu,
        );
        (sim.eval(), prime)
    };
    let mut out = vec![measure(&sim)];
    for _ in 0..checks {
        sim.run(&mut controller, interval);
        out.push(measure(&sim));
    }
    out
}

/// The step of the first formation with these episode settings, seed 4.
fn first_formation(
    interval: u64,
    threshold: f64,
    stale: bool,
    signal: sim::config::SuccessSignal,
) -> Option<u64> {
    let mut sim = checked(interval, threshold, |e| {
        e.stale_eval = stale;
        e.success_signal = signal;
    });
    let mut controller = oc();
    (1..=40 * interval).find(|_| sim.step(&mut controller).is_some())
}

/// The first check (from 1) whose value exceeds every earlier one and the start's.
fn first_record(values: &[f64]) -> usize {
    (1..values.len())
        .find(|&k| values[k] > values[..k].iter().cloned().fold(f64::MIN, f64::max))
        .unwrap()
}

#[test]
fn a_stale_check_forms_one_check_after_the_world_formed() {
    let signals = signals_at_checks(500, 30);
    let evals: Vec<f64> = signals.iter().map(|s| s.0).collect();
    let k = first_record(&evals);
    // a threshold just below check k's Eval, above every earlier one
    let threshold = evals[k] - 1e-12;
    assert_eq!(
        first_formation(500, threshold, false, sim::config::SuccessSignal::Eval),
        Some(500 * k as u64)
    );
    assert_eq!(
        first_formation(500, threshold, true, sim::config::SuccessSignal::Eval),
        Some(500 * (k as u64 + 1))
    );
}

#[test]
fn checks_can_test_eval_prime_instead_of_eval() {
    let signals = signals_at_checks(500, 30);
    let primes: Vec<f64> = signals.iter().map(|s| s.1).collect();
    let k = first_record(&primes);
    let threshold = primes[k] - 1e-12;
    assert_eq!(
        first_formation(500, threshold, false, sim::config::SuccessSignal::EvalPrime),
        Some(500 * k as u64)
    );
    // Eval crosses that threshold at another check (or never) in this run
    let by_eval = signals.iter().position(|s| s.0 > threshold);
    assert_ne!(
        by_eval,
        Some(k),
        "the test needs Eval and Eval' to differ: {signals:?}"
    );
}

#[test]
fn a_checkpoint_of_a_stale_checking_run_resumes_bit_exactly() {
    let stale = || {
        let mut config = SimConfig::default();
        config.world.innies = 4;
        config.episode.check_interval = 1000;
        config.episode.stale_eval = true;
        config.episode.success_eval = 0.8;
        Simulation::new(config, Arc::new(ScalarField::annulus()), 3).unwrap()
    };
    let mut controller = oc();
    let mut straight = stale();
    straight.run(&mut controller, 9000);
    assert!(
        straight.totals().formations > 0,
        "the run should form: {:?}",
        straight.totals()
    );

    let mut first = stale();
    first.run(&mut controller, 4500);
    assert!(first.state().checked_signal.is_some());
    let state: SimulationState =
        serde_json::from_str(&serde_json::to_string(first.state()).unwrap()).unwrap();
    let sensors = sim::sensors::disc::DiscSensors::new(
        &state.config.sensors,
        state.config.world.robot_radius,
    );
    let mut resumed = Simulation::resume(state, Arc::new(ScalarField::annulus()), sensors);
    resumed.run(&mut controller, 4500);
    assert!(final_state(&resumed) == final_state(&straight));
}
