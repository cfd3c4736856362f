//! The world: arena, bodies, robots, the step counter and the world's
//! random generator, plus the derived neighbour index and step buffers.
//!
//! [`World`] serialises as its [`WorldState`] (everything that determines
//! the future); deserialising rebuilds the index, so a checkpointed world
//! resumes bit-exactly.
//!
//! Room 5 of the simulator (`lib.rs`), the first stage of a step (**world** -> physics -> sensors -> control): it owns the bodies and calls physics to move them.

use crate::base::noise::{self, Purpose};
use crate::base::rng::SimRng;
use crate::base::vec2::Vec2;
use crate::config::actuation::RobotMotion;
use crate::config::validate::ConfigError;
use crate::config::{PhysicsConfig, SimConfig, WorldConfig};
use crate::physics::body::{Body, Robot, RobotKind};
use crate::physics::broadphase::NeighbourIndex;
use crate::physics::grid::Neighbour;
use crate::physics::outline::Outline;
use crate::physics::{candidate_reach, PhysicsScratch, StepContext};
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::ops::Range;

/// Everything that determines a world's future: settings, bodies, robots,
/// step counter and generator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldState {
    /// Arena and bodies.
    pub config: WorldConfig,
    /// Contact model.
    pub physics: PhysicsConfig,
    /// Robots first (`0 .. robots`), then pucks.
    pub bodies: Vec<Body>,
    /// One per robot body.
    pub robots: Vec<Robot>,
    /// Physics steps since the world was created.
    pub steps: u64,
    /// Drawn for start positions and the coincident-centre nudge.
    pub rng: SimRng,
    /// The seed the world was created with, from which the noise models
    /// draw ([`crate::base::noise`]).
    pub seed: u64,
    /// Episodes begun before the current one (resets so far).
    pub episode: u64,
    /// Each robot's turn of the last step (a dropped period repeats it);
    /// empty before the first step.
    pub last_turns: Vec<f32>,
}

/// A simulated arena with robots and pucks.
#[derive(Clone, Debug)]
pub struct World {
    state: WorldState,
    index: NeighbourIndex,
    scratch: PhysicsScratch,
    /// Each robot's forward speed of the step (with actuation noise).
    scratch_speeds: Vec<f64>,
    /// Each robot's motion of the episode
    /// ([`crate::config::actuation::ActuationNoise::motion`]),
    /// drawn when the episode begins rather than every step.
    motions: Vec<RobotMotion>,
}

impl World {
    /// A world with random start positions drawn from a generator seeded
    /// with `seed`. The settings are validated first.
    pub fn new(config: &SimConfig, seed: u64) -> Result<World, ConfigError> {
        config.validate()?;
        let mut rng = SimRng::seed_from_u64(seed);
        let bodies = start_positions(&config.world, &mut rng);
        let robots = start_robots(&config.world, &mut rng);
        Ok(World::from_state(WorldState {
            config: config.world.clone(),
            physics: config.physics.clone(),
            bodies,
            robots,
            steps: 0,
            rng,
            seed,
            episode: 0,
            last_turns: Vec::new(),
        }))
    }

    /// A world from a saved state (or a hand-made scene: the bodies need
    /// not match the config's counts, but robots must come first, one per
    /// entry of `robots`).
    pub fn from_state(state: WorldState) -> World {
        let index = index_of(&state);
        let scratch = PhysicsScratch::new(&state.bodies, state.robots.len());
        let motions = motions_of(&state);
        World {
            state,
            index,
            scratch,
            scratch_speeds: Vec::new(),
            motions,
        }
    }

    /// A hand-placed scene (tests, figures): robots at the given positions,
    /// headings and kinds, then pucks at rest; the counts in `config` are
    /// replaced by the scene's.
    pub fn scene(
        config: &SimConfig,
        robots: &[(Vec2, f64, RobotKind)],
        pucks: &[Vec2],
        seed: u64,
    ) -> World {
        let c = &config.world;
        let mut bodies: Vec<Body> = robots.iter().map(|&(p, _, _)| robot_body(p, c)).collect();
        bodies.extend(pucks.iter().map(|&p| puck(Body::new(p, c.puck_radius), c)));
        let robot_state = robots
            .iter()
            .map(|&(_, heading, kind)| Robot::new(heading, kind))
            .collect();
        let innies = robots.iter().filter(|r| r.2 == RobotKind::Innie).count();
        World::from_state(WorldState {
            config: WorldConfig {
                robots: robots.len(),
                innies,
                pucks: pucks.len(),
                ..c.clone()
            },
            physics: config.physics.clone(),
            bodies,
            robots: robot_state,
            steps: 0,
            rng: SimRng::seed_from_u64(seed),
            seed,
            episode: 0,
            last_turns: Vec::new(),
        })
    }

