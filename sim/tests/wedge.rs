//! The wedge-fronted robots (`RobotShape::Wedge`): contacts against
//! hand-computed cases, no lasting overlap and no energy gained over long
//! runs, the camera's view of a wedge, and runs deterministic per seed that
//! resume exactly.
//!
//! The robots have a round back of radius 10 and the tip 13 ahead, so the
//! faces touch the circle at `cos b = 10/13` off the heading; mass 100
//! (the disc's). Pucks have radius 5 (mass 50) unless said otherwise.

use rand::{RngExt, SeedableRng};
use shared::ActionTable;
use sim::base::rng::SimRng;
use sim::config::robot_shape::RobotShape;
use sim::config::Walls;
use sim::control::random::RandomTurns;
use sim::physics::outline::Outline;
use sim::scenario::arena::{ArenaSpec, SkirtShape};
use sim::scenario::sensor_setup::{SelectedSensors, SensorSetup};
use sim::sensors::robot::RobotSensorConfig;
use sim::{
    base::vec2::Vec2, config::SimConfig, fields::ScalarField, physics::body::Body,
    physics::body::RobotKind, simulation::Simulation, world::World, world::WorldState,
};
use std::sync::Arc;

const TIP: f64 = 13.0;
const COS_B: f64 = 10.0 / 13.0;

