//! The robot sensor model: what a Zumo 32U4 with three photo-transistors
//! and a Pixy camera can know, computed with the firmware's own arithmetic.
//!
//! Each robot's reading is
//! - field values: the field at the three sensor points -> discharge times
//!   -> whole Timer3 ticks -> the firmware's calibration
//!   ([`crate::photo_sensors`]);
//! - puck and obstacle bits: the camera's frame ([`crate::pixy_camera`]),
//!   of which the first [`MAX_BLOCKS_PER_PERIOD`] blocks go through
//!   [`shared::CameraConfig::classify`], as on the robot.
//!
//! So a simulated robot and the firmware, given the same raw inputs (ticks
//! and blocks), hash them identically; the equivalence tests check it on
//! the firmware binary. The whole model is configured by a
//! [`RobotSensorConfig`] (JSON, every field optional; `docs/robot-sensors.md`).

use crate::validate::ConfigError;
use crate::field::ScalarField;
use crate::photo_sensors::{PhotoSensorConfig, PhotoSensors};
use crate::pixy_camera::{PixyCamera, PixyCameraConfig};
use crate::sensor_model::{Footprint, FootprintKind, SensorModel};
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::camera::MAX_BLOCKS_PER_PERIOD;
use shared::{FieldCalibration, PixyBlock, SensorReading};

/// Settings of the robot sensor model.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotSensorConfig {
    /// The three field sensors.
    pub field: PhotoSensorConfig,
    /// The Pixy camera.
    pub camera: PixyCameraConfig,
}

impl RobotSensorConfig {
    /// Checks both parts; the error names the setting.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.field.validate()?;
        self.camera.validate()
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
    pub fn blocks_read(&self) -> &[PixyBlock] {
        &self.frame[..self.frame.len().min(MAX_BLOCKS_PER_PERIOD)]
    }
}

/// The robot sensor model (a [`SensorModel`]).
#[derive(Clone, Debug)]
pub struct RobotSensors {
    photo: PhotoSensors,
    camera: PixyCamera,
    scratch: RobotObservation,
}

impl RobotSensors {
    /// The model of `config` in a world of `unit_mm` millimetres per unit
    /// (validate the config first: [`RobotSensorConfig::validate`]).
    pub fn new(config: &RobotSensorConfig, unit_mm: f64) -> RobotSensors {
        RobotSensors {
            photo: PhotoSensors::new(&config.field, unit_mm),
            camera: PixyCamera::new(&config.camera, unit_mm),
            scratch: RobotObservation::default(),
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
        SensorReading::from_parts(self.photo.values(ticks), self.camera.classify().classify(read))
    }

    /// Robot `robot`'s observation of the world (reuses `out`'s buffer).
    pub fn observe(&mut self, world: &World, field: &ScalarField, robot: usize, out: &mut RobotObservation) {
        let pos = world.bodies()[robot].pos;
        let photo = self.photo.read(pos, world.robots()[robot].direction, field, &world.config().field_layout());
        self.camera.frame(world, robot, &mut out.frame);
        out.discharge_us = photo.discharge_us;
        out.ticks = photo.ticks;
        let read = &out.frame[..out.frame.len().min(MAX_BLOCKS_PER_PERIOD)];
        out.reading = SensorReading::from_parts(photo.values, self.camera.classify().classify(read));
    }
}

impl SensorModel for RobotSensors {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        let mut scratch = std::mem::take(&mut self.scratch);
        for (i, reading) in out.iter_mut().enumerate().take(world.robots().len()) {
            self.observe(world, field, i, &mut scratch);
            *reading = scratch.reading;
        }
        self.scratch = scratch;
    }

    /// The three field sensor points (the camera's view is not drawn).
    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        let (pos, dir) = (world.bodies()[robot].pos, world.robots()[robot].direction);
        out.extend(self.photo.points().iter().map(|p| Footprint {
            centre: pos + p.rotated(dir),
            radius: 0.0,
            kind: FootprintKind::Field,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::RobotKind;
    use crate::config::SimConfig;
    use crate::vec2::Vec2;
    use shared::FieldValue;

    #[test]
    fn the_reading_is_the_firmware_arithmetic_on_the_raw_stimulus() {
        let config = SimConfig::default();
        // Robot 0 facing +x with five pucks ahead: only four blocks are read.
        let robots =
            [(Vec2::new(200.0, 400.0), 0.0, RobotKind::Outie), (Vec2::new(260.0, 430.0), 0.0, RobotKind::Outie)];
        let pucks: Vec<Vec2> =
            (0..5).map(|k| Vec2::new(240.0 + 25.0 * f64::from(k), 385.0 + 10.0 * f64::from(k % 2))).collect();
        let world = World::scene(&config, &robots, &pucks, 1);
        let field = ScalarField::annulus();
        let mut model = RobotSensors::new(&RobotSensorConfig::default(), 5.0);
        let mut obs = RobotObservation::default();
        model.observe(&world, &field, 0, &mut obs);
        assert!(obs.blocks_read().len() <= MAX_BLOCKS_PER_PERIOD);
        let values = model.calibration().scales().values(&obs.ticks);
        let blobs = shared::CameraConfig::DEFAULT.classify(obs.blocks_read());
        assert_eq!(obs.reading, SensorReading::from_parts(values, blobs));
        assert!(obs.reading.mid > FieldValue::ZERO);

        let mut readings = vec![SensorReading::default(); 2];
        model.sense(&world, &field, &mut readings);
        assert_eq!(readings[0], obs.reading);
    }

    #[test]
    fn config_files_name_only_what_they_change_and_unknown_keys_are_refused() {
        let c: RobotSensorConfig = serde_json::from_str(r#"{"camera": {"tilt_deg": 25.0}}"#).unwrap();
        assert_eq!(c.camera.tilt_deg, 25.0);
        assert_eq!(c.field, PhotoSensorConfig::default());
        let e = serde_json::from_str::<RobotSensorConfig>(r#"{"camera": {"tilt": 25.0}}"#).unwrap_err().to_string();
        assert!(e.contains("tilt"), "{e}");
    }
}
