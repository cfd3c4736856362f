//! The scenario flags `run` and `render` share: the world's settings,
//! taken from a training config's own flags, and what only a scenario has.

use clap::{Arg, ArgMatches, Args, FromArgMatches};
use host::train::TrainConfig;
use sim::config::{BroadPhase, Walls};
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::ScenarioChoices;
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::trained_for;
use sim::scenario::{ControllerChoice, Scenario};

/// The scenario flags `run` and `render` share: `--controller` and
/// `--naive`, and the world's settings, which are a training config's own
/// flags ([`TrainConfig`]'s fields, declared there once: `--field`,
/// `--sensors`, `--arena`, `--robots`, `--pucks`, `--seed`, `--noise`).
#[derive(Clone, Debug)]
pub struct ScenarioArgs {
    own: ScenarioOwnArgs,
    world: ArgMatches,
}

/// What a scenario has and a training run does not.
#[derive(Clone, Debug, Args)]
struct ScenarioOwnArgs {
    /// oc, random or policy:FILE.
    #[arg(long, default_value = "oc")]
    controller: ControllerChoice,
    /// All-pairs contact checks instead of the spatial grid (same results).
    #[arg(long)]
    naive: bool,
}

/// The training config's flags a scenario takes.
const WORLD_FLAGS: [&str; 8] = [
    "field", "sensors", "arena", "robots", "pucks", "seed", "noise", "walls",
];

/// The arguments of [`TrainConfig`] with these ids, declared there.
pub(crate) fn train_config_args(ids: &[&str]) -> Vec<Arg> {
    TrainConfig::augment_args(clap::Command::new("train"))
        .get_arguments()
        .filter(|a| ids.contains(&a.get_id().as_str()))
        .cloned()
        .collect()
}

impl Args for ScenarioArgs {
    fn augment_args(command: clap::Command) -> clap::Command {
        ScenarioOwnArgs::augment_args(command).args(train_config_args(&WORLD_FLAGS))
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        ScenarioArgs::augment_args(command)
    }
}

impl FromArgMatches for ScenarioArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<ScenarioArgs, clap::Error> {
        Ok(ScenarioArgs {
            own: ScenarioOwnArgs::from_arg_matches(matches)?,
            world: matches.clone(),
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = ScenarioArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

impl ScenarioArgs {
    /// The scenario, with robot sensor and arena files read and checked.
    pub fn scenario(self) -> anyhow::Result<Scenario> {
        let mut scenario = self.config().scenario()?;
        scenario.controller = self.own.controller;
        if self.own.naive {
            scenario.broad_phase = BroadPhase::Naive;
        }
        Ok(scenario)
    }

    /// With `--controller policy:FILE` of a blob that records what it was
    /// trained for (format version 2): a warning when this scenario's
    /// sensor model or arena is another (a policy may be run elsewhere on
    /// purpose, as the robustness experiments do, so it is not refused).
    pub fn policy_mismatch(&self) -> anyhow::Result<Option<String>> {
        let ControllerChoice::Policy(path) = &self.own.controller else {
            return Ok(None);
        };
        let blob = sim::control::policy_file::read(path)?;
        let here = self.config().trained_for();
        Ok(trained_for::mismatch(blob.trained_for(), &here)
            .map(|why| format!("policy file {}: {why}", path.display())))
    }

    /// The world's settings by name, the controller as given.
    pub fn choices(&self) -> ScenarioChoices {
        ScenarioChoices {
            controller: self.own.controller.clone(),
            ..self.config().choices()
        }
    }

    /// The training config of the world flags given.
    fn config(&self) -> TrainConfig {
        let mut config = TrainConfig::default();
        apply_world_flags(&self.world, &mut config);
        config
    }
}

/// Writes the world flags of [`WORLD_FLAGS`] that `m` holds into
/// `config` (a command may take only some of them).
pub(crate) fn apply_world_flags(m: &ArgMatches, config: &mut TrainConfig) {
    fn given<T: Clone + Send + Sync + 'static>(m: &ArgMatches, id: &str) -> Option<T> {
        m.try_get_one::<T>(id).ok().flatten().cloned()
    }
    if let Some(field) = given::<FieldSource>(m, "field") {
        config.field = field;
    }
    if let Some(sensors) = given::<SensorChoice>(m, "sensors") {
        config.sensors = sensors;
    }
    if let Some(arena) = given::<ArenaChoice>(m, "arena") {
        config.arena = Some(arena);
    }
    if let Some(robots) = given::<usize>(m, "robots") {
        config.robots = Some(robots);
    }
    if let Some(pucks) = given::<usize>(m, "pucks") {
        config.pucks = Some(pucks);
    }
    if let Some(seed) = given::<u64>(m, "seed") {
        config.seed = seed;
    }
    if let Some(noise) = given::<f64>(m, "noise") {
        config.noise = noise;
    }
    if let Some(walls) = given::<Walls>(m, "walls") {
        config.walls = Some(walls);
    }
}