fn sin_b() -> f64 {
    (1.0 - COS_B * COS_B).sqrt()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

fn near(a: Vec2, b: Vec2) -> bool {
    close(a.x, b.x) && close(a.y, b.y)
}

/// The thesis' square with wedge robots, pucks of radius 5, robots
/// driving at 1 unit per step, and wall segments (the TV's border; the
/// clamping border has its own test).
fn config() -> SimConfig {
    let mut c = SimConfig::default();
    c.physics.walls = Walls::Segments;
    c.world.robot_shape = RobotShape::Wedge { tip: TIP };
    c.world.puck_radius = 5.0;
    c.world.forward_speed = 1.0;
    c
}

/// One step of a scene of robots (position, heading) and pucks
/// (position, velocity), every robot going straight.
fn step_scene(config: &SimConfig, robots: &[(Vec2, f64)], pucks: &[(Vec2, Vec2)]) -> World {
    let robots: Vec<_> = robots
        .iter()
        .map(|&(p, h)| (p, h, RobotKind::Outie))
        .collect();
    let positions: Vec<Vec2> = pucks.iter().map(|p| p.0).collect();
    let mut state: WorldState = World::scene(config, &robots, &positions, 1).state().clone();
    for (k, p) in pucks.iter().enumerate() {
        state.bodies[robots.len() + k].vel = p.1;
    }
    let mut world = World::from_state(state);
    world.step(&vec![0.0; robots.len()]);
    world
}

#[test]
fn a_puck_met_head_on_at_the_tip_is_carried_ahead() {
    // The tip (13 ahead) is 0.5 from the puck's edge; after the robot's
    // step of 1 it is 0.5 into it, so the puck leaves along the heading.
    let w = step_scene(
        &config(),
        &[(Vec2::new(100.0, 100.0), 0.0)],
        &[(Vec2::new(118.5, 100.0), Vec2::ZERO)],
    );
    let (robot, puck) = (w.bodies()[0], w.bodies()[1]);
    // Overlap 0.5 split by mass shares 1/3 (robot) and 2/3 (puck).
    assert!(close(robot.pos.x, 101.0 - 0.5 / 3.0) && close(robot.pos.y, 100.0));
    assert!(close(puck.pos.x, 118.5 + 1.0 / 3.0) && close(puck.pos.y, 100.0));
    // Impulse along x: robot 0.6 after deceleration, puck at rest;
    // p = 2 x 0.6 / 150.
    let p = 1.2 / 150.0;
    assert!(close(robot.vel.x, 0.6 - p * 50.0), "{:?}", robot.vel);
    assert!(
        close(puck.vel.x, p * 100.0) && close(puck.vel.y, 0.0),
        "{:?}",
        puck.vel
    );
    assert_eq!(w.contacts().len(), 1);
    // A disc robot of radius 10 would not have reached it.
    let mut disc = config();
    disc.world.robot_shape = RobotShape::Disc;
    let w = step_scene(
        &disc,
        &[(Vec2::new(100.0, 100.0), 0.0)],
        &[(Vec2::new(118.5, 100.0), Vec2::ZERO)],
    );
    assert!(w.contacts().is_empty());
}

#[test]
fn a_puck_met_off_centre_on_a_face_is_pushed_out_along_that_face_s_normal() {
    let (cos_b, sin_b) = (COS_B, sin_b());
    let tangent = Vec2::new(10.0 * cos_b, 10.0 * sin_b);
    let tip = Vec2::new(TIP, 0.0);
    for side in [1.0, -1.0] {
        // The puck's centre 5.3 out along the normal from the middle of
        // the right (side 1, +y) or left face: 0.3 from touching.
        let normal = Vec2::new(cos_b, side * sin_b);
        let mid = (Vec2::new(tangent.x, side * tangent.y) + tip) * 0.5;
        let robot = Vec2::new(100.0, 100.0);
        let start = robot + mid + normal * 5.3;
        let w = step_scene(&config(), &[(robot, 0.0)], &[(start, Vec2::ZERO)]);
        let (r, p) = (w.bodies()[0], w.bodies()[1]);
        // The robot's step of 1 along x closes the gap by cos b.
        let overlap = cos_b - 0.3;
        assert!(
            near(
                r.pos,
                robot + Vec2::new(1.0, 0.0) - normal * (overlap / 3.0)
            ),
            "{:?}",
            r.pos
        );
        assert!(
            near(p.pos, start + normal * (overlap * 2.0 / 3.0)),
            "{:?}",
            p.pos
        );
        // Impulse along the face's normal: the puck is deflected to the
        // robot's side, not carried along the heading.
        let k = 2.0 * 0.6 * cos_b / 150.0;
        assert!(near(p.vel, normal * (k * 100.0)), "{:?}", p.vel);
        assert!(
            near(r.vel, Vec2::new(0.6, 0.0) - normal * (k * 50.0)),
            "{:?}",
            r.vel
        );
        assert_eq!(p.vel.y.signum(), side);
    }
}

#[test]
fn a_puck_on_the_round_back_meets_the_disc_it_is() {
    // A standing robot (speed 0) and a puck thrown at its back: the round
    // back is the disc's circle, so the result is the disc's.
    let mut c = config();
    c.world.forward_speed = 0.0;
    let run = |c: &SimConfig| {
        step_scene(
            c,
            &[(Vec2::new(100.0, 100.0), 0.0)],
            &[(Vec2::new(84.0, 100.0), Vec2::new(2.0, 0.0))],
        )
    };
    let w = run(&c);
    let (r, p) = (w.bodies()[0], w.bodies()[1]);
    // The puck moves to 86 (v 1.2): 1 deep; split 2/3 (puck), 1/3 (robot).
    assert!(close(p.pos.x, 86.0 - 2.0 / 3.0) && close(r.pos.x, 100.0 + 1.0 / 3.0));
    let k = 2.0 * 1.2 / 150.0;
    assert!(close(p.vel.x, 1.2 - k * 100.0) && close(r.vel.x, k * 50.0));
    c.world.robot_shape = RobotShape::Disc;
    let disc = run(&c);
    for (a, b) in w.bodies().iter().zip(disc.bodies()) {
        assert!(near(a.pos, b.pos) && near(a.vel, b.vel), "{a:?} {b:?}");
    }
}

#[test]
fn a_wedge_stops_at_a_wall_tip_first_and_fits_a_corner_by_its_round_back() {
    let c = config();
    // Facing the right wall with the tip 0.5 from it: after the step the
    // tip touches it, the robot 13 from the wall (a disc stops at 10), its
    // velocity into the wall reversed.
    let w = step_scene(&c, &[(Vec2::new(800.0 - 13.5, 400.0), 0.0)], &[]);
    let r = w.bodies()[0];
    assert!(close(r.pos.x, 787.0) && close(r.vel.x, -0.6), "{r:?}");
    // At 45 degrees the round back reaches further than the tip
    // (13 cos 45 < 10): the wedge meets the wall as the disc does.
    let diagonal = std::f64::consts::FRAC_PI_4;
    let start = Vec2::new(800.0 - 10.5, 800.0 - 10.5);
    let w = step_scene(&c, &[(start, diagonal)], &[]);
    let r = w.bodies()[0];
    // Into the bottom-right corner: 0.707 - 0.5 deep in both walls, out
    // to 10 from each, and bounced off both as the disc is.
    assert!(near(r.pos, Vec2::new(790.0, 790.0)), "{:?}", r.pos);
    assert!(r.vel.x < 0.0 && r.vel.y < 0.0, "{:?}", r.vel);
    let mut disc = c.clone();
    disc.world.robot_shape = RobotShape::Disc;
    let d = step_scene(&disc, &[(start, diagonal)], &[]).bodies()[0];
    assert!(near(r.pos, d.pos) && near(r.vel, d.vel), "{r:?} {d:?}");
    // Its tip stays 10 - 13 cos 45 from each wall.
    let tip = r.pos + Vec2::from_angle(diagonal) * TIP;
    assert!(close(800.0 - tip.x, 10.0 - TIP * diagonal.cos()));
}

#[test]
fn the_clamping_border_puts_a_wedge_back_by_its_tip_keeping_its_velocity() {
    // The thesis author's border: no wall bodies. The tip would be 0.5
    // past the right wall; the robot is put back where the tip touches it
    // (13 from the wall, a disc 10), its velocity kept (0.6 after the
    // deceleration), no contact recorded.
    let mut c = config();
    c.physics.walls = Walls::Clamp;
    let w = step_scene(&c, &[(Vec2::new(800.0 - 13.5, 400.0), 0.0)], &[]);
    let r = w.bodies()[0];
    assert!(close(r.pos.x, 787.0) && close(r.vel.x, 0.6), "{r:?}");
    assert!(w.contacts().is_empty());
    // Driving along the wall, the round back is what reaches past it
    // (0.5): put back to 10 from the wall, as a disc is.
    let w = step_scene(
        &c,
        &[(Vec2::new(800.0 - 9.5, 400.0), std::f64::consts::FRAC_PI_2)],
        &[],
    );
    let r = w.bodies()[0];
    assert!(close(r.pos.x, 790.0) && close(r.pos.y, 401.0), "{r:?}");
}

#[test]
fn wedges_meeting_tip_to_tip_glance_off_along_a_face() {
    // Facing each other, tips 1 apart; after their steps the tips have
    // passed each other by 1. The least way apart is not along the axis
    // (1) but across a face: the hull's depth is min over n of max(20 -
    // 25 n_x, 10 - 12 n_x, n_x), 10/13 at n_x = cos b.
    let w = step_scene(
        &config(),
        &[
            (Vec2::new(100.0, 100.0), 0.0),
            (Vec2::new(127.0, 100.0), std::f64::consts::PI),
        ],
        &[],
    );
    let (a, b) = (w.bodies()[0], w.bodies()[1]);
    let depth = 10.0 / 13.0;
    let shift = b.pos - Vec2::new(126.0, 100.0);
    // Each is moved half the depth along the face's normal, opposite ways.
    assert!(close(shift.length(), depth / 2.0), "{shift:?}");
    assert!(close(shift.x, depth / 2.0 * COS_B) && close(shift.y.abs(), depth / 2.0 * sin_b()));
    assert!(near(a.pos - Vec2::new(101.0, 100.0), -shift), "{:?}", a.pos);
    // The impulse along that normal: p = 2 (n . (0.6 - -0.6, 0)) / 200.
    let n = shift * (1.0 / shift.length());
    let k = 2.0 * n.x * 1.2 / 200.0;
    assert!(
        near(a.vel, Vec2::new(0.6, 0.0) - n * (k * 100.0)),
        "{:?}",
        a.vel
    );
    assert!(
        near(b.vel, Vec2::new(-0.6, 0.0) + n * (k * 100.0)),
        "{:?}",
        b.vel
    );
    assert_eq!(w.robot_contacts(), 1);
}

#[test]
fn a_wedge_s_tip_against_another_s_side_pushes_along_that_side_s_radius() {
    // Robot 0 against the right wall facing it (held at 787); robot 1
    // above it facing down, its tip 0.5 from robot 0's side (the round
    // back's top, (787, 390)). After the step robot 1's tip is 0.5 into
    // it; the least way apart is straight up: 10 + 13 - 22.5.
    let w = step_scene(
        &config(),
        &[
            (Vec2::new(787.0, 400.0), 0.0),
            (Vec2::new(787.0, 376.5), std::f64::consts::FRAC_PI_2),
        ],
        &[],
    );
    let (side, tip) = (w.bodies()[0], w.bodies()[1]);
    assert!(near(side.pos, Vec2::new(787.0, 400.25)), "{:?}", side.pos);
    assert!(near(tip.pos, Vec2::new(787.0, 377.25)), "{:?}", tip.pos);
    // Impulses in the order found: robot 0's wall first (its stand-in at
    // (800, 400), where the contact was found, moving at (-0.6, 0)), then
    // the two robots along (0, -1).
    let mut after_wall = Body::new(side.pos, 10.0);
    after_wall.vel = Vec2::new(0.6, 0.0);
    let mut stand_in = Body::new(Vec2::new(800.0, 400.0), 10.0);
    stand_in.vel = Vec2::new(-0.6, 0.0);
    sim::physics::elastic_impulse(&mut after_wall, &mut stand_in);
    let mut moving = Body::new(tip.pos, 10.0);
    moving.vel = Vec2::new(0.0, 0.6);
    sim::physics::impulse_along(&mut after_wall, &mut moving, Vec2::new(0.0, -1.0));
    assert!(
        near(side.vel, after_wall.vel),
        "{:?} {:?}",
        side.vel,
        after_wall.vel
    );
    assert!(near(tip.vel, moving.vel), "{:?}", tip.vel);
    // Along (0, -1) the two exchange their y velocities: robot 1 all but
    // stops (robot 0's wall, its normal tilted by 0.25 in 13, left robot
    // 0 a y velocity of about -0.02).
    assert!(
        tip.vel.y.abs() < 0.05 && (side.vel.y - 0.6).abs() < 0.05,
        "{tip:?} {side:?}"
    );
}

/// The deepest overlap in `world`: of any two bodies (by their outlines)
/// and of any body with a wall.
fn deepest(world: &World) -> f64 {
    let c = world.config();
    let outline = Outline::of(c.robot_shape, c.robot_radius);
    let robots = world.robots().len();
    let bodies = world.bodies();
    let facing = |i: usize| world.robots()[i].direction;
    let mut deepest = f64::NEG_INFINITY;
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let delta = bodies[j].pos - bodies[i].pos;
            let depth = match (outline, i < robots, j < robots) {
                (Some(o), true, true) => o.pair_depth(facing(i), facing(j), delta).0,
                (Some(o), true, false) => o.circle_depth(facing(i), delta, bodies[j].radius).0,
                _ => bodies[i].radius + bodies[j].radius - delta.length(),
            };
            deepest = deepest.max(depth);
        }
        let reach = |n: Vec2| match outline.filter(|_| i < robots) {
            Some(o) => o.support(facing(i), n),
            None => bodies[i].radius,
        };
        let p = bodies[i].pos;
        for depth in [
            reach(Vec2::new(-1.0, 0.0)) - p.x,
            reach(Vec2::new(1.0, 0.0)) - (c.arena_width - p.x),
            reach(Vec2::new(0.0, -1.0)) - p.y,
            reach(Vec2::new(0.0, 1.0)) - (c.arena_height - p.y),
        ] {
            deepest = deepest.max(depth);
        }
    }
    deepest
}

