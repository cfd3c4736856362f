//! One running simulation as the view shows it: built from the view's
//! settings by the scenario code `host run` uses
//! ([`sim::scenario::choices::ScenarioChoices`]), stepped by its
//! controller, and described to browsers as a `hello` (what stays until
//! the next reset: arena, bodies' sizes, the robots' outline, the field
//! image, the settings) and `frame`s (what each step changes).

use crate::settings::ViewSettings;
use serde::Serialize;
use shared::PolicyBlob;
use sim::base::vec2::Vec2;
use sim::control::Controller;
use sim::episodes::eval::pucks_in_band;
use sim::physics::outline::Outline;
use sim::render::{self, RenderOptions};
use sim::scenario::sensor_setup::SelectedSensors;
use sim::scenario::trained_for;
use sim::sensors::{FootprintKind, SensorModel};
use sim::simulation::Simulation;
use std::path::PathBuf;

/// Width of the field image, pixels.
pub const FIELD_IMAGE_WIDTH: u32 = 800;

/// Points of the Eval plot kept: past this, every other one is dropped.
pub const HISTORY_POINTS: usize = 512;

/// A running simulation and its controller.
pub struct Session {
    settings: ViewSettings,
    sim: Simulation<SelectedSensors>,
    controller: Box<dyn Controller + Send>,
    /// Why the policy may act poorly here: it was trained for another
    /// sensor model or arena (`host run`'s warning).
    warning: Option<String>,
}

/// The plot's points (step, Eval, formations), at most [`HISTORY_POINTS`].
#[derive(Clone, Debug, Default)]
pub struct History(Vec<[f64; 3]>);

impl History {
    /// Adds a frame's step, Eval and formations (once a step); past
    /// [`HISTORY_POINTS`], every other point is dropped.
    pub fn record(&mut self, frame: &Frame) {
        let point = [frame.step as f64, frame.eval, frame.formations as f64];
        if self.0.last().is_some_and(|p| p[0] == point[0]) {
            return;
        }
        if self.0.len() >= HISTORY_POINTS {
            let mut k = 0;
            self.0.retain(|_| {
                k += 1;
                k % 2 == 1
            });
        }
        self.0.push(point);
    }

    /// The points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.0
    }
}

/// A policy to drive the robots with, already read or decoded.
pub struct Policy {
    /// Where it came from (a file, or an upload's name).
    pub path: PathBuf,
    /// The blob.
    pub blob: PolicyBlob,
}

/// What stays the same until the next reset.
#[derive(Clone, Debug, Serialize)]
pub struct Hello {
    /// The arena's width and height, units.
    pub arena: [f64; 2],
    /// Robot radius (the round back of a wedge), units.
    pub robot_radius: f64,
    /// Puck radius, units.
    pub puck_radius: f64,
    /// A wedge robot's outline, points (forward, right) in units around
    /// its centre; `None` for discs.
    pub outline: Option<Vec<[f64; 2]>>,
    /// Where a robot's sensors look, around its centre as the outline.
    pub sensors: Vec<SensorMark>,
    /// The floor a robot's camera sees, a polygon around its centre as the
    /// outline; empty without a camera.
    pub camera_view: Vec<[f64; 2]>,
    /// The settings, as URL parameters.
    pub settings: Vec<(String, String)>,
    /// Steps between formation checks.
    pub check_interval: u64,
    /// A second view to show beside this one (`host train --view`: the
    /// world acting with the learner's greedy table).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub companion: Option<Companion>,
    /// What the world is, over the panel (`host experiment --view`: the
    /// experiment, arm and trial).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub caption: Option<String>,
    /// A policy trained for another sensor model or arena than the world's:
    /// `host run`'s warning, shown on the page.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

/// A sensor's footprint in a robot's frame, for drawing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorMark {
    /// `field` (a point read), `puck` or `obstacle` (a disc searched).
    pub kind: &'static str,
    /// Its centre, (forward, right) in units from the robot's centre.
    pub at: [f64; 2],
    /// Its radius, units (0 for a field point).
    pub radius: f64,
}

/// A second view a page shows beside its own, in a frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Companion {
    /// Its heading.
    pub label: String,
    /// Its page's address.
    pub url: String,
}

/// A learning run's progress, sent with the frames of the world it learns
/// in (`host train --view`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Learning {
    /// States the learner has visited.
    pub states_visited: u64,
    /// States its hasher has.
    pub states_total: u64,
    /// Exploration (epsilon) now.
    pub exploration: f64,
    /// The training step of the greedy table the companion acts with, if
    /// it has one yet.
    pub greedy_step: Option<u64>,
}

/// The state after a step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Frame {
    /// Steps run since the reset.
    pub step: u64,
    /// Steps of the current episode.
    pub episode_step: u64,
    /// Eval of the current world.
    pub eval: f64,
    /// Episodes that formed the shape.
    pub formations: u64,
    /// Episodes reset at the stuck limit.
    pub stuck: u64,
    /// Mean Eval at the formation checks so far.
    pub mean_eval: f64,
    /// Robot-robot collisions per 1000 steps.
    pub collisions_per_1000: f64,
    /// Each robot's x, y, and heading's unit vector x, y: 4 numbers a robot.
    pub robots: Vec<f32>,
    /// Each puck's x, y.
    pub pucks: Vec<f32>,
    /// Each puck: 1 in the target band, 0 outside.
    pub in_band: Vec<u8>,
    /// With a learning run: its progress.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub learning: Option<Learning>,
}

