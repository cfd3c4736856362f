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
        let m = &self.world;
        if let Some(field) = m.get_one::<FieldSource>("field") {
            config.field = field.clone();
        }
        if let Some(sensors) = m.get_one::<SensorChoice>("sensors") {
            config.sensors = sensors.clone();
        }
        config.arena = m.get_one::<ArenaChoice>("arena").cloned();
        config.robots = m.get_one::<usize>("robots").copied();
        config.pucks = m.get_one::<usize>("pucks").copied();
        if let Some(&seed) = m.get_one::<u64>("seed") {
            config.seed = seed;
        }
        if let Some(&noise) = m.get_one::<f64>("noise") {
            config.noise = noise;
        }
        config.walls = m.get_one::<Walls>("walls").copied();
        config
    }
}
