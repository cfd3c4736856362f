//! `host bench`: the speed of frozen benchmark configurations,
//! single-threaded.
//!
//! A step is everything a run does per step: every robot's sensors, the
//! controller, physics, and Eval at the default check interval.
//!
//! With the disc sensors (the default) the configuration is the standard
//! one (annulus, 8 robots of which 4 innies, 250 pucks, orbital
//! construction, the thesis' 800 x 800 arena), timed from the start. With
//! the robot's senses (`--sensors robot`) it is the same with the random
//! controller (orbital construction piles robots against the walls, which
//! changes the camera's cost as a run goes on), timed after a warm-up, and
//! the report adds the mean number of bodies in the camera's range. On a
//! screen arena (`--arena tv75`) the bodies are the arena's own (5 robots
//! and 12 pucks on the TV: 250 pucks do not fit on it).

use anyhow::{bail, Result};
use sim::scenario::sensor_setup::SensorSetup;
use sim::scenario::{Arena, ControllerChoice, Scenario};
use sim::sensors::pixy_camera::PixyCameraConfig;
use sim::{config::BroadPhase, world::World};
use std::fmt;
use std::time::{Duration, Instant};

/// Which configuration to measure.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BenchVariant {
    /// All-pairs contact and sensor checks instead of the grid.
    pub naive: bool,
    /// 64 robots and 1,000 pucks in an arena enlarged to the standard
    /// density (800 x sqrt(1064 / 258) = 1625 units), instead of 8 and 250.
    pub scale: bool,
    /// The robot's senses (photo-transistors and Pixy camera, default
    /// settings) with the random controller, instead of the disc sensors
    /// with orbital construction.
    pub robot_senses: bool,
    /// The arena; `None` for the thesis' square.
    pub arena: Option<Arena>,
}

/// Steps run before timing with the robot's senses, so that the robots
/// have left their start positions.
pub const ROBOT_WARM_UP: u64 = 2_000;

/// Steps timed with the robot's senses unless told otherwise.
pub const ROBOT_STEPS: u64 = 20_000;

impl BenchVariant {
    /// The scenario measured: annulus, seed 1, orbital construction with
    /// the disc sensors or random turns with the robot's senses.
    pub fn scenario(&self) -> Scenario {
        let mut s = Scenario {
            broad_phase: if self.naive {
                BroadPhase::Naive
            } else {
                BroadPhase::Grid
            },
            ..Scenario::default()
        };
        if self.scale {
            s.robots = Some(64);
            s.pucks = Some(1000);
            let standard = (8 + 250) as f64;
            s.arena = Arena::Square((800.0 * (1064.0 / standard).sqrt()).round());
        }
        if let Some(arena) = &self.arena {
            s.arena = arena.clone();
        }
        if self.robot_senses {
            s.sensors = SensorSetup::Robot(Box::default());
            s.controller = ControllerChoice::Random;
        }
        s
    }

    /// Steps run untimed before the timed ones.
    pub fn warm_up(&self) -> u64 {
        if self.robot_senses {
            ROBOT_WARM_UP
        } else {
            0
        }
    }
}

/// What a benchmark run measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchReport {
    /// Timed steps per second.
    pub steps_per_second: f64,
    /// With the robot's senses: the mean, over the timed steps and the
    /// robots, of the other bodies whose nearest point lies within the
    /// camera's range of its lens (in any direction).
    pub bodies_in_camera_range: Option<f64>,
}

impl fmt::Display for BenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.0} steps/s", self.steps_per_second)?;
        if let Some(bodies) = self.bodies_in_camera_range {
            write!(
                f,
                "\n{bodies:.2} bodies in the camera's range (mean per robot and step)"
            )?;
        }
        Ok(())
    }
}

