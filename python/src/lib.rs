//! `zumo_swarm._native`: the simulator of the `sim` crate for Python, as a
//! batch of worlds stepped in Rust threads with NumPy arrays in and out.
//!
//! This crate holds no simulation logic: [`settings`] checks the keyword
//! arguments and builds a `sim` scenario, [`world_env`] drives one
//! simulation through `sim`'s step API (observe, advance, reset) with the
//! reward and truncation an environment adds, [`batch`] steps many worlds
//! in parallel, [`observation`] turns readings into arrays, and
//! [`policy_codec`] encodes greedy tables with `shared`'s blob format. The
//! Gymnasium and PettingZoo classes are Python (`zumo_swarm/`), over
//! [`PyBatch`]; their `render_mode="human"` hands world 0 to the `view`
//! crate's `View::follow` after every step and reset.
#![warn(missing_docs)]

pub mod batch;
pub mod observation;
pub mod policy_codec;
pub mod settings;
pub mod world_env;

use batch::{Actions, Batch, StepError};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use observation::Observations;
use policy_codec::PolicyHeader;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict};
use settings::{ActionKind, Autoreset, EnvArgs, ObservationKind, READING_LEN};
use shared::{ActionTable, StateHasher};
use sim::episodes::reward::Reward;
use sim::render::RenderOptions;
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_choice::SensorChoice;

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn step_error(e: StepError) -> PyErr {
    match e {
        StepError::WrongKind { .. } => PyTypeError::new_err(e.to_string()),
        StepError::Ended { .. } => PyRuntimeError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// The seeds `reset` takes: the first world's, or one per world.
#[derive(FromPyObject)]
enum Seeds {
    /// World `i`: this seed + `i`.
    First(i64),
    /// One per world.
    Each(Vec<i64>),
}

/// Worlds of one configuration, stepped together.
#[pyclass(module = "zumo_swarm._native", name = "Batch")]
pub struct PyBatch {
    batch: Batch,
    /// The live view of world 0 (`render_mode="human"`), fed after every
    /// step and reset.
    view: Option<view::Follower>,
}

fn observations_array<'py>(
    py: Python<'py>,
    obs: Observations,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(match obs {
        Observations::Readings(v) => PyArray1::from_vec(py, v).reshape(shape)?.into_any(),
        Observations::States(v) => PyArray1::from_vec(py, v).reshape(shape)?.into_any(),
    })
}

impl PyBatch {
    /// The observation array's shape: worlds, robots, then floats per robot.
    fn observation_shape(&self, worlds: usize) -> Vec<usize> {
        let robots = self.batch.settings().robots();
        match self.batch.settings().observation {
            ObservationKind::Reading => vec![worlds, robots, READING_LEN],
            ObservationKind::State(_) => vec![worlds, robots],
        }
    }

    /// Gives the live view, if one is served, world 0 after a step or
    /// (`restarted`) a reset.
    fn feed_view(&self, restarted: bool) -> PyResult<()> {
        let Some(view) = &self.view else {
            return Ok(());
        };
        let sim = self.batch.worlds()[0].sim();
        if restarted {
            view.reset(sim).map_err(PyRuntimeError::new_err)
        } else {
            view.step(sim);
            Ok(())
        }
    }

    fn world_index(&self, world: usize) -> PyResult<usize> {
        let n = self.batch.worlds().len();
        if world < n {
            Ok(world)
        } else {
            Err(value_error(format!("world = {world}: must be in 0..{n}")))
        }
    }
}

/// The world settings given as keyword arguments, each as the text
/// [`WorldChoices::set`] reads: a whole number or a number as written,
/// a string as it is, `None` as "" (the arena's own).
fn world_settings(kwargs: &Bound<'_, PyDict>) -> PyResult<Vec<(String, String)>> {
    kwargs
        .iter()
        .map(|(name, value)| {
            let name: String = name.extract()?;
            let text = if value.is_none() {
                String::new()
            } else if value.is_instance_of::<PyBool>() {
                return Err(PyTypeError::new_err(format!(
                    "{name} = {value}: expected a number or a name"
                )));
            } else if let Ok(n) = value.extract::<i64>() {
                n.to_string()
            } else if let Ok(x) = value.extract::<f64>() {
                x.to_string()
            } else if let Ok(s) = value.extract::<String>() {
                s
            } else {
                return Err(PyTypeError::new_err(format!(
                    "{name} = {value}: expected a number or a name"
                )));
            };
            Ok((name, text))
        })
        .collect()
}

#[pymethods]
impl PyBatch {
    /// `num_worlds` worlds seeded `seed`, `seed + 1`, ...; the keyword
    /// arguments are the environments' (docs/python.md), the world's
    /// settings other than those named here among them (`world`, by the
    /// names of [`WorldChoices`]). `autoreset` is "off", "next-step" or
    /// "same-step"; `threads` defaults to one per core.
    #[new]
    #[pyo3(signature = (
        num_worlds = 1, *, field = "annulus".to_string(), robots = None, pucks = None, sensors = "disc".to_string(),
        robot_config = None, seed = 1, max_steps = None, thresholds = None, reward = "reference".to_string(),
        gamma = settings::DEFAULT_GAMMA, observation = "reading".to_string(), hasher = "original".to_string(), action = "discrete".to_string(),
        actions = None, forward_speed = ActionTable::DEFAULT_FORWARD_SPEED, autoreset = "next-step".to_string(),
        threads = None, arena = None, **world
    ))]
    #[allow(
        clippy::too_many_arguments,
        reason = "each argument is a Python keyword argument of the constructor"
    )]
    fn new(
        py: Python<'_>,
        num_worlds: i64,
        field: String,
        robots: Option<i64>,
        pucks: Option<i64>,
        sensors: String,
        robot_config: Option<String>,
        seed: i64,
        max_steps: Option<i64>,
        thresholds: Option<(f64, f64)>,
        reward: String,
        gamma: f64,
        observation: String,
        hasher: String,
        action: String,
        actions: Option<Vec<f32>>,
        forward_speed: f32,
        autoreset: String,
        threads: Option<i64>,
        arena: Option<String>,
        world: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyBatch> {
        let args = EnvArgs {
            field,
            arena,
            robots,
            pucks,
            sensors,
            robot_config,
            seed,
            max_steps,
            thresholds,
            reward,
            gamma,
            observation,
            hasher,
            action,
            actions: actions.unwrap_or_else(|| ActionTable::DEFAULT_ANGULAR.to_vec()),
            forward_speed,
            world: world.map(world_settings).transpose()?.unwrap_or_default(),
        };
        // before any world is allocated
        let num_worlds = settings::count(&sim::base::ranges::WORLDS, "num_worlds", num_worlds)
            .map_err(value_error)?;
        let autoreset = match autoreset.as_str() {
            "off" => Autoreset::Off,
            "next-step" => Autoreset::NextStep,
            "same-step" => Autoreset::SameStep,
            other => {
                return Err(value_error(format!(
                    "autoreset = {other:?}: expected \"off\", \"next-step\" or \"same-step\""
                )))
            }
        };
        let threads = match threads {
            None => std::thread::available_parallelism().map_or(1, |n| n.get()),
            Some(t) => settings::count(&sim::base::ranges::THREADS, "threads", t)
                .map_err(value_error)? as usize,
        };
        settings::world_seeds(args.seed, num_worlds as usize).map_err(value_error)?;
        let batch = py
            .detach(|| {
                let settings = args.settings().map_err(|e| e.to_string())?;
                Batch::new(settings, num_worlds as usize, autoreset, threads)
                    .map_err(|e| e.to_string())
            })
            .map_err(PyValueError::new_err)?;
        Ok(PyBatch { batch, view: None })
    }

    /// Number of worlds.
    #[getter]
    fn num_worlds(&self) -> usize {
        self.batch.worlds().len()
    }

    /// Robots per world.
    #[getter]
    fn robots(&self) -> usize {
        self.batch.settings().robots()
    }

    /// Threads that step the worlds.
    #[getter]
    fn threads(&self) -> usize {
        self.batch.threads()
    }

    /// The action table's angular speeds, radians per step.
    #[getter]
    fn angular_speeds(&self) -> Vec<f32> {
        self.batch.settings().actions.angular_speeds().to_vec()
    }

    /// The robots' forward speed, units per step.
    #[getter]
    fn forward_speed(&self) -> f32 {
        self.batch.settings().actions.forward_speed()
    }

    /// The bound of a continuous action: the table's largest angular speed.
    #[getter]
    fn max_turn(&self) -> f32 {
        self.batch.settings().max_turn()
    }

    /// "discrete" or "continuous".
    #[getter]
    fn action(&self) -> &'static str {
        match self.batch.settings().action {
            ActionKind::Discrete => "discrete",
            ActionKind::Continuous => "continuous",
        }
    }

    /// The hasher's name for state observations, `None` for readings.
    #[getter]
    fn hasher(&self) -> Option<&'static str> {
        match self.batch.settings().observation {
            ObservationKind::State(h) => Some(h.name()),
            ObservationKind::Reading => None,
        }
    }

    /// Number of states of a state observation, `None` for readings.
    #[getter]
    fn num_states(&self) -> Option<usize> {
        match self.batch.settings().observation {
            ObservationKind::State(h) => Some(h.num_states()),
            ObservationKind::Reading => None,
        }
    }

    /// The first world's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.batch.settings().seed
    }

    /// Episode steps before truncation by the stuck limit.
    #[getter]
    fn stuck_limit(&self) -> u64 {
        self.batch.settings().prepared.config().episode.stuck_limit
    }

    /// Truncation by `max_steps`, if set.
    #[getter]
    fn max_steps(&self) -> Option<u64> {
        self.batch.settings().max_steps
    }

    /// Steps between formation checks.
    #[getter]
    fn check_interval(&self) -> u64 {
        self.batch
            .settings()
            .prepared
            .config()
            .episode
            .check_interval
    }

    /// The reward's name.
    #[getter]
    fn reward(&self) -> &'static str {
        self.batch.settings().reward.name()
    }

    /// Starts every world's next episode (the first reset of a world just
    /// built keeps the episode its seed laid out); with `seeds`, a list of
    /// one per world, or one number, the first world's (world `i`: `seeds +
    /// i`), each world starts afresh from its seed. Returns the
    /// observations.
    #[pyo3(signature = (seeds = None))]
    fn reset<'py>(&mut self, py: Python<'py>, seeds: Option<Seeds>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.batch.worlds().len();
        let seeds = match seeds {
            None => None,
            Some(Seeds::First(first)) => {
                Some(settings::world_seeds(first, n).map_err(value_error)?)
            }
            Some(Seeds::Each(s)) if s.len() != n => {
                return Err(value_error(format!(
                    "seed: got {} seeds for {n} worlds",
                    s.len()
                )))
            }
            Some(Seeds::Each(s)) => Some(
                s.iter()
                    .map(|&x| settings::world_seeds(x, 1).map(|one| one[0]))
                    .collect::<Result<Vec<u64>, _>>()
                    .map_err(value_error)?,
            ),
        };
        let batch = &mut self.batch;
        let obs = py
            .detach(|| batch.reset(seeds.as_deref()))
            .map_err(value_error)?;
        self.feed_view(true)?;
        observations_array(py, obs, &self.observation_shape(n))
    }

    /// Every world's current observations.
    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        observations_array(
            py,
            self.batch.observations(),
            &self.observation_shape(self.batch.worlds().len()),
        )
    }

    /// One step of every world with a flat array of worlds x robots
    /// actions (int64 indices or float64 angular speeds). Returns
    /// (observations, reward per world, terminated, truncated, info,
    /// reward per robot (worlds x robots)), info a dict of per-world
    /// arrays; with same-step autoreset it holds `final_obs` (zeros for
    /// worlds that did not end) and `_final_obs`.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let out = if let Ok(a) = actions.extract::<PyReadonlyArray1<'py, i64>>() {
            let a = a.as_slice()?;
            let batch = &mut self.batch;
            py.detach(|| batch.step(Actions::Discrete(a)))
        } else if let Ok(a) = actions.extract::<PyReadonlyArray1<'py, f64>>() {
            let a = a.as_slice()?;
            let batch = &mut self.batch;
            py.detach(|| batch.step(Actions::Continuous(a)))
        } else {
            return Err(PyTypeError::new_err(
                "actions must be a one-dimensional int64 or float64 NumPy array",
            ));
        }
        .map_err(step_error)?;
        // world 0 started a new episode in this step (autoreset)
        self.feed_view(out.steps[0].reset || out.final_mask.first() == Some(&true))?;
        let n = out.steps.len();
        let shape = self.observation_shape(n);
        let column = |f: &dyn Fn(&world_env::WorldStep) -> f64| {
            out.steps.iter().map(f).collect::<Vec<f64>>()
        };
        let info = PyDict::new(py);
        info.set_item("eval", PyArray1::from_vec(py, column(&|s| s.eval)))?;
        let ints =
            |f: &dyn Fn(usize) -> i64| PyArray1::from_vec(py, (0..n).map(f).collect::<Vec<i64>>());
        info.set_item("episode_step", ints(&|i| out.steps[i].episode_step as i64))?;
        info.set_item(
            "robot_contacts",
            ints(&|i| out.steps[i].robot_contacts as i64),
        )?;
        let worlds = self.batch.worlds();
        info.set_item(
            "formations",
            ints(&|i| worlds[i].totals().formations as i64),
        )?;
        info.set_item("stuck_episodes", ints(&|i| worlds[i].totals().stuck as i64))?;
        info.set_item("total_steps", ints(&|i| worlds[i].totals().steps as i64))?;
        info.set_item(
            "mean_eval",
            PyArray1::from_vec(py, worlds.iter().map(|w| w.totals().mean_eval()).collect()),
        )?;
        info.set_item(
            "collisions_per_1000",
            PyArray1::from_vec(
                py,
                worlds
                    .iter()
                    .map(|w| w.totals().collisions_per_1000())
                    .collect(),
            ),
        )?;
        info.set_item(
            "reset",
            PyArray1::from_vec(py, out.steps.iter().map(|s| s.reset).collect::<Vec<bool>>()),
        )?;
        if let Some(finals) = out.final_observations {
            info.set_item("final_obs", observations_array(py, finals, &shape)?)?;
            info.set_item("_final_obs", PyArray1::from_vec(py, out.final_mask))?;
        }
        let rewards = PyArray1::from_vec(py, column(&|s| s.reward));
        let terminated = PyArray1::from_vec(
            py,
            out.steps
                .iter()
                .map(|s| s.terminated)
                .collect::<Vec<bool>>(),
        );
        let truncated = PyArray1::from_vec(
            py,
            out.steps.iter().map(|s| s.truncated).collect::<Vec<bool>>(),
        );
        let obs = observations_array(py, out.observations, &shape)?;
        let robots = self.batch.settings().robots();
        let robot_rewards = PyArray1::from_vec(py, out.robot_rewards).reshape([n, robots])?;
        Ok((obs, rewards, terminated, truncated, info, robot_rewards)
            .into_pyobject(py)?
            .into_any())
    }

    /// Serves the live view of world 0 (`docs/view.md`) on `bind` (by
    /// default loopback, any free port) until [`PyBatch::close_view`] or
    /// the batch is dropped; every step and reset is shown. Returns the
    /// page's address.
    #[pyo3(signature = (bind = "127.0.0.1:0"))]
    fn serve_view(&mut self, bind: &str) -> PyResult<String> {
        let address = bind.parse().map_err(|e| {
            value_error(format!(
                "bind = {bind:?}: expected an address and port such as 127.0.0.1:0 ({e})"
            ))
        })?;
        // the old one stops first, so its port is free again
        self.view = None;
        let follower = view::View::follow(address, self.batch.worlds()[0].sim())
            .map_err(PyRuntimeError::new_err)?;
        let url = follower.url();
        self.view = Some(follower);
        Ok(url)
    }

    /// Stops the live view, if one is served.
    fn close_view(&mut self) {
        self.view = None;
    }

    /// World `world` drawn as `host render` draws it: an RGB array of
    /// `size` x `size` pixels (field grey, pucks red, robots blue; with
    /// `band` the target band outlined in cyan and the pucks inside it
    /// green).
    #[pyo3(signature = (world = 0, size = 800, footprints = false, band = false))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        world: usize,
        size: u32,
        footprints: bool,
        band: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let world = self.world_index(world)?;
        if !(16..=4096).contains(&size) {
            return Err(value_error(format!(
                "render_size = {size}: must be 16 to 4096 pixels"
            )));
        }
        let image = sim::render::draw(
            self.batch.worlds()[world].sim(),
            RenderOptions {
                size,
                footprints,
                band,
            },
        );
        let (w, h) = (image.width() as usize, image.height() as usize);
        Ok(PyArray1::from_vec(py, image.into_raw())
            .reshape([h, w, 3])?
            .into_any())
    }

    /// World `world`'s global state, for centralised critics: per robot its
    /// position over the arena's size (x, y in [0, 1]), its heading's
    /// cosine and sine and the field value under it; then per puck its
    /// position over the arena's size and the field value under it
    /// (float32, [`PyBatch::state_size`] values).
    #[pyo3(signature = (world = 0))]
    fn state<'py>(&self, py: Python<'py>, world: usize) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let sim = self.batch.worlds()[self.world_index(world)?].sim();
        let w = sim.world();
        let (arena, layout) = (w.config().arena(), w.config().field_layout());
        let at = |p: sim::base::vec2::Vec2| {
            [
                (p.x / arena.x) as f32,
                (p.y / arena.y) as f32,
                sim.field().evaluate(p, &layout),
            ]
        };
        let mut out = Vec::with_capacity(self.state_size());
        for (body, robot) in w.bodies().iter().zip(w.robots()) {
            let [x, y, field] = at(body.pos);
            out.extend([
                x,
                y,
                robot.direction.x as f32,
                robot.direction.y as f32,
                field,
            ]);
        }
        for puck in w.pucks() {
            out.extend(at(puck.pos));
        }
        Ok(PyArray1::from_vec(py, out))
    }

    /// The sensor model and arena, as a policy blob records what it was
    /// trained for.
    #[getter]
    fn trained_for(&self) -> (String, String) {
        let t = &self.batch.settings().trained_for;
        (t.sensors.as_str().to_string(), t.arena.as_str().to_string())
    }

    /// Values in [`PyBatch::state`]: 5 per robot, 3 per puck.
    #[getter]
    fn state_size(&self) -> usize {
        let w = self.batch.worlds()[0].sim().world();
        5 * w.robots().len() + 3 * w.pucks().len()
    }

    /// World `world`'s bodies (robots first, then pucks): an array of
    /// (x, y) positions and one of headings of the robots, radians.
    #[pyo3(signature = (world = 0))]
    fn positions<'py>(&self, py: Python<'py>, world: usize) -> PyResult<Bound<'py, PyAny>> {
        let w = self.batch.worlds()[self.world_index(world)?].sim().world();
        let xy: Vec<f64> = w.bodies().iter().flat_map(|b| [b.pos.x, b.pos.y]).collect();
        let headings: Vec<f64> = w
            .robots()
            .iter()
            .map(|r| r.direction.y.atan2(r.direction.x))
            .collect();
        let n = w.bodies().len();
        Ok((
            PyArray1::from_vec(py, xy).reshape([n, 2])?,
            PyArray1::from_vec(py, headings),
        )
            .into_pyobject(py)?
            .into_any())
    }
}