/// tv75, whose robots wear the thesis' wedge.
fn tv75_wedge() -> ArenaSpec {
    ArenaSpec::tv75()
}

#[test]
fn tv75_is_in_the_thesis_skirt_and_its_disc_file_differs_only_in_the_outline() {
    assert_eq!(ArenaSpec::tv75().robot_shape, SkirtShape::thesis_wedge());
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/arenas/tv75-disc.toml");
    let disc = sim::scenario::arena_choice::read_arena(&path).unwrap();
    assert_eq!(
        disc,
        ArenaSpec {
            name: "tv75-disc".into(),
            robot_shape: SkirtShape::Disc,
            ..ArenaSpec::tv75()
        }
    );
    let spec = tv75_wedge();
    // 85 mm over 6.5 mm per unit; the faces meet at 2 asin(65 / 85).
    assert_eq!(
        spec.robot_shape_units(),
        RobotShape::Wedge { tip: 85.0 / 6.5 }
    );
    let o = Outline::of(spec.robot_shape_units(), 10.0).unwrap();
    assert!(
        (o.tip_angle().to_degrees() - 99.76).abs() < 0.01,
        "{}",
        o.tip_angle().to_degrees()
    );
}

#[test]
fn an_arena_file_s_tip_outside_its_range_is_refused_naming_it() {
    for tip_mm in [65.0, 40.0, 196.0, f64::NAN] {
        let spec = ArenaSpec {
            robot_shape: SkirtShape::Wedge { tip_mm },
            ..ArenaSpec::tv75()
        };
        let e = spec.validate().unwrap_err().to_string();
        assert!(
            e.contains("arena.robot_shape.wedge.tip_mm / arena.robot_radius_mm"),
            "{e}"
        );
    }
}

