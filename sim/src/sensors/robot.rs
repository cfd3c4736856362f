//! The robot sensor model: what a Zumo 32U4 with three photo-transistors
//! and a Pixy camera can know, computed with the firmware's own arithmetic.
//!
//! Each robot's reading is
//! - field values: the field at the three sensor points -> discharge times
//!   -> whole Timer3 ticks -> the firmware's calibration
//!   ([`crate::sensors::photo`]);
//! - puck and obstacle bits: the camera's frame ([`crate::sensors::pixy_camera`]),
//!   of which the first [`MAX_BLOCKS_PER_PERIOD`] blocks go through
//!   [`shared::CameraConfig::classify`], as on the robot.
//!
//! Per step, in order: the camera's frame is taken (its blocks jittered,
//! missed and joined by spurious ones as [`RobotNoise`] says), delayed by
//! the camera's latency (frames in flight per robot), possibly dropped,
//! then held for [`shared::camera::HOLD_PERIODS`] periods by the robot's
//! `CameraMemory` as the firmware holds it; the photo-transistors read
//! with their brightness gain and RC jitter. Every noise draw comes from a
//! counter-based stream of the world's seed ([`crate::base::noise`]), and what
//! the model remembers is saved with a simulation's snapshot, so a run
//! resumes bit-exactly.
//!
//! So a simulated robot and the firmware, given the same raw inputs (ticks
//! and blocks), hash them identically; the equivalence tests check it on
//! the firmware binary. The whole model is configured by a
//! [`RobotSensorConfig`] (JSON, every field optional; `docs/robot-sensors.md`).

use crate::base::gain_grid::GainGrid;
use crate::base::noise::{self, Place, Purpose};
use crate::base::vec2::Vec2;
use crate::config::validate::ConfigError;
use crate::config::WorldConfig;
use crate::fields::ScalarField;
use crate::sensors::camera_memory::CameraMemory;
use crate::sensors::photo::PhotoNoise;
use crate::sensors::photo::{PhotoSensorConfig, PhotoSensors};
use crate::sensors::pixy_camera::{PixyCamera, PixyCameraConfig};
use crate::sensors::robot_noise::RobotNoise;
use crate::sensors::{Footprint, FootprintKind, SensorMemory, SensorModel};
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::camera::MAX_BLOCKS_PER_PERIOD;
use shared::{FieldCalibration, PixyBlock, SensorReading};

/// Version of the model's results, hashed with the settings of experiment
/// trials that use it. 2: millimetre geometry, the photo-transistors on
/// the skirt, the camera's puck and obstacle regions, its frame of latency
/// and the firmware's hold, noise.
pub const MODEL_VERSION: u32 = 2;

/// Settings of the robot sensor model.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotSensorConfig {
    /// The three field sensors.
    pub field: PhotoSensorConfig,
    /// The Pixy camera.
    pub camera: PixyCameraConfig,
    /// The sensors' noise (none by default).
    pub noise: RobotNoise,
}

impl RobotSensorConfig {
    /// Checks every part; the error names the setting.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.field.validate()?;
        self.camera.validate()?;
        self.noise.validate()
    }
}

/// Everything one robot's sensors produce in one control period: the raw
/// stimulus the robot's pins and bus would carry, and the reading.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotObservation {
    /// Discharge times of the left, mid and right sensors, us (what the
    /// pins do; the firmware adds its latency when it times them).
    pub discharge_us: [f64; 3],
    /// The firmware's raw times: whole Timer3 ticks.
    pub ticks: [u16; 3],
    /// The camera's whole frame, in the order the Pixy sends it.
    pub frame: Vec<PixyBlock>,
    /// The reading the firmware computes from `ticks` and the blocks it reads.
    pub reading: SensorReading,
}

impl RobotObservation {
    /// The blocks the firmware reads: the first [`MAX_BLOCKS_PER_PERIOD`].
    #[cfg(test)]
    pub(crate) fn blocks_read(&self) -> &[PixyBlock] {
        &self.frame[..self.frame.len().min(MAX_BLOCKS_PER_PERIOD)]
    }
}

/// The robot sensor model (a [`SensorModel`]).
#[derive(Clone, Debug)]
pub struct RobotSensors {
    photo: PhotoSensors,
    camera: PixyCamera,
    latency_frames: u8,
    noise: RobotNoise,
    /// Whether `noise` is other than [`RobotNoise::NONE`] (compared once).
    noisy: bool,
    /// The screen's brightness gains and the (seed, episode) they are of.
    brightness: Option<(u64, u64, GainGrid)>,
    /// Each robot's camera link.
    links: Vec<CameraMemory>,
    /// Each robot's observation of the last sensing.
    observations: Vec<RobotObservation>,
    /// The frame being captured (a reused buffer).
    capture: Vec<PixyBlock>,
}