/// Encodes a greedy table (`table`: one action per state) or each state's
/// best actions (`sets`: bit masks) as policy blob bytes, with the sensor
/// model and arena trained for if given.
#[pyfunction]
#[pyo3(signature = (*, table = None, sets = None, hasher, actions, forward_speed, field, name, trainer_steps, seed, trained_for = None))]
#[allow(
    clippy::too_many_arguments,
    reason = "each argument is a Python keyword argument of the function"
)]
fn encode_policy<'py>(
    py: Python<'py>,
    table: Option<Vec<i64>>,
    sets: Option<Vec<i64>>,
    hasher: &str,
    actions: Vec<f32>,
    forward_speed: f32,
    field: &str,
    name: &str,
    trainer_steps: u64,
    seed: u64,
    trained_for: Option<(String, String)>,
) -> PyResult<Bound<'py, PyBytes>> {
    let header = PolicyHeader {
        hasher,
        actions: &actions,
        forward_speed,
        field,
        name,
        trainer_steps,
        seed,
        trained_for: trained_for
            .as_ref()
            .map(|(sensors, arena)| (sensors.as_str(), arena.as_str())),
    };
    let choices = match (&table, &sets) {
        (Some(table), None) => policy_codec::Choices::Table(table),
        (None, Some(sets)) => policy_codec::Choices::Sets(sets),
        _ => return Err(value_error("give either table or sets")),
    };
    let bytes = policy_codec::encode(choices, &header).map_err(value_error)?;
    Ok(PyBytes::new(py, &bytes))
}

