//! The robot sensor model end to end: deterministic, and sensing only what
//! the robot's camera can see.

use sim::controllers::RandomTurns;
use sim::{
    DiscSensorConfig, DiscSensors, RobotKind, RobotSensorConfig, RobotSensors, ScalarField, SensorModel, SimConfig,
    Simulation, Vec2, World,
};
use shared::{ActionTable, SensorReading};
use std::sync::Arc;

#[test]
fn the_same_seed_gives_the_same_trajectory_with_the_robot_model() {
    let run = || {
        let config = SimConfig::default();
        let sensors = RobotSensors::new(&RobotSensorConfig::default(), config.world.unit_mm);
        let mut sim = Simulation::with_sensors(config, Arc::new(ScalarField::annulus()), sensors, 5).unwrap();
        let mut controller = RandomTurns::new(ActionTable::default());
        sim.run(&mut controller, 500);
        (sim.world().bodies().iter().map(|b| (b.pos.x, b.pos.y)).collect::<Vec<_>>(), sim.readings().to_vec())
    };
    assert_eq!(run(), run());
}

#[test]
fn a_puck_in_the_thesis_side_disc_is_sensed_by_the_discs_but_not_the_camera() {
    let config = SimConfig::default();
    // Robot facing +x; a puck at 60 degrees right, 7 radii: the thesis'
    // outer right puck disc, outside the Pixy's 75-degree view.
    let (a, d) = (60f64.to_radians(), 70.0);
    let world = World::scene(
        &config,
        &[(Vec2::new(300.0, 300.0), 0.0, RobotKind::Outie)],
        &[Vec2::new(300.0 + d * a.cos(), 300.0 + d * a.sin())],
        1,
    );
    let field = ScalarField::annulus();
    let mut reading = [SensorReading::default()];
    DiscSensors::new(&DiscSensorConfig::default(), 10.0).sense(&world, &field, &mut reading);
    assert!(reading[0].puck_right);
    RobotSensors::new(&RobotSensorConfig::default(), 5.0).sense(&world, &field, &mut reading);
    assert!(!reading[0].puck_right && !reading[0].puck_left);
}