impl Session {
    /// Builds the simulation of `settings`, driven by `policy` when the
    /// controller is a policy. Errors name the setting.
    pub fn build(settings: ViewSettings, policy: Option<Policy>) -> Result<Session, String> {
        let path = policy.as_ref().map(|p| p.path.clone());
        let choices = settings.choices(path);
        let warning = policy.as_ref().and_then(|p| {
            let here =
                trained_for::trained_for(&choices.world.sensors, &choices.world.arena_choice());
            trained_for::mismatch(p.blob.trained_for(), &here)
                .map(|why| format!("policy {}: {why}", p.path.display()))
        });
        let scenario = choices.scenario().map_err(|e| e.to_string())?;
        let built = match policy {
            Some(p) => scenario.build_with_policy(p.blob),
            None => scenario.build(),
        };
        let (sim, controller) = built.map_err(|e| e.to_string())?;
        Ok(Session {
            settings,
            sim,
            controller,
            warning,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &ViewSettings {
        &self.settings
    }

    /// The simulation.
    pub fn simulation(&self) -> &Simulation<SelectedSensors> {
        &self.sim
    }

    /// One step.
    pub fn step(&mut self) {
        self.sim.step(self.controller.as_mut());
    }

    /// What stays until the next reset.
    pub fn hello(&self) -> Hello {
        Hello {
            warning: self.warning.clone(),
            ..Hello::of(&self.sim, self.settings.pairs())
        }
    }

    /// The field as grey with the target band outlined, as a PNG
    /// [`FIELD_IMAGE_WIDTH`] pixels wide.
    pub fn field_png(&self) -> Result<Vec<u8>, String> {
        field_png(&self.sim)
    }

    /// The current state.
    pub fn frame(&self) -> Frame {
        Frame::of(&self.sim)
    }
}

impl Hello {
    /// What stays of `sim` until its next reset; `settings` as URL parameters.
    pub fn of(sim: &Simulation<SelectedSensors>, settings: Vec<(String, String)>) -> Hello {
        let world = sim.world().config();
        let arena = world.arena();
        Hello {
            arena: [arena.x, arena.y],
            robot_radius: world.robot_radius,
            puck_radius: world.puck_radius,
            outline: Outline::of(world.robot_shape, world.robot_radius).map(|o| boundary(&o)),
            sensors: sensor_marks(sim),
            camera_view: sim
                .sensors()
                .camera_view()
                .iter()
                .map(|p| [p.x, p.y])
                .collect(),
            settings,
            check_interval: sim.config().episode.check_interval,
            companion: None,
            caption: None,
            warning: None,
        }
    }
}

/// `sim`'s field as grey with the target band outlined, as a PNG
/// [`FIELD_IMAGE_WIDTH`] pixels wide.
pub fn field_png(sim: &Simulation<SelectedSensors>) -> Result<Vec<u8>, String> {
    let options = RenderOptions {
        size: FIELD_IMAGE_WIDTH,
        footprints: false,
        band: true,
    };
    let image = render::draw_ground(sim, options);
    let mut png = Vec::new();
    image::DynamicImage::ImageRgb8(image)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| format!("cannot encode the field image: {e}"))?;
    Ok(png)
}

impl Frame {
    /// `sim`'s current state.
    pub fn of(sim: &Simulation<SelectedSensors>) -> Frame {
        let world = sim.world();
        let totals = sim.totals();
        let robots = world
            .robots()
            .iter()
            .zip(world.bodies())
            .flat_map(|(r, b)| [b.pos.x, b.pos.y, r.direction.x, r.direction.y])
            .map(|v| v as f32)
            .collect();
        let pucks = world
            .pucks()
            .iter()
            .flat_map(|p| [p.pos.x as f32, p.pos.y as f32])
            .collect();
        let in_band = pucks_in_band(world, sim.field(), &sim.config().thresholds)
            .map(u8::from)
            .collect();
        Frame {
            step: totals.steps,
            episode_step: sim.state().episode_step,
            eval: sim.eval(),
            formations: totals.formations,
            stuck: totals.stuck,
            mean_eval: totals.mean_eval(),
            collisions_per_1000: totals.collisions_per_1000(),
            robots,
            pucks,
            in_band,
            learning: None,
        }
    }
}

/// Robot 0's sensor footprints in its own frame (every robot's are the
/// same there); none in a world without robots.
fn sensor_marks(sim: &Simulation<SelectedSensors>) -> Vec<SensorMark> {
    let world = sim.world();
    let (Some(body), Some(robot)) = (world.bodies().first(), world.robots().first()) else {
        return Vec::new();
    };
    let mut footprints = Vec::new();
    sim.sensors().footprints(world, 0, &mut footprints);
    let back = Vec2::new(robot.direction.x, -robot.direction.y);
    footprints
        .iter()
        .map(|f| {
            let at = (f.centre - body.pos).rotated(back);
            SensorMark {
                kind: match f.kind {
                    FootprintKind::Field => "field",
                    FootprintKind::Puck => "puck",
                    FootprintKind::Obstacle => "obstacle",
                },
                at: [at.x, at.y],
                radius: f.radius,
            }
        })
        .collect()
}

/// Points around a wedge robot's outline, (forward, right) in units: where
/// each of 64 rays from the centre leaves it.
fn boundary(outline: &Outline) -> Vec<[f64; 2]> {
    const RAYS: usize = 64;
    (0..RAYS)
        .map(|k| {
            let ray = Vec2::from_angle(k as f64 * std::f64::consts::TAU / RAYS as f64);
            let (mut inside, mut outside) = (0.0, outline.tip() * 1.5);
            for _ in 0..40 {
                let mid = (inside + outside) / 2.0;
                if outline.distance(ray * mid).0 <= 0.0 {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            [ray.x * inside, ray.y * inside]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim::config::robot_shape::RobotShape;
    use sim::scenario::choices::WorldChoices;

    #[test]
    fn a_sessions_frames_follow_host_runs_simulation_step_for_step() {
        let mut settings = ViewSettings::default();
        settings.world.robots = Some(3);
        settings.world.pucks = Some(20);
        settings.world.seed = 5;
        let mut session = Session::build(settings.clone(), None).unwrap();
        let (mut sim, mut controller) = settings.choices(None).scenario().unwrap().build().unwrap();
        for _ in 0..300 {
            session.step();
            sim.step(controller.as_mut());
        }
        let frame = session.frame();
        assert_eq!(frame.step, 300);
        assert_eq!(frame.robots.len(), 12);
        assert_eq!(frame.pucks.len(), 40);
        assert_eq!(frame.in_band.len(), 20);
        let b = &sim.world().bodies()[2];
        assert_eq!(
            (frame.robots[8], frame.robots[9]),
            (b.pos.x as f32, b.pos.y as f32)
        );
        assert_eq!(frame.eval, sim.eval());
        assert_eq!(frame.mean_eval, sim.totals().mean_eval());
    }

    #[test]
    fn the_wedges_outline_reaches_its_tip_ahead_and_its_radius_behind() {
        let o = Outline::of(RobotShape::Wedge { tip: 15.0 }, 10.0).unwrap();
        let points = boundary(&o);
        assert!((points[0][0] - o.tip()).abs() < 1e-6, "{:?}", points[0]);
        assert!((points[32][0] + 10.0).abs() < 1e-6, "{:?}", points[32]);
    }

    #[test]
    fn the_hello_places_each_sensor_in_the_robots_frame_whatever_its_heading() {
        // the disc model: three field points, four puck and two obstacle discs
        let session = Session::build(ViewSettings::default(), None).unwrap();
        let hello = session.hello();
        let kinds: Vec<&str> = hello.sensors.iter().map(|m| m.kind).collect();
        assert_eq!(
            kinds,
            ["field", "field", "field", "puck", "puck", "puck", "puck", "obstacle", "obstacle"]
        );
        // the left and right ones mirror each other across the heading
        let [l, _, r] = [0, 1, 2].map(|k| hello.sensors[k].at);
        assert!(
            (l[0] - r[0]).abs() < 1e-9 && (l[1] + r[1]).abs() < 1e-9,
            "{l:?} {r:?}"
        );
        assert!(l[1] < 0.0, "left is negative right: {l:?}");
        assert!(hello.camera_view.is_empty());
        // the robot's senses: the photo-transistors and the camera's floor
        let robot = Session::build(
            ViewSettings {
                world: WorldChoices {
                    sensors: sim::scenario::sensor_choice::SensorChoice::Robot(None),
                    ..WorldChoices::default()
                },
                ..ViewSettings::default()
            },
            None,
        )
        .unwrap();
        let hello = robot.hello();
        assert_eq!(hello.sensors.len(), 3);
        assert!(hello.sensors.iter().all(|m| m.kind == "field"));
        assert_eq!(
            hello.camera_view.len(),
            4 * sim::sensors::pixy_camera::VIEW_EDGE_POINTS
        );
        assert!(hello.camera_view.iter().all(|p| p[0] > 0.0));
    }

    #[test]
    fn the_plot_keeps_a_bounded_number_of_points() {
        let mut session = Session::build(
            ViewSettings {
                world: WorldChoices {
                    robots: Some(2),
                    pucks: Some(5),
                    ..WorldChoices::default()
                },
                ..ViewSettings::default()
            },
            None,
        )
        .unwrap();
        let mut history = History::default();
        for _ in 0..3 * HISTORY_POINTS {
            session.step();
            history.record(&session.frame());
        }
        assert!(history.points().len() <= HISTORY_POINTS);
        assert!(history.points().windows(2).all(|w| w[0][0] < w[1][0]));
    }
}