impl RobotSensors {
    /// The model of `config` on the robots of `world` (its millimetres per
    /// unit, the robots' outline; validate the config first:
    /// [`RobotSensorConfig::validate`]).
    pub fn new(config: &RobotSensorConfig, world: &WorldConfig) -> RobotSensors {
        RobotSensors {
            photo: PhotoSensors::new(&config.field, world),
            camera: PixyCamera::new(&config.camera, world.unit_mm),
            latency_frames: config.camera.latency_frames,
            noise: config.noise.clone(),
            noisy: config.noise != RobotNoise::NONE,
            brightness: None,
            links: Vec::new(),
            observations: Vec::new(),
            capture: Vec::new(),
        }
    }

    /// The field calibration the robots store and the firmware applies.
    pub fn calibration(&self) -> FieldCalibration {
        self.photo.calibration()
    }

    /// The reading the firmware computes from raw times (ticks) and a
    /// camera frame: the calibration of the times, the classification of
    /// the blocks it reads (the first [`MAX_BLOCKS_PER_PERIOD`]).
    pub fn reading(&self, ticks: &[u16; 3], frame: &[PixyBlock]) -> SensorReading {
        let read = &frame[..frame.len().min(MAX_BLOCKS_PER_PERIOD)];
        SensorReading::from_parts(
            self.photo.values(ticks),
            self.camera.classify().classify(read),
        )
    }

    /// Every robot's observation of the last sensing (the world the
    /// simulation stepped to, or reset to).
    pub fn observations(&self) -> &[RobotObservation] {
        &self.observations
    }

    /// Robot `robot`'s observation of the world, into `observations`: its
    /// field sensors' reading, and the camera frame its link delivers.
    /// With noise, `step` holds the step's [`Purpose::Discharge`] and
    /// [`Purpose::Camera`] places, which every robot's streams share, and
    /// the episode's brightness gains; without, it is `None`.
    fn observe(
        &mut self,
        world: &World,
        field: &ScalarField,
        robot: usize,
        step: Option<([Place; 2], &GainGrid)>,
    ) {
        let episode = world.state().episode;
        let (pos, direction) = (world.bodies()[robot].pos, world.robots()[robot].direction);
        let layout = world.config().field_layout();
        let photo = if let Some(([discharge, _], grid)) = step {
            let mut rng = discharge.stream(robot as u64);
            let arena = world.config().arena();
            let noise = PhotoNoise {
                noise: &self.noise,
                grid,
                arena,
                rng: &mut rng,
            };
            self.photo.read(pos, direction, field, &layout, Some(noise))
        } else {
            self.photo.read(pos, direction, field, &layout, None)
        };

        let mut capture = std::mem::take(&mut self.capture);
        self.camera.frame(world, robot, &mut capture);
        let classify = self.camera.classify();
        let (puck, robot_signature) = (classify.puck_signature, classify.robot_signature);
        // What reaches the robot now: the camera sends nothing when it sees
        // nothing, and a dropped frame does not arrive. Without noise there
        // is nothing to draw (the noise draws none at zero amounts).
        let arrives = step.is_none_or(|([_, camera], _)| {
            let mut rng = camera.stream(robot as u64);
            self.noise
                .perturb_frame(&mut capture, puck, robot_signature, &mut rng);
            !noise::chance(&mut rng, self.noise.frame_drop)
        });
        let link = &mut self.links[robot];
        if link.episode != episode {
            *link = CameraMemory {
                episode,
                ..CameraMemory::default()
            };
        }
        if self.latency_frames > 0 {
            std::mem::swap(&mut link.captured, &mut capture);
        }
        let delivered: &[PixyBlock] = if arrives { &capture } else { &[] };
        let held = link.period(delivered);
        let out = &mut self.observations[robot];
        out.frame.clear();
        out.frame.extend_from_slice(held);
        self.capture = capture;
        out.discharge_us = photo.discharge_us;
        out.ticks = photo.ticks;
        let read = &out.frame[..out.frame.len().min(MAX_BLOCKS_PER_PERIOD)];
        out.reading =
            SensorReading::from_parts(photo.values, self.camera.classify().classify(read));
    }
}

/// The screen's brightness gains of an episode, from `cache` if it holds
/// that episode's (computed once per episode).
fn brightness_grid<'a>(
    cache: &'a mut Option<(u64, u64, GainGrid)>,
    noise: &RobotNoise,
    seed: u64,
    episode: u64,
) -> &'a GainGrid {
    if !matches!(cache, Some((s, e, _)) if *s == seed && *e == episode) {
        *cache = None;
    }
    &cache
        .get_or_insert_with(|| (seed, episode, noise.brightness_grid(seed, episode)))
        .2
}

