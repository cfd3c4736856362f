//! The scenario flags `run` and `render` share: the world's settings
//! ([`WorldChoices`], declared there once) and what only a scenario has.

use clap::parser::ValueSource;
use clap::{Arg, ArgMatches, Args, FromArgMatches};
use host::train::TrainConfig;
use sim::config::BroadPhase;
use sim::scenario::choices::{ScenarioChoices, WorldChoices};
use sim::scenario::trained_for;
use sim::scenario::{ControllerChoice, Scenario};

/// The scenario flags `run` and `render` share: `--controller` and
/// `--naive`, and the world's settings (`--field`, `--sensors`,
/// `--arena`, `--robots`, `--pucks`, `--seed`, `--noise`, `--walls`).
#[derive(Clone, Debug)]
pub struct ScenarioArgs {
    own: ScenarioOwnArgs,
    world: WorldChoices,
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
        WorldChoices::augment_args(ScenarioOwnArgs::augment_args(command))
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        ScenarioArgs::augment_args(command)
    }
}

impl FromArgMatches for ScenarioArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<ScenarioArgs, clap::Error> {
        let mut world = WorldChoices::default();
        world.update_from_arg_matches(matches)?;
        Ok(ScenarioArgs {
            own: ScenarioOwnArgs::from_arg_matches(matches)?,
            world,
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
        TrainConfig {
            world: self.world.clone(),
            ..TrainConfig::default()
        }
    }
}

/// Writes the world flags given on the command line of `m` (a command that
/// takes only some of them) into `world`, each by its name.
pub(crate) fn apply_world_flags(m: &ArgMatches, world: &mut WorldChoices) -> anyhow::Result<()> {
    for name in WorldChoices::names() {
        if m.ids().any(|id| id == name) && m.value_source(name) == Some(ValueSource::CommandLine) {
            if let Some(text) = m.get_raw(name).and_then(|mut v| v.next()) {
                world.set(name, &text.to_string_lossy())?;
            }
        }
    }
    Ok(())
}