/// A crowded TV: 12 wedge robots and 30 pucks turning at random.
fn crowded(shape: RobotShape, seed: u64) -> Simulation {
    let tv = ArenaSpec::tv75();
    let field = ScalarField::annulus_of(64, 36);
    let mut c = SimConfig::default();
    tv.apply(&mut c, &field);
    c.world.robot_shape = shape;
    c.world.robots = 12;
    c.world.pucks = 30;
    Simulation::new(c, Arc::new(field), seed).unwrap()
}

#[test]
fn crowded_wedges_leave_no_overlap_once_they_stop_pushing() {
    // Robots driving into crowds of pucks press them into each other and
    // the walls deeper than one pass of resolution undoes, discs and
    // wedges alike; once they stop driving, every overlap is resolved
    // within a few steps.
    for shape in [RobotShape::Disc, tv75_wedge().robot_shape_units()] {
        let mut sim = crowded(shape, 11);
        let mut controller = RandomTurns::new(ActionTable::default());
        let mut deepest_seen = f64::NEG_INFINITY;
        for _ in 0..20_000 {
            sim.run(&mut controller, 1);
            deepest_seen = deepest_seen.max(deepest(sim.world()));
        }
        assert!(
            deepest_seen > 1.0,
            "{shape:?}: the crowd was pressed ({deepest_seen})"
        );
        let mut state = sim.world().state().clone();
        state.config.forward_speed = 0.0;
        let mut world = World::from_state(state);
        let threshold = world.state().physics.overlap_threshold;
        let settled = (0..200).position(|_| {
            world.step(&[0.0; 12]);
            deepest(&world) <= threshold + 1e-9
        });
        assert!(
            settled.is_some_and(|s| s < 50),
            "{shape:?}: still {} deep after 200 steps",
            deepest(&world)
        );
    }
}