/// Decodes policy blob bytes read from `path` (named in errors) into a
/// dict: hasher, actions, forward_speed, table, sets, field, name,
/// trainer_steps, seed, trained_for ((sensors, arena) or None), version.
#[pyfunction]
fn decode_policy<'py>(py: Python<'py>, data: &[u8], path: &str) -> PyResult<Bound<'py, PyDict>> {
    let blob =
        sim::control::policy_file::decode(std::path::Path::new(path), data).map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("hasher", blob.hasher().name())?;
    d.set_item("actions", blob.actions().angular_speeds().to_vec())?;
    d.set_item("forward_speed", blob.actions().forward_speed())?;
    d.set_item(
        "table",
        PyArray1::from_vec(py, policy_codec::table_of(&blob)),
    )?;
    let p = blob.provenance();
    d.set_item("field", p.field.as_str())?;
    d.set_item("name", p.name.as_str())?;
    d.set_item("trainer_steps", p.trainer_steps)?;
    d.set_item("seed", p.seed)?;
    d.set_item("sets", PyArray1::from_vec(py, policy_codec::sets_of(&blob)))?;
    d.set_item(
        "trained_for",
        blob.trained_for()
            .map(|t| (t.sensors.as_str().to_string(), t.arena.as_str().to_string())),
    )?;
    d.set_item("version", blob.version())?;
    Ok(d)
}

