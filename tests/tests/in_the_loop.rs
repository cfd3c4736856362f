//! The firmware in the loop (`docs/in-the-loop.md`): the release ELF in
//! simavr, one instance per robot, drives the simulated world.
//!
//! - a closed-loop episode on the annulus (5 robots on the TV, default
//!   noise) whose every period is decided as the policy does on the
//!   firmware's own logged readings, with wheel speeds from the pins;
//! - a firmware held on a stimulus whose action is the sharpest turn
//!   circles as the robot profile predicts;
//! - a negative control: an ELF of another policy, checked against the
//!   loop's policy, is inconsistent in most periods;
//! - determinism per seed;
//! - fast-forwarding the firmwares' busy waits changes nothing: the same
//!   frames, counters and world as simulating every cycle.
//!
//! The ELFs come from `scripts/test`; a missing or stale one fails with
//! the command that builds it.

use shared::{ActionId, MotorCommand, PolicyBlob, RobotProfile, Role};
use sim::fields::source::FieldSource;
use sim::sensors::robot::{RobotSensorConfig, RobotSensors};
use tests::equivalence::{
    cycles_of_ticks, is_robust, read_policy, Expectation, Variant, EIGHT_BIT, ROLE,
};
use tests::in_the_loop::{InTheLoop, LoopCounts, Stimulus, World};
use tests::zumo::firmware_elf_in;

/// Steps of the closed-loop episode.
const EPISODE_STEPS: u64 = 600;
/// Steps of the runs with and without the busy wait skipped.
const SKIP_STEPS: u64 = 150;

fn policy_of(v: &Variant) -> PolicyBlob {
    read_policy(v.policy).unwrap_or_else(|e| panic!("{e:#}")).1
}

fn elf_of(v: &Variant) -> std::path::PathBuf {
    firmware_elf_in(v.elf_dir, v.build)
}

/// Five robots on the TV's annulus, the default noise.
fn annulus(seed: u64) -> World {
    World {
        field: FieldSource::Annulus,
        arena: None,
        robots: Some(5),
        pucks: None,
        noise: 1.0,
        seed,
    }
}

#[test]
fn a_closed_loop_episode_decides_as_the_policy_and_drives_from_the_pins() {
    let policy = policy_of(&ROLE);
    let scenario = annulus(5).scenario().unwrap();
    let mut run = InTheLoop::new(&elf_of(&ROLE), &policy, &scenario).unwrap();
    assert_eq!(run.robot_ids(), [1, 3, 0, 2, 4], "innies odd, outies even");
    let s = run.run(EPISODE_STEPS).unwrap();
    let c = &s.counts;
    println!("{}", serde_json::to_string_pretty(&s).unwrap());
    assert_eq!(c.periods, 5 * EPISODE_STEPS);
    assert_eq!(c.periods_checked, c.periods, "every period's frame arrived");
    assert_eq!(
        c.periods_consistent, c.periods,
        "decisions_consistent must be 1"
    );
    assert_eq!(
        c.periods_from_pins, c.periods,
        "every turn came from the pins"
    );
    assert_eq!(c.forward_mismatches, 0);
    // The world moved: turns differed between periods (not all straight).
    assert!(
        s.state_agreement > 0.8,
        "state agreement {}",
        s.state_agreement
    );
    assert_eq!(s.run.steps, EPISODE_STEPS);
}

/// Raw times (ticks) between the calibration's white and black screens
/// whose state, with an empty camera frame, the policy answers with
/// `action`, two ticks from every quantisation edge.
fn stimulus_for(policy: &PolicyBlob, model: &RobotSensors, action: ActionId) -> Option<[u16; 3]> {
    let e = Expectation::new(model, policy, Role::Outie);
    let state_of = |t: &[u16; 3]| e.state(t, &[]);
    let ranges = model.calibration().ranges;
    let level = |i: usize, k: u16| {
        let (b, d) = (ranges[i].bright, ranges[i].dark);
        b + (d - b) * k / 15
    };
    (0..16u16)
        .flat_map(|a| (0..16u16).flat_map(move |b| (0..16u16).map(move |c| [a, b, c])))
        .map(|[a, b, c]| [level(0, a), level(1, b), level(2, c)])
        .find(|t| policy.table().action(state_of(t)) == action && is_robust(t, &state_of))
}