    /// Everything that determines the future, for checkpoints.
    pub fn state(&self) -> &WorldState {
        &self.state
    }

    /// New random positions and headings for every body, at rest, drawn
    /// from the world's generator (an episode reset).
    pub fn reset(&mut self) {
        let s = &mut self.state;
        s.bodies = start_positions(&s.config, &mut s.rng);
        s.robots = start_robots(&s.config, &mut s.rng);
        s.episode += 1;
        s.last_turns.clear();
        self.index = index_of(s);
        self.scratch = PhysicsScratch::new(&s.bodies, s.robots.len());
        self.motions = motions_of(s);
    }

    /// Turns every robot by its angular speed (radians, positive = right),
    /// then runs one physics step; with actuation noise
    /// ([`crate::config::actuation`]) as each robot really moves.
    pub fn step(&mut self, turns: &[f32]) {
        let noisy = !self.state.config.actuation.is_none();
        if noisy {
            self.actuate(turns);
        } else {
            for (robot, &w) in self.state.robots.iter_mut().zip(turns) {
                robot.turn(f64::from(w));
            }
        }
        let s = &mut self.state;
        StepContext {
            bodies: &mut s.bodies,
            robots: &s.robots,
            forward_speed: s.config.forward_speed,
            robot_speeds: noisy.then_some(&self.scratch_speeds[..]),
            config: &s.physics,
            arena: s.config.arena(),
            max_radius: s.config.max_radius(),
            outline: Outline::of(s.config.robot_shape, s.config.robot_radius),
            index: &mut self.index,
            rng: &mut s.rng,
            scratch: &mut self.scratch,
        }
        .step();
        s.steps += 1;
    }

    /// Turns the robots as they really do and sets their speeds for this
    /// step: each one's motion of the episode, the period's length, a
    /// dropped period's repeated turn.
    fn actuate(&mut self, turns: &[f32]) {
        let s = &mut self.state;
        let actuation = &s.config.actuation;
        s.last_turns.resize(s.robots.len(), 0.0);
        self.scratch_speeds.resize(s.robots.len(), 0.0);
        let step = noise::place(s.seed, Purpose::Period, s.steps);
        for (i, robot) in s.robots.iter_mut().enumerate() {
            let motion = self.motions[i];
            let (length, dropped) = actuation.period_at(step, i);
            let commanded = turns.get(i).copied().unwrap_or(0.0);
            let turn = if dropped { s.last_turns[i] } else { commanded };
            s.last_turns[i] = turn;
            robot.turn((f64::from(turn) + motion.turn_bias) * length);
            self.scratch_speeds[i] = s.config.forward_speed * motion.wheel_speed_factor * length;
        }
    }

    /// Arena and body settings.
    pub fn config(&self) -> &WorldConfig {
        &self.state.config
    }

    /// All bodies, robots first.
    pub fn bodies(&self) -> &[Body] {
        &self.state.bodies
    }

    /// The robots; robot `i` is body `i`.
    pub fn robots(&self) -> &[Robot] {
        &self.state.robots
    }

    /// Body indices of the pucks.
    pub(crate) fn puck_range(&self) -> Range<usize> {
        self.state.robots.len()..self.state.bodies.len()
    }

    /// The pucks' bodies.
    pub fn pucks(&self) -> &[Body] {
        &self.state.bodies[self.puck_range()]
    }

    /// Physics steps run so far.
    pub fn steps(&self) -> u64 {
        self.state.steps
    }

    /// Distinct robot-robot pairs that were in contact in the last step.
    pub fn robot_contacts(&self) -> usize {
        self.scratch.robot_contacts()
    }

    /// Calls `f` with every body whose position changed since the last
    /// call (or since the world was built or reset), ascending by index.
    pub(crate) fn drain_moved(&mut self, mut f: impl FnMut(usize, &Body)) {
        let bodies = &self.state.bodies;
        self.scratch.drain_moved(|i| f(i, &bodies[i]))
    }

    /// The contacts of the last step, in the order they were found.
    pub fn contacts(&self) -> &[crate::physics::Contact] {
        self.scratch.contacts()
    }

    /// A puck that overlaps the disc at `centre` of `radius` (strictly:
    /// touching is not overlapping), if there is one.
    pub(crate) fn puck_in_disc(&self, centre: Vec2, radius: f64) -> Option<usize> {
        const NONE: u32 = u32::MAX;
        let robots = self.state.robots.len() as u32;
        let half = radius + self.state.config.puck_radius;
        let mut found = NONE;
        self.any_body_in_box(
            centre - Vec2::new(half, half),
            centre + Vec2::new(half, half),
            |row| {
                for n in row {
                    let hit = (n.body >= robots) & disc_overlaps(centre, radius, n.pos, n.radius);
                    found = if hit { n.body } else { found };
                }
                found != NONE
            },
        );
        (found != NONE).then_some(found as usize)
    }