/// The world's reward `reward` gives a step whose signal (Eval) goes from
/// `before` to `after`, `formed` when the step forms the shape; `gamma` is
/// the discount of `success-shaped`'s shaping. The very function the
/// environments and `host train` use.
#[pyfunction]
#[pyo3(signature = (reward, before, after, formed = false, gamma = settings::DEFAULT_GAMMA))]
fn reward_value(reward: &str, before: f64, after: f64, formed: bool, gamma: f64) -> PyResult<f64> {
    let reward: Reward = reward
        .parse()
        .map_err(|e: String| value_error(format!("reward = {reward:?}: {e}")))?;
    Ok(reward.reward(
        sim::episodes::reward::Transition {
            before,
            after,
            formed,
        },
        gamma,
    ))
}

/// The native module.
#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBatch>()?;
    m.add_function(wrap_pyfunction!(encode_policy, m)?)?;
    m.add_function(wrap_pyfunction!(decode_policy, m)?)?;
    m.add_function(wrap_pyfunction!(reward_value, m)?)?;
    m.add(
        "HASHERS",
        StateHasher::ALL
            .iter()
            .map(|h| h.name())
            .collect::<Vec<_>>(),
    )?;
    m.add(
        "REWARDS",
        Reward::ALL.iter().map(|r| r.name()).collect::<Vec<_>>(),
    )?;
    m.add("SENSORS", SensorChoice::NAMES)?;
    m.add("SEED_RANGE", settings::SEED_RANGE)?;
    m.add("WORLD_SETTINGS", WorldChoices::names().to_vec())?;
    m.add("DEFAULT_ANGULAR", ActionTable::DEFAULT_ANGULAR.to_vec())?;
    m.add("DEFAULT_FORWARD_SPEED", ActionTable::DEFAULT_FORWARD_SPEED)?;
    m.add(
        "READING_FIELDS",
        [
            "left",
            "mid",
            "right",
            "puck_left",
            "puck_right",
            "obstacle_left",
            "obstacle_right",
        ],
    )?;
    Ok(())
}
