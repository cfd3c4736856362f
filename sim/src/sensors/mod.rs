//! The interface between the world and the controllers: a sensor model
//! turns the world into one [`SensorReading`] per robot, and can show what
//! it senses for drawing.
//!
//! Room 6 of the simulator (`lib.rs`), the third stage of a step (world -> physics -> **sensors** -> control).

pub(crate) mod camera_memory;
pub mod disc;
pub mod mixed;
pub mod photo;
pub mod pixy_camera;
pub mod robot;
pub mod robot_noise;

use crate::base::vec2::Vec2;
use crate::fields::ScalarField;
use crate::sensors::camera_memory::CameraMemory;
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::SensorReading;

/// What a sensor model remembers between periods and a checkpoint must
/// keep (the thesis' discs remember nothing).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SensorMemory {
    /// Per camera model (one for the robot model; a mix lists its parts'
    /// in order), each robot's camera link.
    pub cameras: Vec<Vec<CameraMemory>>,
}

/// Produces every robot's reading from the world and field.
///
/// A model may keep state between steps (`&mut self`), for example sensor
/// noise drawn from its own seeded generator.
pub trait SensorModel {
    /// Fills `out[i]` with robot `i`'s reading; `out` has one entry per robot.
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]);

    /// Appends the areas robot `robot` senses, for drawing. The default
    /// draws nothing.
    fn footprints(&self, _world: &World, _robot: usize, _out: &mut Vec<Footprint>) {}

    /// The floor a robot's camera sees, for drawing: a polygon in the
    /// robot's frame (x ahead, y to its right, units). The default, for a
    /// model without a camera: none.
    fn camera_view(&self) -> Vec<Vec2> {
        Vec::new()
    }

    /// What the model remembers, for a checkpoint. The default: nothing.
    fn memory(&self) -> SensorMemory {
        SensorMemory::default()
    }

    /// Takes up a checkpoint's memory (`memory`'s). The default ignores it.
    fn restore(&mut self, _memory: &SensorMemory) {}
}

/// What a drawn sensor area detects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FootprintKind {
    /// A field sample point.
    Field,
    /// A puck-sensor disc.
    Puck,
    /// An obstacle-sensor disc.
    Obstacle,
}

/// A sensed area in arena coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Centre.
    pub centre: Vec2,
    /// Radius (0 for field sample points).
    pub radius: f64,
    /// What it detects.
    pub kind: FootprintKind,
}