#[test]
fn standing_wedges_hit_by_sliding_pucks_gain_no_energy_over_a_long_run() {
    // No deceleration, robots standing: a contact exchanges energy
    // elastically and a robot's is dropped at its next step. (A wall's
    // stand-in moves at minus the body's velocity when the contact was
    // found, so a body whose velocity another contact of the same step
    // changed first can leave a wall a little faster, with discs as with
    // wedges: energy may rise in a step, never above where it started.)
    for shape in [RobotShape::Disc, RobotShape::Wedge { tip: TIP }] {
        let mut c = config();
        c.world.robot_shape = shape;
        c.world.forward_speed = 0.0;
        c.world.arena_width = 200.0;
        c.world.arena_height = 200.0;
        c.world.robots = 6;
        c.world.pucks = 30;
        c.physics.deceleration = 0.0;
        let mut state = World::new(&c, 4).unwrap().state().clone();
        let mut rng = SimRng::seed_from_u64(9);
        for b in &mut state.bodies[6..] {
            b.vel = Vec2::from_angle(rng.random_range(0.0..std::f64::consts::TAU)) * 1.5;
        }
        let energy = |bodies: &[Body]| {
            bodies
                .iter()
                .map(|b| 0.5 * b.mass * b.vel.length_squared())
                .sum::<f64>()
        };
        let mut world = World::from_state(state);
        let (start, mut highest, mut robot_contacts) = (energy(world.bodies()), 0.0f64, 0);
        for _ in 0..20_000 {
            world.step(&[0.0; 6]);
            highest = highest.max(energy(world.bodies()));
            robot_contacts += world
                .contacts()
                .iter()
                .filter(|c| matches!(c, sim::physics::Contact::Bodies(a, b) if *a.min(b) < 6))
                .count();
        }
        assert!(
            robot_contacts > 100,
            "{shape:?}: the pucks hit the robots: {robot_contacts}"
        );
        assert!(
            highest <= start * (1.0 + 1e-12),
            "{shape:?}: {highest} above the start's {start}"
        );
        assert!(
            energy(world.bodies()) < start / 2.0,
            "{shape:?}: the robots absorb energy"
        );
    }
}