#[test]
fn a_firmware_held_on_the_sharpest_turn_circles_as_the_profile_predicts() {
    let policy = policy_of(&EIGHT_BIT);
    // Action 0 turns right at 0.3 rad per step at 2 units per step: the
    // profile mixes it to motor commands 341 / -41 (shared::drive), which
    // the pins carry; read back, the tracks run (341 + 41) / 2 / 75 =
    // 2.0 units per step apart from the mean 2.0 and the robot turns
    // (341 + 41) / (1.5 x 50 x 17) = 382 / 1275 = 0.299608 rad per step.
    // Turning then moving 2.0 each step puts it on a circle of radius
    // 2.0 / (2 sin(0.299608 / 2)) = 6.7005 units.
    assert_eq!(
        RobotProfile::ZUMO.mix(2.0, 0.3),
        MotorCommand {
            left: 341,
            right: -41
        }
    );
    let (w, r) = (382.0 / 1275.0, 6.7005);
    let world = World {
        robots: Some(1),
        pucks: Some(1),
        noise: 0.0,
        ..annulus(7)
    };
    let scenario = world.scenario().unwrap();
    let config = RobotSensorConfig::default();
    let model = RobotSensors::new(&config, &sim::config::WorldConfig::default());
    let ticks = stimulus_for(&policy, &model, ActionId(0)).expect("a state that turns right");
    let mut run = InTheLoop::new(&elf_of(&EIGHT_BIT), &policy, &scenario).unwrap();
    run.hold_stimulus(Some(Stimulus {
        cycles: ticks.map(|t| cycles_of_ticks(t, config.field.poll_latency_us)),
        frame: Vec::new(),
    }));
    let mut path = Vec::new();
    let mut headings = Vec::new();
    // The first steps push the start's overlap apart (shorter moves).
    for _ in 0..10 {
        run.step().unwrap();
    }
    for _ in 0..50 {
        run.step().unwrap();
        let world = run.simulation().world();
        path.push(world.bodies()[0].pos);
        headings.push(world.robots()[0].heading);
    }
    // Each step turned by w.
    for h in headings.windows(2) {
        let turned = (h[1] - h[0]).rem_euclid(std::f64::consts::TAU);
        assert!((turned - w).abs() < 1e-5, "turned {turned}, not {w}");
    }
    // Every position on one circle of radius r: its centre from the first
    // three.
    let (a, b, c) = (path[0], path[1], path[2]);
    let d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    let n = |p: sim::base::vec2::Vec2| p.x * p.x + p.y * p.y;
    let centre = (
        (n(a) * (b.y - c.y) + n(b) * (c.y - a.y) + n(c) * (a.y - b.y)) / d,
        (n(a) * (c.x - b.x) + n(b) * (a.x - c.x) + n(c) * (b.x - a.x)) / d,
    );
    for p in &path {
        let radius = ((p.x - centre.0).powi(2) + (p.y - centre.1).powi(2)).sqrt();
        assert!((radius - r).abs() < 1e-3, "radius {radius}, not {r}");
    }
    let c = run.counts();
    assert_eq!(c.periods_from_pins, c.periods_checked);
}

#[test]
fn a_firmware_of_another_policy_diverges_from_the_loops_policy() {
    // The 8-bit annulus policy's ELF, checked against the role policy.
    let policy = policy_of(&ROLE);
    let scenario = annulus(5).scenario().unwrap();
    let mut run = InTheLoop::new(&elf_of(&EIGHT_BIT), &policy, &scenario).unwrap();
    let s = run.run(200).unwrap();
    println!("{}", serde_json::to_string_pretty(&s).unwrap());
    assert!(
        s.decisions_consistent < 0.5,
        "decisions consistent {} with another policy's firmware",
        s.decisions_consistent
    );
    assert!(
        s.state_agreement < 0.75,
        "state agreement {}",
        s.state_agreement
    );
}

