//! Sensor golden cases: which disc sees what, and which field cells the
//! field sensors read.

use shared::{FieldValue, SensorReading};
use sim::{
    base::vec2::Vec2, config::disc_sensors::DiscSensorConfig, config::SimConfig,
    fields::ScalarField, physics::body::RobotKind, sensors::disc::DiscSensors,
    sensors::SensorModel, world::World,
};

const R: f64 = 10.0;
const ROBOT: Vec2 = Vec2::new(400.0, 400.0);

/// Robot 0 at (400, 400) facing +x (its right is +y, down on screen).
fn read(config: &SimConfig, kind: RobotKind, pucks: &[Vec2], robots: &[Vec2]) -> SensorReading {
    let mut placed = vec![(ROBOT, 0.0, kind)];
    placed.extend(robots.iter().map(|&p| (p, 0.0, RobotKind::Outie)));
    let world = World::scene(config, &placed, pucks, 1);
    let mut sensors = DiscSensors::new(&config.sensors, R);
    let mut out = vec![SensorReading::default(); placed.len()];
    sensors.sense(&world, &ScalarField::annulus(), &mut out);
    out[0]
}

/// A point at `angle_deg` (right of heading) and `distance` radii from the robot.
fn at(angle_deg: f64, distance: f64) -> Vec2 {
    ROBOT + Vec2::from_angle(angle_deg.to_radians()) * (distance * R)
}

fn flags(r: &SensorReading) -> [bool; 4] {
    [r.puck_left, r.puck_right, r.obstacle_left, r.obstacle_right]
}

#[test]
fn a_puck_in_a_left_disc_sets_the_left_bit_only() {
    let c = SimConfig::default();
    for (angle, dist) in [(-30.0, 4.0), (-60.0, 7.0)] {
        assert_eq!(
            flags(&read(&c, RobotKind::Outie, &[at(angle, dist)], &[])),
            [true, false, false, false]
        );
        assert_eq!(
            flags(&read(&c, RobotKind::Outie, &[at(-angle, dist)], &[])),
            [false, true, false, false]
        );
    }
    // innie discs sit elsewhere: (-45, 3r) and (-70, 6.5r)
    assert_eq!(
        flags(&read(&c, RobotKind::Innie, &[at(-45.0, 3.0)], &[])),
        [true, false, false, false]
    );
}

#[test]
fn a_puck_just_outside_the_disc_is_not_seen() {
    let c = SimConfig::default();
    // disc radius 2r = 20 plus puck radius 10: seen below 30 from the disc centre.
    let centre = at(-60.0, 7.0);
    let outward = Vec2::from_angle((-60.0f64).to_radians());
    assert!(read(&c, RobotKind::Outie, &[centre + outward * 29.9], &[]).puck_left);
    assert!(!read(&c, RobotKind::Outie, &[centre + outward * 30.0], &[]).puck_left);
}

#[test]
fn obstacle_sensors_see_any_body_by_default_and_only_robots_in_the_thesis_setup() {
    let c = SimConfig::default();
    // default disc: (-45 deg, r), radius r / 4; a body whose edge reaches it
    let touching = at(-45.0, 1.0) + Vec2::from_angle((-45.0f64).to_radians()) * 12.0;
    let r = read(&c, RobotKind::Outie, &[touching], &[]);
    assert!(r.obstacle_left && !r.obstacle_right, "{r:?}");
    assert_eq!(
        flags(&read(&c, RobotKind::Outie, &[], &[touching])),
        [false, false, true, false]
    );

    let thesis = SimConfig {
        sensors: DiscSensorConfig::thesis_obstacles(),
        ..SimConfig::default()
    };
    let right = at(45.0, 1.0) + Vec2::from_angle(45f64.to_radians()) * 25.0;
    assert!(
        !read(&thesis, RobotKind::Outie, &[right], &[]).obstacle_right,
        "pucks are not obstacles"
    );
    assert!(read(&thesis, RobotKind::Outie, &[], &[right]).obstacle_right);
}

#[test]
fn field_sensors_read_the_rounded_cells_and_zero_past_the_edge() {
    let c = SimConfig::default();
    let f = ScalarField::annulus();
    let cell = |x, y| FieldValue::from_f32(f.cell(x, y));
    // mid at (420, 400) -> (33.6, 32) -> cell (34, 32); left (414.1, 385.9) ->
    // (33, 31); right (414.1, 414.1) -> (33, 33)
    let r = read(&c, RobotKind::Outie, &[], &[]);
    assert_eq!(
        (r.left, r.mid, r.right),
        (cell(33, 31), cell(34, 32), cell(33, 33))
    );

    // near the right wall: the mid point at x = 790 reads cell 63, at
    // x >= 793.75 the index rounds to 64, outside the grid: 0.
    let world_at = |x: f64| {
        let world = World::scene(&c, &[(Vec2::new(x, 400.0), 0.0, RobotKind::Outie)], &[], 1);
        let mut out = [SensorReading::default()];
        DiscSensors::new(&c.sensors, R).sense(&world, &f, &mut out);
        out[0]
    };
    assert_eq!(world_at(770.0).mid, cell(63, 32));
    assert_eq!(world_at(773.75).mid, FieldValue::ZERO);
    assert_eq!(world_at(785.0).mid, FieldValue::ZERO);
}

/// The sensors remember which puck set each puck bit, to test it first
/// next time. That is only a shortcut: readings along an orbital
/// construction run, also after sensing another world in between, equal
/// those of sensors that start afresh every step.
#[test]
fn readings_do_not_depend_on_what_the_sensors_saw_before() {
    use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
    use sim::{config::Thresholds, simulation::Simulation};
    use std::sync::Arc;
    let config = SimConfig::default();
    let field = Arc::new(ScalarField::annulus());
    let mut sim = Simulation::new(config.clone(), field.clone(), 3).expect("valid config");
    let mut oc = OrbitalConstruction::new(OrbitalConfig::default(), &Thresholds::default());
    let mut remembering = DiscSensors::new(&config.sensors, R);
    let mut out = vec![SensorReading::default(); config.world.robots];
    let mut fresh_out = out.clone();
    let mut hits = 0;
    for step in 0..3000 {
        sim.step(&mut oc);
        if step == 1500 {
            // another world, with other pucks at the remembered indices
            remembering.sense(
                &World::new(&config, 99).expect("valid config"),
                &field,
                &mut out,
            );
        }
        let world = sim.world();
        remembering.sense(world, &field, &mut out);
        DiscSensors::new(&config.sensors, R).sense(world, &field, &mut fresh_out);
        assert_eq!(out, fresh_out, "step {step}");
        assert_eq!(out, sim.readings(), "step {step}");
        hits += out.iter().filter(|r| r.puck_left || r.puck_right).count();
    }
    assert!(
        hits > 3000,
        "the run must exercise the puck sensors ({hits} readings with a puck)"
    );
}
