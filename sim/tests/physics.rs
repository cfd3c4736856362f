//! Physics: impulses, walls, sliding pucks, and grid vs all-pairs identity.

use shared::ActionTable;
use sim::control::random::RandomTurns;
use sim::physics::elastic_impulse;
use sim::{
    base::vec2::Vec2, config::BroadPhase, config::SimConfig, physics::body::Body,
    physics::body::RobotKind, simulation::Simulation, world::World, world::WorldState,
};
use std::sync::Arc;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

#[test]
fn impulse_between_unequal_bodies_conserves_momentum_and_energy() {
    let mut a = Body::new(Vec2::new(0.0, 0.0), 10.0);
    let mut b = Body::new(Vec2::new(14.0, 0.0), 5.0);
    a.vel = Vec2::new(1.0, 0.5);
    b.vel = Vec2::new(-1.0, 0.0);
    let momentum = |a: &Body, b: &Body| a.vel * a.mass + b.vel * b.mass;
    let energy = |a: &Body, b: &Body| {
        0.5 * (a.mass * a.vel.length_squared() + b.mass * b.vel.length_squared())
    };
    let (p0, e0) = (momentum(&a, &b), energy(&a, &b));
    elastic_impulse(&mut a, &mut b);
    // masses 100 and 50; along x: k = 2, p = 4 / 150; v_a = 1 - p 50, v_b = -1 + p 100
    assert!(
        close(a.vel.x, -1.0 / 3.0) && close(b.vel.x, 5.0 / 3.0),
        "{:?} {:?}",
        a.vel,
        b.vel
    );
    assert_eq!(
        (a.vel.y, b.vel.y),
        (0.5, 0.0),
        "no change across the centre line"
    );
    let p1 = momentum(&a, &b);
    assert!(close(p0.x, p1.x) && close(p0.y, p1.y));
    assert!(close(e0, energy(&a, &b)));
}

/// Robot body 0 (radius 10) moving right at 1, puck (radius 5) moving left.
fn head_on() -> World {
    let mut config = SimConfig::default();
    config.world.puck_radius = 5.0;
    config.world.forward_speed = 1.0;
    let world = World::scene(
        &config,
        &[(Vec2::new(100.0, 100.0), 0.0, RobotKind::Outie)],
        &[Vec2::new(115.5, 100.0)],
        1,
    );
    let mut state: WorldState = world.state().clone();
    state.bodies[1].vel = Vec2::new(-1.0, 0.0);
    World::from_state(state)
}

#[test]
fn a_contact_step_matches_the_hand_computed_result() {
    let mut w = head_on();
    w.step(&[0.0]);
    // integrate: robot 101 (v 0.6), puck 114.5 (v -0.6); overlap 1.5 split
    // by mass shares 1/3, 2/3; impulse k = 1.2, p = 2.4 / 150.
    let (r, p) = (w.bodies()[0], w.bodies()[1]);
    assert!(
        close(r.pos.x, 100.5) && close(p.pos.x, 115.5),
        "{:?} {:?}",
        r.pos,
        p.pos
    );
    assert!(close(r.vel.x, 0.6 - 2.4 / 150.0 * 50.0), "{:?}", r.vel);
    assert!(close(p.vel.x, -0.6 + 2.4 / 150.0 * 100.0), "{:?}", p.vel);
    assert!(close(
        r.vel.x * r.mass + p.vel.x * p.mass,
        0.6 * 100.0 - 0.6 * 50.0
    ));
    assert_eq!(w.contacts().len(), 1);
}

/// A puck half a unit from the left border moving into it at (-2, 0.5),
/// one step later, with the border `walls`.
fn a_puck_at_the_border_after_one_step(walls: sim::config::Walls) -> World {
    let mut config = SimConfig::default();
    config.physics.walls = walls;
    let robot_far = (Vec2::new(400.0, 400.0), 0.0, RobotKind::Outie);
    let mut state = World::scene(&config, &[robot_far], &[Vec2::new(10.5, 400.0)], 1)
        .state()
        .clone();
    state.bodies[1].vel = Vec2::new(-2.0, 0.5);
    let mut w = World::from_state(state);
    w.step(&[0.0]);
    w
}