/// A TV run with the robot's senses and the default noise, the robots in
/// the thesis' wedge.
fn tv_run(seed: u64) -> Simulation<SelectedSensors> {
    let tv = tv75_wedge();
    let field = ScalarField::annulus_of(64, 36);
    let mut c = SimConfig::default();
    tv.apply(&mut c, &field);
    c.world.actuation = sim::config::actuation::ActuationNoise::randomised();
    assert!(!c.world.robot_shape.is_disc());
    let robot = RobotSensorConfig {
        noise: sim::sensors::robot_noise::RobotNoise::randomised(),
        ..RobotSensorConfig::default()
    };
    let sensors = SensorSetup::Robot(Box::new(robot)).build(&c);
    Simulation::with_sensors(c, Arc::new(field), sensors, seed).unwrap()
}

fn positions(sim: &mut Simulation<SelectedSensors>, steps: u64) -> Vec<(f64, f64)> {
    let mut controller = RandomTurns::new(ActionTable::default());
    sim.run(&mut controller, steps);
    sim.world()
        .bodies()
        .iter()
        .map(|b| (b.pos.x, b.pos.y))
        .collect()
}

#[test]
fn a_wedge_run_is_the_same_for_the_same_seed_and_resumes_exactly_from_a_snapshot() {
    let whole = positions(&mut tv_run(6), 3000);
    assert_eq!(whole, positions(&mut tv_run(6), 3000));
    assert_ne!(whole, positions(&mut tv_run(7), 3000));
    let mut first = tv_run(6);
    positions(&mut first, 1200);
    let saved = serde_json::to_string(&first.snapshot()).unwrap();
    let state: sim::simulation::SimulationState = serde_json::from_str(&saved).unwrap();
    assert!(
        !state.world.config().robot_shape.is_disc(),
        "the outline is saved"
    );
    let sensors = SensorSetup::Robot(Box::new(RobotSensorConfig {
        noise: sim::sensors::robot_noise::RobotNoise::randomised(),
        ..RobotSensorConfig::default()
    }))
    .build(first.config());
    let mut resumed = Simulation::resume(state, Arc::new(first.field().clone()), sensors);
    assert_eq!(positions(&mut resumed, 1800), whole);
}

