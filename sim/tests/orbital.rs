//! Orbital construction's decisions in the three configurations of the
//! thesis' Figure 6, on the annulus: A and C orbit clockwise (right >= mid
//! >= left), B does not and turns to realign.

use shared::SensorReading;
use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::{
    base::vec2::Vec2, config::SimConfig, config::Thresholds, fields::ScalarField,
    physics::body::RobotKind, sensors::disc::DiscSensors, sensors::SensorModel, world::World,
};
use std::f64::consts::FRAC_PI_2;

fn read(pos: Vec2, heading: f64, kind: RobotKind, pucks: &[Vec2]) -> SensorReading {
    let c = SimConfig::default();
    let world = World::scene(&c, &[(pos, heading, kind)], pucks, 1);
    let mut out = [SensorReading::default()];
    DiscSensors::new(&c.sensors, 10.0).sense(&world, &ScalarField::annulus(), &mut out);
    out[0]
}

fn oc() -> OrbitalConstruction {
    OrbitalConstruction::new(OrbitalConfig::default(), &Thresholds::default())
}

fn clockwise(r: &SensorReading) -> bool {
    r.right >= r.mid && r.mid >= r.left
}

/// A point `angle_deg` right of `heading` at `distance` from `pos`.
fn beside(pos: Vec2, heading: f64, angle_deg: f64, distance: f64) -> Vec2 {
    pos + Vec2::from_angle(heading + angle_deg.to_radians()) * distance
}

#[test]
fn agent_a_left_of_centre_heading_up_orbits_clockwise() {
    // A: west of the centre, heading up (-y): the centre is to its right.
    let (outer, inner) = (Vec2::new(130.0, 400.0), Vec2::new(250.0, 400.0));
    let up = -FRAC_PI_2;
    let r = read(outer, up, RobotKind::Outie, &[]);
    assert!(clockwise(&r), "{r:?}");
    assert!(r.mid.to_f32() < 0.6);
    assert_eq!(
        oc().turn(&r, RobotKind::Outie),
        0.3 * 0.3,
        "below T_o: gentle right, inwards"
    );
    let r = read(inner, up, RobotKind::Outie, &[]);
    assert!(clockwise(&r) && r.mid.to_f32() > 0.6, "{r:?}");
    assert_eq!(
        oc().turn(&r, RobotKind::Outie),
        -0.3 * 0.3,
        "above T_o: gentle left, outwards"
    );
    // an innie orbits at T_i = 0.8 instead: still inside it, so it turns in
    assert_eq!(oc().turn(&r, RobotKind::Innie), 0.3 * 0.3);
}

#[test]
fn agent_a_nudges_pucks_by_kind() {
    let pos = Vec2::new(200.0, 400.0);
    let up = -FRAC_PI_2;
    let left_puck = beside(pos, up, -30.0, 40.0);
    let r = read(pos, up, RobotKind::Outie, &[left_puck]);
    assert!(clockwise(&r) && r.puck_left);
    assert_eq!(
        oc().turn(&r, RobotKind::Outie),
        -0.3,
        "an outie turns into a puck on its left"
    );

    let right_puck = beside(pos, up, 45.0, 30.0);
    let r = read(pos, up, RobotKind::Innie, &[right_puck]);
    assert!(clockwise(&r) && r.puck_right);
    assert_eq!(
        oc().turn(&r, RobotKind::Innie),
        0.3,
        "an innie turns into a puck on its right"
    );

    let r = read(pos, up, RobotKind::Innie, &[beside(pos, up, -45.0, 30.0)]);
    assert!(r.puck_left && !r.puck_right);
    assert_eq!(
        oc().turn(&r, RobotKind::Innie).abs(),
        0.09,
        "an innie ignores pucks on its left"
    );
}

#[test]
fn agent_b_heading_the_wrong_way_realigns() {
    // B: west of the centre heading down: the centre is on its left.
    let r = read(Vec2::new(200.0, 400.0), FRAC_PI_2, RobotKind::Outie, &[]);
    assert!(!clockwise(&r) && r.left > r.mid, "{r:?}");
    assert_eq!(oc().turn(&r, RobotKind::Outie), 0.3);
    // heading straight at the centre, mid is the highest: turn left
    let r = read(Vec2::new(200.0, 400.0), 0.0, RobotKind::Outie, &[]);
    assert!(
        r.mid >= r.left && r.mid >= r.right && !clockwise(&r),
        "{r:?}"
    );
    assert_eq!(oc().turn(&r, RobotKind::Outie), -0.3);
}

#[test]
fn agent_c_above_centre_heading_right_orbits_clockwise() {
    // C: north of the centre heading right (+x): the centre is to its right.
    let r = read(Vec2::new(400.0, 150.0), 0.0, RobotKind::Outie, &[]);
    assert!(clockwise(&r), "{r:?}");
    assert_eq!(oc().turn(&r, RobotKind::Outie), 0.09);
}

#[test]
fn the_left_obstacle_sensor_comes_first() {
    let mut r = read(Vec2::new(200.0, 400.0), -FRAC_PI_2, RobotKind::Outie, &[]);
    r.obstacle_left = true;
    r.puck_left = true;
    assert_eq!(oc().turn(&r, RobotKind::Outie), 0.3);
}