#[test]
fn a_wall_contact_reverses_the_velocity_into_the_wall() {
    let w = a_puck_at_the_border_after_one_step(sim::config::Walls::Segments);
    let p = w.bodies()[1];
    // after integration v = (-1.2, 0.3); the wall reflects x and keeps y
    assert!(close(p.vel.x, 1.2) && close(p.vel.y, 0.3), "{:?}", p.vel);
    assert!(
        close(p.pos.x, 10.0),
        "pushed out to touch the wall: {:?}",
        p.pos
    );
}

#[test]
fn a_clamping_border_puts_a_body_back_and_keeps_its_velocity() {
    let w = a_puck_at_the_border_after_one_step(sim::config::Walls::Clamp);
    let p = w.bodies()[1];
    // after integration x = 8.5, v = (-1.2, 0.3): clamped to its radius,
    // no contact, no impulse
    assert!(close(p.pos.x, 10.0), "{:?}", p.pos);
    assert!(close(p.vel.x, -1.2) && close(p.vel.y, 0.3), "{:?}", p.vel);
    assert!(w.contacts().is_empty(), "{:?}", w.contacts());
}

#[test]
fn pushed_pucks_slow_down_and_stop() {
    let config = SimConfig::default();
    let robot_far = (Vec2::new(700.0, 700.0), 0.0, RobotKind::Outie);
    let mut state = World::scene(&config, &[robot_far], &[Vec2::new(300.0, 300.0)], 1)
        .state()
        .clone();
    state.bodies[1].vel = Vec2::new(1.5, -0.5);
    let mut w = World::from_state(state);
    let mut last_speed = f64::INFINITY;
    for _ in 0..40 {
        w.step(&[0.3]);
        let speed = w.bodies()[1].vel.length();
        assert!(speed < last_speed || speed == 0.0);
        last_speed = speed;
    }
    assert_eq!(w.bodies()[1].vel, Vec2::ZERO);
    let rest = w.bodies()[1].pos;
    w.step(&[0.3]);
    assert_eq!(w.bodies()[1].pos, rest);
    // slid 1.5 / 0.4 = 3.75 along x at most
    assert!(rest.x > 303.0 && rest.x < 303.75, "{rest:?}");
}

/// A dense world (24 robots, 400 pucks in an arena of `width` x `height`)
/// under random turns; the final bodies, robots and generator, serialised.
fn dense_run(broad_phase: BroadPhase, (width, height): (f64, f64), steps: u64) -> String {
    let mut config = SimConfig::default();
    config.world.arena_width = width;
    config.world.arena_height = height;
    config.world.robots = 24;
    config.world.pucks = 400;
    config.world.broad_phase = broad_phase;
    let field = Arc::new(sim::fields::ScalarField::annulus());
    let mut sim = Simulation::new(config, field, 7).unwrap();
    let mut controller = RandomTurns::new(ActionTable::default());
    sim.run(&mut controller, steps);
    let w = sim.world().state();
    serde_json::to_string(&(&w.bodies, &w.robots, &w.rng, w.steps)).unwrap()
}

#[test]
fn grid_and_all_pairs_give_bit_identical_trajectories() {
    let grid = dense_run(BroadPhase::Grid, (500.0, 500.0), 10_000);
    let naive = dense_run(BroadPhase::Naive, (500.0, 500.0), 10_000);
    assert!(grid == naive, "trajectories differ");
}

#[test]
fn grid_and_all_pairs_agree_in_a_rectangular_arena_and_every_body_stays_inside_its_walls() {
    let grid = dense_run(BroadPhase::Grid, (700.0, 330.0), 6_000);
    let naive = dense_run(BroadPhase::Naive, (700.0, 330.0), 6_000);
    assert!(grid == naive, "trajectories differ");
    let (bodies, ..): (Vec<Body>, serde_json::Value, serde_json::Value, u64) =
        serde_json::from_str(&grid).unwrap();
    // Within the walls, up to the overlap a step's motion can leave before
    // the next step resolves it (speed 2, overlap threshold 0.1).
    let slack = 2.1;
    for b in &bodies {
        assert!(
            b.pos.x >= b.radius - slack && b.pos.x <= 700.0 - b.radius + slack,
            "{b:?}"
        );
        assert!(
            b.pos.y >= b.radius - slack && b.pos.y <= 330.0 - b.radius + slack,
            "{b:?}"
        );
    }
    assert!(
        bodies.iter().any(|b| b.pos.y > 300.0) && bodies.iter().any(|b| b.pos.x > 650.0),
        "the far walls are reached"
    );
}