/// `docs/robot-sensors/skirt.svg`: the thesis' skirt on the TV's robots
/// (tv75's) drawn to scale, 2 pixels per
/// mm, heading up: the outline, the Zumo's 98 x 86 mm chassis, the three
/// photo-transistors where the sensor model puts them, the Pixy's lens,
/// and the disc of tv75's radius for comparison. Every figure is the
/// code's.
fn skirt_svg() -> String {
    let spec = tv75_wedge();
    let unit = spec.unit_mm();
    let o = Outline::of(spec.robot_shape_units(), 10.0).unwrap();
    let (r, tip) = (o.radius() * unit, o.tip() * unit);
    let t = o.tangent_point() * unit;
    let world = sim::config::WorldConfig {
        unit_mm: unit,
        robot_shape: spec.robot_shape_units(),
        ..Default::default()
    };
    let mounts = sim::sensors::photo::PhotoSensorConfig::default().mounts_on(&world);
    let lens = sim::sensors::pixy_camera::PixyCameraConfig::default().forward_mm;
    // SVG: x to the robot's right, y down the page (minus ahead), mm.
    let p = |forward: f64, right: f64| format!("{:.2} {:.2}", right, -forward);
    let mut s = String::new();
    s.push_str(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"360\" height=\"440\" \
         viewBox=\"-90 -110 180 220\" font-family=\"sans-serif\" font-size=\"4\">\n",
    );
    s.push_str("<rect x=\"-90\" y=\"-110\" width=\"180\" height=\"220\" fill=\"white\"/>\n");
    s.push_str(&format!(
        "<circle cx=\"0\" cy=\"0\" r=\"{r:.2}\" fill=\"none\" stroke=\"#999\" stroke-dasharray=\"2 2\" stroke-width=\"0.5\"/>\n"
    ));
    s.push_str(&format!(
        "<path d=\"M {} L {} A {r:.2} {r:.2} 0 1 1 {} Z\" fill=\"#cfe0ff\" fill-opacity=\"0.6\" stroke=\"#1f4fbf\" stroke-width=\"0.8\"/>\n",
        p(tip, 0.0),
        p(t.x, t.y),
        p(t.x, -t.y)
    ));
    s.push_str(
        "<rect x=\"-43\" y=\"-49\" width=\"86\" height=\"98\" fill=\"none\" stroke=\"#333\" stroke-width=\"0.6\"/>\n",
    );
    for (m, name) in mounts.iter().zip(["DN1", "DN3", "DN5"]) {
        s.push_str(&format!(
            "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"1.5\" fill=\"#d62728\"/><text x=\"{:.2}\" y=\"{:.2}\">{name}</text>\n",
            m.right_mm,
            -m.forward_mm,
            m.right_mm + 3.0,
            -m.forward_mm + 6.0
        ));
    }
    s.push_str(&format!(
        "<rect x=\"-2\" y=\"{:.2}\" width=\"4\" height=\"4\" fill=\"#2ca02c\"/><text x=\"4\" y=\"{:.2}\">Pixy lens</text>\n",
        -lens - 2.0,
        -lens + 2.0
    ));
    s.push_str(
        "<line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"-20\" stroke=\"#1f4fbf\" stroke-width=\"0.5\"/>\n",
    );
    for (k, line) in [
        format!("round back: radius {r:.0} mm (dashed: tv75's disc)"),
        format!(
            "tip {tip:.0} mm ahead; faces tangent {:.1} mm ahead, {:.1} mm aside",
            t.x, t.y
        ),
        format!("angle at the tip {:.1} degrees", o.tip_angle().to_degrees()),
        "chassis 98 x 86 mm (Zumo 32U4); 1 mm = 2 px".to_string(),
    ]
    .iter()
    .enumerate()
    {
        s.push_str(&format!(
            "<text x=\"-88\" y=\"{}\">{line}</text>\n",
            80 + 7 * k
        ));
    }
    s.push_str("</svg>\n");
    s
}

#[test]
fn the_skirt_drawing_in_the_docs_is_the_outline_drawn_to_scale() {
    // REGENERATE_DOCS=1 cargo test -p sim --test wedge writes it.
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/robot-sensors/skirt.svg");
    let svg = skirt_svg();
    if std::env::var_os("REGENERATE_DOCS").is_some() {
        std::fs::write(&path, &svg).unwrap();
    }
    let published = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        published == svg,
        "docs/robot-sensors/skirt.svg is not the outline's drawing; regenerate it with REGENERATE_DOCS=1 cargo test -p sim --test wedge"
    );
}