#[test]
fn a_closed_loop_run_is_determined_by_its_seed() {
    let policy = policy_of(&ROLE);
    let elf = elf_of(&ROLE);
    let world_after = |seed: u64| {
        let scenario = annulus(seed).scenario().unwrap();
        let mut run = InTheLoop::new(&elf, &policy, &scenario).unwrap();
        let counts = run.run(150).unwrap().counts;
        (format!("{:?}", run.simulation().snapshot().world), counts)
    };
    let (a, b, c) = (world_after(9), world_after(9), world_after(10));
    assert_eq!(a, b);
    assert_ne!(a.0, c.0);
}

#[test]
fn skipping_the_busy_wait_changes_no_frame_counter_or_world() {
    let policy = policy_of(&ROLE);
    let elf = elf_of(&ROLE);
    let scenario = annulus(3).scenario().unwrap();
    let run_with = |skip: bool| {
        let mut run = InTheLoop::new(&elf, &policy, &scenario).unwrap();
        run.skip_waits(skip);
        run.record_frames();
        let s = run.run(SKIP_STEPS).unwrap();
        let world = format!("{:?}", run.simulation().snapshot());
        (s, run.recorded_frames().to_vec(), world)
    };
    let (skipped, skipped_frames, skipped_world) = run_with(true);
    let (simulated, simulated_frames, simulated_world) = run_with(false);
    println!(
        "skipped {} of {} cycles; {:.0} against {:.0} periods per second",
        skipped.counts.cycles_skipped,
        skipped.counts.avr_cycles,
        skipped.periods_per_second,
        simulated.periods_per_second
    );
    assert_eq!(simulated.counts.cycles_skipped, 0);
    // the fast-forward starts once an idle pass is found in the wait's USB
    // loop, a little into the wait: about half of every period is skipped
    assert!(
        skipped.counts.cycles_skipped as f64
            > 0.45 * skipped.cycles.period * skipped.counts.periods as f64,
        "the wait is about half the cycles: {:?}",
        skipped.counts
    );
    assert!(skipped_frames.len() as u64 >= 5 * SKIP_STEPS);
    assert_eq!(skipped_frames, simulated_frames, "the same log frames");
    assert_eq!(skipped_world, simulated_world, "the same world");
    let unskipped = LoopCounts {
        cycles_skipped: 0,
        ..skipped.counts.clone()
    };
    assert_eq!(unskipped, simulated.counts, "the same counters and cycles");
    assert_eq!(skipped.cycles.period, simulated.cycles.period);
    assert_eq!(skipped.cycles.sensing, simulated.cycles.sensing);
    assert_eq!(skipped.cycles.logging, simulated.cycles.logging);
}

#[test]
fn the_docs_tables_of_the_runs_are_the_ones_the_runs_json_gives() {
    let root = tests::figures::workspace();
    let json = std::fs::read_to_string(root.join("docs/in-the-loop-runs.json")).unwrap();
    let tables = tests::in_the_loop::runs_tables(&json).unwrap();
    let doc = std::fs::read_to_string(root.join("docs/in-the-loop.md")).unwrap();
    let (begin, end) = (RUNS_BEGIN, "<!-- in-the-loop-runs end -->");
    let section = doc
        .split_once(begin)
        .and_then(|(_, rest)| rest.split_once(end))
        .map(|(section, _)| section.trim())
        .expect("docs/in-the-loop.md marks the runs' tables");
    assert!(
        section == tables,
        "docs/in-the-loop.md's tables differ from docs/in-the-loop-runs.json's runs; between the \
         markers it must read:\n{tables}"
    );
}

/// The line before the runs' tables in `docs/in-the-loop.md`.
const RUNS_BEGIN: &str = "<!-- in-the-loop-runs begin: generated from docs/in-the-loop-runs.json \
                          by tests::in_the_loop::runs_tables (the test prints them); do not edit -->";