impl SensorModel for RobotSensors {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        let robots = world.robots().len();
        self.links.resize(robots, CameraMemory::default());
        self.observations
            .resize(robots, RobotObservation::default());
        let (seed, episode, step) = (world.state().seed, world.state().episode, world.steps());
        // Taken out of `self` for the robots' loop, and looked up once.
        let mut brightness = self.brightness.take();
        let noise = self.noisy.then(|| {
            let places = [Purpose::Discharge, Purpose::Camera].map(|p| noise::place(seed, p, step));
            (
                places,
                brightness_grid(&mut brightness, &self.noise, seed, episode),
            )
        });
        for (i, reading) in out.iter_mut().enumerate().take(robots) {
            self.observe(world, field, i, noise);
            *reading = self.observations[i].reading;
        }
        self.brightness = brightness;
    }

    /// The three field sensor points (the camera's view is
    /// [`SensorModel::camera_view`]).
    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        let (pos, dir) = (world.bodies()[robot].pos, world.robots()[robot].direction);
        out.extend(self.photo.points().iter().map(|p| Footprint {
            centre: pos + p.rotated(dir),
            radius: 0.0,
            kind: FootprintKind::Field,
        }));
    }

    fn camera_view(&self) -> Vec<Vec2> {
        self.camera.floor_view()
    }

    /// One camera model: its robots' links.
    fn memory(&self) -> SensorMemory {
        SensorMemory {
            cameras: vec![self.links.clone()],
        }
    }

    fn restore(&mut self, memory: &SensorMemory) {
        self.links = memory.cameras.first().cloned().unwrap_or_default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::vec2::Vec2;
    use crate::config::SimConfig;
    use crate::physics::body::RobotKind;
    use shared::FieldValue;

    #[test]
    fn the_reading_is_the_firmware_arithmetic_on_the_raw_stimulus() {
        let config = SimConfig::default();
        // Robot 0 facing +x with five pucks ahead: only four blocks are read.
        let robots = [
            (Vec2::new(200.0, 400.0), 0.0, RobotKind::Outie),
            (Vec2::new(260.0, 430.0), 0.0, RobotKind::Outie),
        ];
        let pucks: Vec<Vec2> = (0..5)
            .map(|k| Vec2::new(240.0 + 25.0 * f64::from(k), 385.0 + 10.0 * f64::from(k % 2)))
            .collect();
        let world = World::scene(&config, &robots, &pucks, 1);
        let field = ScalarField::annulus();
        let mut model = RobotSensors::new(&RobotSensorConfig::default(), &config.world);
        let mut readings = vec![SensorReading::default(); 2];
        // One frame of latency: the first period's frame arrives in the second.
        model.sense(&world, &field, &mut readings);
        assert!(model.observations()[0].frame.is_empty());
        model.sense(&world, &field, &mut readings);
        let obs = model.observations()[0].clone();
        assert!(!obs.frame.is_empty() && obs.blocks_read().len() <= MAX_BLOCKS_PER_PERIOD);
        let values = model.calibration().scales().values(&obs.ticks);
        let blobs = shared::CameraConfig::DEFAULT.classify(obs.blocks_read());
        assert_eq!(obs.reading, SensorReading::from_parts(values, blobs));
        assert_eq!(model.reading(&obs.ticks, &obs.frame), obs.reading);
        assert!(obs.reading.mid > FieldValue::ZERO);
        assert_eq!(readings[0], obs.reading);
    }

    #[test]
    fn a_frame_holds_one_more_period_and_an_ideal_camera_has_no_latency() {
        let config = SimConfig::default();
        let robot = [(Vec2::new(200.0, 400.0), 0.0, RobotKind::Outie)];
        let field = ScalarField::annulus();
        let with_puck = World::scene(&config, &robot, &[Vec2::new(240.0, 400.0)], 1);
        let empty = World::scene(&config, &robot, &[], 1);
        let mut readings = [SensorReading::default()];
        let mut model = RobotSensors::new(&RobotSensorConfig::default(), &config.world);
        let mut seen = |world: &World, model: &mut RobotSensors| {
            model.sense(world, &field, &mut readings);
            readings[0].puck_left
        };
        // Captured in period 1, arriving in 2, held through 3 (the camera
        // sends nothing once it sees nothing), gone in 4.
        assert_eq!(
            [
                seen(&with_puck, &mut model),
                seen(&empty, &mut model),
                seen(&empty, &mut model),
                seen(&empty, &mut model)
            ],
            [false, true, true, false]
        );
        let mut ideal = RobotSensorConfig::default();
        ideal.camera.latency_frames = 0;
        let mut model = RobotSensors::new(&ideal, &config.world);
        assert_eq!(
            [
                seen(&with_puck, &mut model),
                seen(&empty, &mut model),
                seen(&empty, &mut model)
            ],
            [true, true, false]
        );
    }

    #[test]
    fn config_files_name_only_what_they_change_and_unknown_keys_are_refused() {
        let c: RobotSensorConfig =
            serde_json::from_str(r#"{"camera": {"tilt_deg": 25.0}}"#).unwrap();
        assert_eq!(c.camera.tilt_deg, 25.0);
        assert_eq!(c.field, PhotoSensorConfig::default());
        let e = serde_json::from_str::<RobotSensorConfig>(r#"{"camera": {"tilt": 25.0}}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tilt"), "{e}");
    }
}