    /// Whether body `body` is a puck that overlaps the disc at `centre` of
    /// `radius`: the test of [`World::puck_in_disc`] for one body.
    pub(crate) fn puck_overlaps_disc(&self, body: usize, centre: Vec2, radius: f64) -> bool {
        match self.state.bodies.get(body) {
            Some(b) if body >= self.state.robots.len() => {
                disc_overlaps(centre, radius, b.pos, b.radius)
            }
            _ => false,
        }
    }

    /// Whether `pred` holds for some run of bodies; the runs together hold
    /// at least every body whose centre is closer than `reach` to body
    /// `body`'s (and maybe others), and none are passed after `pred`
    /// returns true.
    pub(crate) fn any_body_around(
        &self,
        body: usize,
        reach: f64,
        pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        self.index.any_around(&self.state.bodies, body, reach, pred)
    }

    /// Whether `pred` holds for some run of bodies; the runs together hold
    /// at least every body whose circle reaches within `reach` of `centre`
    /// (and maybe others), and none are passed after `pred` returns true.
    pub fn any_body_near(
        &self,
        centre: Vec2,
        reach: f64,
        pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        let r = reach + self.state.config.max_radius();
        self.any_body_in_box(centre - Vec2::new(r, r), centre + Vec2::new(r, r), pred)
    }

    /// Whether `pred` holds for some run of bodies; the runs together hold
    /// at least every body whose centre lies in the box `min ..= max` (and
    /// maybe others), and none are passed after `pred` returns true.
    pub(crate) fn any_body_in_box(
        &self,
        min: Vec2,
        max: Vec2,
        pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        self.index.any_in_box(min, max, pred)
    }
}

/// Whether the disc at `centre` of `radius` and a circle at `pos` of
/// `circle_radius` overlap (strictly: touching is not overlapping): the
/// one test every disc sensor applies.
#[inline]
pub(crate) fn disc_overlaps(centre: Vec2, radius: f64, pos: Vec2, circle_radius: f64) -> bool {
    let r = radius + circle_radius;
    (pos - centre).length_squared() < r * r
}

/// Each robot's motion in a state's episode.
fn motions_of(state: &WorldState) -> Vec<RobotMotion> {
    let actuation = &state.config.actuation;
    (0..state.robots.len())
        .map(|i| actuation.motion(state.seed, state.episode, i))
        .collect()
}

/// A fresh neighbour index of a state's bodies.
fn index_of(state: &WorldState) -> NeighbourIndex {
    NeighbourIndex::new(
        state.config.broad_phase,
        state.config.arena(),
        candidate_reach(state.config.max_radius()),
        &state.bodies,
    )
}

/// Robots uniformly in `[r, side - r)` (`r` their bodies' radius: a
/// wedge's tip distance), then pucks in `[4r, side - 4r)`, on each axis (x
/// drawn before y).
fn start_positions(c: &WorldConfig, rng: &mut SimRng) -> Vec<Body> {
    let mut place = |margin: f64| {
        let x = rng.random_range(margin..c.arena_width - margin);
        let y = rng.random_range(margin..c.arena_height - margin);
        Vec2::new(x, y)
    };
    let mut bodies = Vec::with_capacity(c.bodies());
    bodies.extend((0..c.robots).map(|_| robot_body(place(c.robot_body_radius()), c)));
    bodies.extend(
        (0..c.pucks).map(|_| puck(Body::new(place(4.0 * c.puck_radius), c.puck_radius), c)),
    );
    bodies
}

/// A robot's body at rest: its outline's bounding radius, and the mass of
/// a disc of the robot radius whatever the outline (a foam skirt weighs
/// next to nothing).
fn robot_body(pos: Vec2, c: &WorldConfig) -> Body {
    Body {
        radius: c.robot_body_radius(),
        ..Body::new(pos, c.robot_radius)
    }
}

/// A puck body with the configured mass, if one is set.
fn puck(mut body: Body, c: &WorldConfig) -> Body {
    if let Some(mass) = c.puck_mass {
        body.mass = mass;
    }
    body
}

/// Uniformly random headings; the first `innies` robots are innies.
fn start_robots(c: &WorldConfig, rng: &mut SimRng) -> Vec<Robot> {
    (0..c.robots)
        .map(|i| {
            let kind = if i < c.innies {
                RobotKind::Innie
            } else {
                RobotKind::Outie
            };
            Robot::new(rng.random_range(0.0..std::f64::consts::TAU), kind)
        })
        .collect()
}

impl Serialize for World {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.state.serialize(s)
    }
}

impl<'de> Deserialize<'de> for World {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<World, D::Error> {
        WorldState::deserialize(d).map(World::from_state)
    }
}
