//! Sensor models combined ([`MixedSensors`]), for ablations: the field
//! values of one model, the puck bits of another and the obstacle bits of
//! a third, for example the robot's photo-transistors with the thesis'
//! puck and obstacle discs.

use crate::base::vec2::Vec2;
use crate::fields::ScalarField;
use crate::sensors::{Footprint, SensorMemory, SensorModel};
use crate::world::World;
use shared::SensorReading;

/// Field values from `field`, puck bits from `pucks`, obstacle bits from
/// `obstacles`.
#[derive(Clone, Debug)]
pub struct MixedSensors<M> {
    field: M,
    pucks: M,
    obstacles: M,
    scratch: Vec<SensorReading>,
}

impl<M: SensorModel> MixedSensors<M> {
    /// The three models' mix.
    pub fn new(field: M, pucks: M, obstacles: M) -> MixedSensors<M> {
        MixedSensors {
            field,
            pucks,
            obstacles,
            scratch: Vec::new(),
        }
    }
}

impl<M: SensorModel> SensorModel for MixedSensors<M> {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        self.field.sense(world, field, out);
        self.scratch.resize(out.len(), SensorReading::default());
        self.pucks.sense(world, field, &mut self.scratch);
        for (reading, pucks) in out.iter_mut().zip(&self.scratch) {
            reading.puck_left = pucks.puck_left;
            reading.puck_right = pucks.puck_right;
        }
        self.obstacles.sense(world, field, &mut self.scratch);
        for (reading, obstacles) in out.iter_mut().zip(&self.scratch) {
            reading.obstacle_left = obstacles.obstacle_left;
            reading.obstacle_right = obstacles.obstacle_right;
        }
    }

    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        self.field.footprints(world, robot, out);
        self.pucks.footprints(world, robot, out);
        self.obstacles.footprints(world, robot, out);
    }

    /// The puck part's camera's, else the obstacle part's.
    fn camera_view(&self) -> Vec<Vec2> {
        let pucks = self.pucks.camera_view();
        if pucks.is_empty() {
            self.obstacles.camera_view()
        } else {
            pucks
        }
    }

    /// The three parts' camera models, in order.
    fn memory(&self) -> SensorMemory {
        let mut cameras = self.field.memory().cameras;
        cameras.extend(self.pucks.memory().cameras);
        cameras.extend(self.obstacles.memory().cameras);
        SensorMemory { cameras }
    }

    fn restore(&mut self, memory: &SensorMemory) {
        let mut rest = &memory.cameras[..];
        for part in [&mut self.field, &mut self.pucks, &mut self.obstacles] {
            let k = part.memory().cameras.len().min(rest.len());
            part.restore(&SensorMemory {
                cameras: rest[..k].to_vec(),
            });
            rest = &rest[k..];
        }
    }
}