/// Runs the variant's warm-up, then `steps` timed steps (with the robot's
/// senses, counting the bodies in each camera's range after every step,
/// outside the timing).
pub fn run(variant: &BenchVariant, steps: u64) -> Result<BenchReport> {
    if variant.robot_senses && (variant.naive || variant.scale) {
        bail!("--sensors robot measures the standard configuration: it cannot be combined with --naive or --scale");
    }
    let (mut sim, mut controller) = variant.scenario().build()?;
    sim.run(&mut controller, variant.warm_up());
    if !variant.robot_senses {
        let start = Instant::now();
        sim.run(&mut controller, steps);
        return Ok(BenchReport {
            steps_per_second: rate(steps, start.elapsed()),
            bodies_in_camera_range: None,
        });
    }
    let camera = PixyCameraConfig::default();
    let unit_mm = sim.config().world.unit_mm;
    let range = CameraRange {
        forward: camera.forward_mm / unit_mm,
        max_range: camera.max_range_mm / unit_mm,
    };
    let (mut timed, mut seen) = (Duration::ZERO, 0u64);
    for _ in 0..steps {
        let start = Instant::now();
        sim.step(&mut controller);
        timed += start.elapsed();
        seen += range.bodies_seen(sim.world());
    }
    let robots = sim.world().robots().len() as u64;
    Ok(BenchReport {
        steps_per_second: rate(steps, timed),
        bodies_in_camera_range: Some(seen as f64 / (steps.max(1) * robots) as f64),
    })
}

fn rate(steps: u64, elapsed: Duration) -> f64 {
    let seconds = elapsed.as_secs_f64();
    if seconds > 0.0 {
        steps as f64 / seconds
    } else {
        f64::INFINITY
    }
}

/// Where a robot's camera sits and how far it sees, units.
struct CameraRange {
    forward: f64,
    max_range: f64,
}

impl CameraRange {
    /// Bodies within range of each robot's lens, summed over the robots.
    fn bodies_seen(&self, world: &World) -> u64 {
        let mut seen = 0;
        for (i, robot) in world.robots().iter().enumerate() {
            let lens = world.bodies()[i].pos + robot.direction * self.forward;
            world.any_body_near(lens, self.max_range, |row| {
                for b in row {
                    let reach = self.max_range + b.radius;
                    seen += u64::from(
                        b.body as usize != i && (b.pos - lens).length_squared() <= reach * reach,
                    );
                }
                false
            });
        }
        seen
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim::base::vec2::Vec2;

    #[test]
    fn the_robot_benchmark_counts_the_bodies_a_camera_could_see() {
        let variant = BenchVariant {
            robot_senses: true,
            ..BenchVariant::default()
        };
        let report = run(&variant, 50).unwrap();
        let bodies = report.bodies_in_camera_range.unwrap();
        // 257 other bodies in the arena; a range of 250 units from the lens
        // covers a good part of it.
        assert!(bodies > 10.0 && bodies < 257.0, "{bodies}");
        assert!(report.to_string().contains("bodies in the camera's range"));
        let naive = BenchVariant {
            naive: true,
            ..variant
        };
        assert!(run(&naive, 1).unwrap_err().to_string().contains("--naive"));
    }

    #[test]
    fn bodies_in_range_are_counted_by_the_distance_of_their_nearest_point() {
        let config = sim::config::SimConfig::default();
        let robots = [(
            Vec2::new(100.0, 100.0),
            0.0,
            sim::physics::body::RobotKind::Outie,
        )];
        // Lens at 103 (forward 3); range 250: the puck at 362 reaches to
        // 352 (in), the one at 364 only to 354 (out); one behind is in.
        let world = World::scene(
            &config,
            &robots,
            &[
                Vec2::new(362.0, 100.0),
                Vec2::new(364.5, 100.0),
                Vec2::new(50.0, 100.0),
            ],
            1,
        );
        let range = CameraRange {
            forward: 3.0,
            max_range: 250.0,
        };
        assert_eq!(range.bodies_seen(&world), 2);
    }
}
