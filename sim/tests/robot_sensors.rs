//! The robot sensor model end to end: deterministic, and sensing only what
//! the robot's camera can see.

use shared::{ActionTable, SensorReading};
use sim::control::random::RandomTurns;
use sim::{
    base::vec2::Vec2, config::disc_sensors::DiscSensorConfig, config::SimConfig,
    fields::ScalarField, physics::body::RobotKind, sensors::disc::DiscSensors,
    sensors::robot::RobotSensorConfig, sensors::robot::RobotSensors,
    sensors::robot_noise::RobotNoise, sensors::SensorModel, simulation::Simulation, world::World,
};
use std::sync::Arc;

#[test]
fn the_same_seed_gives_the_same_trajectory_with_the_robot_model() {
    let run = || {
        let config = SimConfig::default();
        let sensors = RobotSensors::new(&RobotSensorConfig::default(), &config.world);
        let mut sim =
            Simulation::with_sensors(config, Arc::new(ScalarField::annulus()), sensors, 5).unwrap();
        let mut controller = RandomTurns::new(ActionTable::default());
        sim.run(&mut controller, 500);
        (
            sim.world()
                .bodies()
                .iter()
                .map(|b| (b.pos.x, b.pos.y))
                .collect::<Vec<_>>(),
            sim.readings().to_vec(),
        )
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
    RobotSensors::new(&RobotSensorConfig::default(), &config.world).sense(
        &world,
        &field,
        &mut reading,
    );
    assert!(!reading[0].puck_right && !reading[0].puck_left);
}

/// A simulation on the TV with the robot's senses and random turns, with
/// the default noise times `noise`.
fn noisy(noise: f64, seed: u64) -> Simulation<sim::scenario::sensor_setup::SelectedSensors> {
    let tv = sim::scenario::arena::ArenaSpec::tv75();
    let field = ScalarField::annulus_of(64, 36);
    let mut config = SimConfig::default();
    tv.apply(&mut config, &field);
    config.world.actuation = sim::config::actuation::ActuationNoise::randomised().scaled(noise);
    let robot = RobotSensorConfig {
        noise: sim::sensors::robot_noise::RobotNoise::randomised().scaled(noise),
        ..RobotSensorConfig::default()
    };
    let sensors = sim::scenario::sensor_setup::SensorSetup::Robot(Box::new(robot)).build(&config);
    Simulation::with_sensors(config, Arc::new(field), sensors, seed).unwrap()
}

fn trajectory(
    sim: &mut Simulation<sim::scenario::sensor_setup::SelectedSensors>,
    steps: u64,
) -> (Vec<(f64, f64)>, Vec<SensorReading>) {
    let mut controller = RandomTurns::new(ActionTable::default());
    sim.run(&mut controller, steps);
    (
        sim.world()
            .bodies()
            .iter()
            .map(|b| (b.pos.x, b.pos.y))
            .collect(),
        sim.readings().to_vec(),
    )
}

#[test]
fn the_same_seed_gives_the_same_noise_and_zero_noise_is_the_noiseless_model() {
    let a = trajectory(&mut noisy(1.0, 3), 3000);
    assert_eq!(a, trajectory(&mut noisy(1.0, 3), 3000));
    assert_ne!(
        a,
        trajectory(&mut noisy(1.0, 4), 3000),
        "another seed, other noise"
    );
    let quiet = trajectory(&mut noisy(0.0, 3), 3000);
    assert_ne!(a, quiet, "the noise changes the run");
    // Zero noise, given explicitly, is the model without noise.
    let tv = sim::scenario::arena::ArenaSpec::tv75();
    let field = ScalarField::annulus_of(64, 36);
    let mut config = SimConfig::default();
    tv.apply(&mut config, &field);
    let sensors = sim::scenario::sensor_setup::SensorSetup::Robot(Box::default()).build(&config);
    let mut plain = Simulation::with_sensors(config, Arc::new(field), sensors, 3).unwrap();
    assert_eq!(quiet, trajectory(&mut plain, 3000));
}

#[test]
fn a_noisy_run_resumed_from_its_snapshot_goes_on_exactly() {
    let mut straight = noisy(2.0, 5);
    let whole = trajectory(&mut straight, 2500);
    let mut first = noisy(2.0, 5);
    trajectory(&mut first, 1000);
    let saved = serde_json::to_string(&first.snapshot()).unwrap();
    let state: sim::simulation::SimulationState = serde_json::from_str(&saved).unwrap();
    let fresh = noisy(2.0, 5);
    let sensors = sim::scenario::sensor_setup::SensorSetup::Robot(Box::new(RobotSensorConfig {
        noise: sim::sensors::robot_noise::RobotNoise::randomised().scaled(2.0),
        ..RobotSensorConfig::default()
    }))
    .build(fresh.config());
    let mut resumed = Simulation::resume(state, Arc::new(fresh.field().clone()), sensors);
    assert_eq!(trajectory(&mut resumed, 1500), whole);
}

/// The robot senses' noise of a scenario on `tv75` whose panel shows
/// `share` of its unevenness, at twice the default noise.
fn noise_on_a_panel_showing(share: f64) -> Result<RobotNoise, String> {
    use sim::scenario::{arena::ArenaSpec, sensor_setup::SensorSetup, Arena, Scenario};
    let scenario = Scenario {
        arena: Arena::Screen(Box::new(ArenaSpec {
            brightness_unevenness: share,
            ..ArenaSpec::tv75()
        })),
        sensors: SensorSetup::Robot(Box::default()),
        noise: 2.0,
        ..Scenario::default()
    };
    match scenario.prepare().map_err(|e| e.to_string())?.sensors() {
        SensorSetup::Robot(robot) => Ok(robot.noise.clone()),
        other => Err(format!("not the robot's senses: {other:?}")),
    }
}

#[test]
fn a_flat_field_corrected_panel_shows_its_share_of_the_unevenness_and_no_other_noise_changes() {
    let panel = noise_on_a_panel_showing(1.0).unwrap();
    assert_eq!(panel, RobotNoise::randomised().scaled(2.0));
    let flattened = noise_on_a_panel_showing(0.2).unwrap();
    assert!((flattened.brightness - 0.2 * panel.brightness).abs() < 1e-15);
    assert_eq!(
        RobotNoise {
            brightness: panel.brightness,
            ..flattened
        },
        panel
    );
    let e = noise_on_a_panel_showing(1.5).unwrap_err();
    assert!(e.contains("arena.brightness_unevenness"), "{e}");
}

/// The motion noise and the senses' noise of a scenario on `tv75` whose
/// robots show `share` of the motion noise, at `noise` times the default.
fn noises_of_robots_showing(
    share: f64,
    noise: f64,
) -> Result<(sim::config::actuation::ActuationNoise, RobotNoise), String> {
    use sim::scenario::{arena::ArenaSpec, sensor_setup::SensorSetup, Arena, Scenario};
    let scenario = Scenario {
        arena: Arena::Screen(Box::new(ArenaSpec {
            motion_noise: share,
            ..ArenaSpec::tv75()
        })),
        sensors: SensorSetup::Robot(Box::default()),
        noise,
        ..Scenario::default()
    };
    let prepared = scenario.prepare().map_err(|e| e.to_string())?;
    match prepared.sensors() {
        SensorSetup::Robot(robot) => Ok((
            prepared.config().world.actuation.clone(),
            robot.noise.clone(),
        )),
        other => Err(format!("not the robot's senses: {other:?}")),
    }
}

#[test]
fn robots_showing_half_the_motion_noise_at_twice_the_noise_move_as_at_the_default_and_sense_at_twice_it(
) {
    let (default_motion, default_senses) = noises_of_robots_showing(1.0, 1.0).unwrap();
    let (motion, senses) = noises_of_robots_showing(0.5, 2.0).unwrap();
    assert_eq!(motion, default_motion);
    assert!(!motion.is_none());
    assert_eq!(senses, default_senses.scaled(2.0));
    let (still, _) = noises_of_robots_showing(0.0, 2.0).unwrap();
    assert!(still.is_none(), "{still:?}");
    let e = noises_of_robots_showing(1.5, 1.0).unwrap_err();
    assert!(e.contains("arena.motion_noise"), "{e}");
}
