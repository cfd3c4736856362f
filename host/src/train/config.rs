//! What a training run is: [`TrainConfig`], read from a TOML file and/or
//! the `host train` flags ([`TrainFlags`]), flags winning. Each setting is
//! declared once, as a field of [`TrainConfig`]: its doc comment is both
//! the file key's documentation and the flag's help.

use super::selection::SelectConfig;
use crate::learn::LearnConfig;
use anyhow::{bail, Context, Result};
use clap::parser::ValueSource;
use clap::{ArgAction, ArgMatches, Args, FromArgMatches};
use serde::de::{self, DeserializeOwned, Deserializer, IgnoredAny, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use shared::blob::name_prefix;
use sim::base::ranges;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::{ScenarioChoices, WorldChoices};
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::{orbital_innies, role_innies};
use sim::{
    config::disc_sensors::ObstacleTargets, config::SuccessSignal, config::Walls,
    fields::source::FieldSource, scenario::ControllerChoice, scenario::PreparedScenario,
    scenario::Scenario,
};
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

/// Steps `host train` runs by default: on the annulus with 8 robots and
/// 250 pucks, about 13 s at 150,000 steps/s, forming dozens of shapes
/// (see docs/training.md for the measurement).
pub const DEFAULT_STEPS: u64 = 2_000_000;

/// Steps over which a decaying exploration probability stays constant
/// ([`TrainConfig::exploration_at`]).
pub const DECAY_PERIOD: u64 = 1000;

/// Steps between checkpoints by default.
pub const DEFAULT_CHECKPOINT_EVERY: u64 = 1_000_000;

/// A training run: world, learner and outputs. Every key of a config file
/// is optional; missing ones keep the defaults (the thesis' Table 1 run).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Args)]
#[serde(default, deny_unknown_fields)]
pub struct TrainConfig {
    /// The world: its settings are the config's own keys and flags
    /// (`field`, `sensors`, `arena`, `robots`, `pucks`, `seed`, `noise`,
    /// `walls`), declared once in [`WorldChoices`].
    #[serde(flatten)]
    #[command(flatten)]
    pub world: WorldChoices,
    /// Steps to run [default: 2,000,000; when resuming, the checkpoint's
    /// run length].
    #[arg(long, required = false)]
    pub steps: u64,
    /// The learner.
    #[command(flatten)]
    pub learn: LearnConfig,
    /// Where results go.
    #[command(flatten)]
    pub output: OutputConfig,
    /// How often formations are checked, and on which world.
    #[command(flatten)]
    pub formation_check: FormationCheck,
    /// What a check tests: `eval` (default), `eval-prime` (Eval' as
    /// printed) or `eval-prime-spread`.
    #[arg(skip)]
    pub success: SuccessSignal,
    /// Innies among the robots of an orbital-construction run or of a
    /// learning run with a role hasher (original-role, bits9-role)
    /// [default: for orbital construction half the robots on the annulus,
    /// none on letters and images; for a role hasher the flashed swarm's on
    /// every field, the robots of odd id]. Other learning runs have none.
    #[arg(long)]
    pub innies: Option<usize>,
    /// The disc sensor model's obstacle discs; `None` for the model's own
    /// (`disc`: radius r/4 seeing any body).
    #[arg(skip)]
    pub obstacle_discs: Option<ObstacleDiscs>,
    /// Policy selection: the run's policy is the best greedy policy of
    /// periodic evaluations instead of the last one
    /// ([`super::selection`]); `None` for the last.
    #[arg(skip)]
    pub select: Option<SelectConfig>,
    /// Start from orbital construction: distil this many of its steps, on a
    /// world of the run's settings, into the table the run starts from
    /// (docs/training.md) [default: none, the initial Q-values].
    #[arg(long)]
    pub distil_oc: Option<u64>,
    /// Decaying exploration: the exploration probability falls linearly
    /// from --epsilon at step 0 to 0 at this step (in steps of
    /// 1,000) and stays 0 [default: none, --epsilon throughout].
    #[arg(long)]
    pub epsilon_decay: Option<u64>,
    /// n-step returns: each update's target sums the robot's next N
    /// rewards, discounted, before bootstrapping from the table (1 to 64)
    /// [default: 1, the thesis' one-step Q-learning].
    #[arg(long)]
    pub n_step: Option<u32>,
}

/// When an episode's formation is checked (`[formation_check]`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Args)]
#[serde(default, deny_unknown_fields)]
pub struct FormationCheck {
    /// Steps between formation checks [default: 100].
    #[arg(
        long = "check-every",
        id = "check_every",
        value_name = "STEPS",
        required = false
    )]
    pub every: u64,
    /// Test the Eval measured at the previous check (at the episode's
    /// start for the first) instead of the current one, as the thesis
    /// author's loop did with `every = 1000` (reference model, "What the
    /// thesis author's own runs did").
    #[arg(long = "stale-check", id = "stale_check", value_name = "BOOL", action = ArgAction::Set, required = false)]
    pub stale: bool,
}

impl Default for FormationCheck {
    /// Every 100 steps, on the current world.
    fn default() -> FormationCheck {
        FormationCheck {
            every: 100,
            stale: false,
        }
    }
}

/// The obstacle discs of the disc sensor model (`obstacle_discs = { radius
/// = 2.0, sees = "any-body" }`), at (+-45 deg, r) as in the original code.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleDiscs {
    /// Disc radius, robot radii (the original code 0.25, the thesis' text 2).
    pub radius: f64,
    /// `robots` (the thesis' text) or `any-body` (the original code).
    pub sees: ObstacleTargets,
}

/// Where a training run writes, and how often it checkpoints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Args)]
#[serde(default, deny_unknown_fields)]
pub struct OutputConfig {
    /// Directory of `<name>.policy` and `<name>.ckpt` [default: out].
    #[arg(long = "out", id = "out", value_name = "DIR", required = false)]
    pub dir: PathBuf,
    /// Name of the output files and of the policy (at most 32 bytes, no
    /// path separators) [default: <field>-<hasher>, e.g. annulus-original].
    #[arg(long)]
    pub name: Option<String>,
    /// Steps between checkpoints, 0 for only at the end [default: 1,000,000].
    #[arg(long, required = false)]
    pub checkpoint_every: u64,
}

impl Default for OutputConfig {
    /// `out/`, the derived name, a checkpoint every 1,000,000 steps.
    fn default() -> OutputConfig {
        OutputConfig {
            dir: PathBuf::from("out"),
            name: None,
            checkpoint_every: DEFAULT_CHECKPOINT_EVERY,
        }
    }
}

impl Default for TrainConfig {
    /// Annulus, disc sensors in the thesis' square (8 robots, 250 pucks),
    /// no noise, [`DEFAULT_STEPS`], seed 1, the thesis' learner.
    fn default() -> TrainConfig {
        TrainConfig {
            world: WorldChoices::default(),
            steps: DEFAULT_STEPS,
            learn: LearnConfig::default(),
            output: OutputConfig::default(),
            formation_check: FormationCheck::default(),
            success: SuccessSignal::Eval,
            innies: None,
            obstacle_discs: None,
            select: None,
            distil_oc: None,
            epsilon_decay: None,
            n_step: None,
        }
    }
}

/// Longest run name: the policy blob's name field.
const MAX_NAME_LEN: usize = shared::blob::MAX_NAME_LEN;

impl TrainConfig {
    /// Reads a TOML file; syntax errors and unknown keys name the file, the
    /// line and the column.
    pub fn from_file(path: &Path) -> Result<TrainConfig> {
        let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
            .with_context(|| format!("cannot read config file {}", path.display()))?;
        TrainConfig::from_toml(&text).with_context(|| {
            format!(
                "config file {} is not a valid training config",
                path.display()
            )
        })
    }

    /// The config of TOML text: an error names the key, with its line.
    pub fn from_toml(text: &str) -> Result<TrainConfig, toml::de::Error> {
        read_checked(&text)
    }

    /// The config of a TOML table (an experiment's settings, merged from
    /// its files): an error names the key.
    pub fn from_toml_table(table: toml::Table) -> Result<TrainConfig, toml::de::Error> {
        read_checked(&toml::Value::Table(table))
    }

    /// How the run's border keeps the bodies in: `walls`, else the
    /// arena's own (the thesis' square clamps, a screen has its bezel).
    pub fn walls_in_effect(&self) -> Walls {
        self.world.walls.unwrap_or(match self.arena_choice() {
            ArenaChoice::Thesis => Walls::Clamp,
            ArenaChoice::Named(_) | ArenaChoice::File(_) => Walls::Segments,
        })
    }

    /// The arena the run uses.
    pub fn arena_choice(&self) -> ArenaChoice {
        self.world.arena_choice()
    }

    /// The sensor model and arena the run trains for, as its policy blob
    /// records them.
    pub fn trained_for(&self) -> shared::TrainedFor {
        sim::scenario::trained_for::trained_for(&self.world.sensors, &self.arena_choice())
    }

    /// The run as a scenario (arena and sensor files read and checked),
    /// without the settings only training has.
    pub fn scenario(&self) -> Result<Scenario> {
        Ok(self.choices().scenario()?)
    }

    /// The world's settings by name, the controller random.
    pub fn choices(&self) -> ScenarioChoices {
        ScenarioChoices {
            controller: ControllerChoice::Random,
            world: self.world.clone(),
        }
    }

    /// Loads the field and derives the simulation settings: the field's
    /// defaults ([`sim::scenario::field_config`]) in the run's arena, with
    /// its counts, noise, stuck limit, formation checks and obstacle discs;
    /// every robot an outie. Errors name the offending setting.
    pub fn prepare(&self) -> Result<PreparedScenario> {
        self.validate()?;
        // the scenario's errors say what kind of setting is wrong
        let mut prepared = self.scenario()?.prepare()?;
        let c = prepared.config_mut();
        c.episode.check_interval = self.formation_check.every;
        c.episode.stale_eval = self.formation_check.stale;
        c.episode.success_signal = self.success;
        if let Some(discs) = self.obstacle_discs {
            c.sensors.obstacle.radius = discs.radius;
            c.sensors.obstacle_targets = discs.sees;
        }
        if let Some(n) = self.innies.filter(|&n| n > c.world.robots) {
            bail!("innies = {n}: cannot exceed robots = {}", c.world.robots);
        }
        if self.learn.hasher.0.has_role_bit() {
            // a role-aware policy learns both roles, in the flashed swarm's mix
            c.world.innies = self.role_innies(c.world.robots);
        }
        c.validate().context("invalid simulation settings")?;
        Ok(prepared)
    }

    /// The innies of an orbital-construction run of these settings with
    /// `robots` robots.
    pub fn oc_innies(&self, robots: usize) -> usize {
        self.innies
            .unwrap_or_else(|| orbital_innies(&self.world.field, robots))
    }

    /// The innies of a run of these settings with the role hasher and
    /// `robots` robots: the flashed swarm's ([`role_innies`]) on every
    /// field unless set.
    pub fn role_innies(&self, robots: usize) -> usize {
        self.innies.unwrap_or_else(|| role_innies(robots))
    }

    /// The exploration probability at training step `step`: `--epsilon`,
    /// or with [`TrainConfig::epsilon_decay`] its linear decay, evaluated
    /// at the last multiple of [`DECAY_PERIOD`] (so that a run holds it
    /// constant over whole periods, and a resumed run gets what the
    /// straight run had).
    pub fn exploration_at(&self, step: u64) -> f64 {
        match self.epsilon_decay {
            Some(end) => {
                let at = step - step % DECAY_PERIOD;
                self.learn.epsilon * (1.0 - at as f64 / end as f64).max(0.0)
            }
            None => self.learn.epsilon,
        }
    }

    /// Rewards per update target: [`TrainConfig::n_step`], 1 when unset.
    pub fn rewards_per_update(&self) -> usize {
        self.n_step.unwrap_or(1) as usize
    }

    /// The run's name: [`OutputConfig::name`] or `<field>-<hasher>`.
    pub fn name(&self) -> String {
        match &self.output.name {
            Some(name) => name.clone(),
            None => name_prefix(&format!(
                "{}-{}",
                field_label(&self.world.field).replace(':', "-"),
                self.learn.hasher.0.name()
            ))
            .to_string(),
        }
    }

    /// Checks every setting before a run against its plausible range
    /// ([`sim::base::ranges`]) and the rules between settings; errors name
    /// the setting.
    pub fn validate(&self) -> Result<()> {
        ranges::STEPS.check_count("steps", self.steps)?;
        self.world.check_ranges()?;
        ranges::CHECK_INTERVAL.check_count("formation_check.every", self.formation_check.every)?;
        if let Some(discs) = self.obstacle_discs {
            ranges::DISC_RADIUS.check_as("obstacle_discs.radius", discs.radius)?;
        }
        self.learn.validate()?;
        ranges::INITIAL_Q.check(self.learn.initial_q)?;
        for a in &self.learn.actions {
            ranges::ANGULAR_SPEED.check(f64::from(*a))?;
        }
        if let Some(select) = self.select {
            ranges::STEPS.check_count("select.every", select.every)?;
            ranges::STEPS.check_count("select.steps", select.steps)?;
        }
        if let Some(steps) = self.distil_oc {
            ranges::STEPS.check_count("distil_oc", steps)?;
        }
        if let Some(steps) = self.epsilon_decay {
            ranges::STEPS.check_count("epsilon_decay", steps)?;
        }
        if let Some(n) = self.n_step {
            ranges::N_STEP.check_count("n_step", u64::from(n))?;
        }
        ranges::CHECKPOINT_EVERY.check_count("checkpoint_every", self.output.checkpoint_every)?;
        if self.obstacle_discs.is_some() && self.world.sensors != SensorChoice::Disc {
            bail!(
                "obstacle_discs: only the disc sensor model takes them (sensors = {:?})",
                self.world.sensors.to_string()
            );
        }
        let name = self.name();
        if name.is_empty()
            || name.len() > MAX_NAME_LEN
            || name.contains(['/', '\\'])
            || name.starts_with('.')
        {
            bail!(
                "name {name:?}: must be 1 to {MAX_NAME_LEN} bytes, without path separators, not starting with a dot"
            );
        }
        Ok(())
    }
}

/// TOML a config is read from.
trait TomlSource {
    /// The source as a `T`.
    fn read<T: DeserializeOwned>(&self) -> Result<T, toml::de::Error>;
}

impl TomlSource for &str {
    fn read<T: DeserializeOwned>(&self) -> Result<T, toml::de::Error> {
        toml::from_str(self)
    }
}

impl TomlSource for toml::Value {
    fn read<T: DeserializeOwned>(&self) -> Result<T, toml::de::Error> {
        self.clone().try_into()
    }
}

/// A config read so that its errors name the key and keep its place: the
/// world's settings are flattened into the config, and serde reads
/// flattened keys through a buffer that forgets both, so the keys, then
/// the world's settings on their own, are read first.
fn read_checked(source: &impl TomlSource) -> Result<TrainConfig, toml::de::Error> {
    source.read::<SettingKeys>()?;
    source.read::<WorldChoices>()?;
    source.read::<TrainConfig>()
}

/// The top-level keys of a config, each a setting's ([`TrainConfig`]'s
/// serde form names them); reading one of no setting fails, naming it.
struct SettingKeys;

impl<'de> Deserialize<'de> for SettingKeys {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<SettingKeys, D::Error> {
        /// A key of a setting.
        struct Key;
        impl<'de> Deserialize<'de> for Key {
            fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Key, D::Error> {
                static NAMES: LazyLock<Vec<String>> =
                    LazyLock::new(|| match serde_json::to_value(TrainConfig::default()) {
                        Ok(serde_json::Value::Object(map)) => map.keys().cloned().collect(),
                        _ => Vec::new(),
                    });
                let key = String::deserialize(d)?;
                if NAMES.contains(&key) {
                    Ok(Key)
                } else {
                    Err(de::Error::custom(format!(
                        "unknown field `{key}`, expected one of {}",
                        NAMES.join(", ")
                    )))
                }
            }
        }
        struct Keys;
        impl<'de> Visitor<'de> for Keys {
            type Value = SettingKeys;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table of settings")
            }
            fn visit_map<A: MapAccess<'de>>(
                self,
                mut map: A,
            ) -> std::result::Result<SettingKeys, A::Error> {
                while map.next_key::<Key>()?.is_some() {
                    map.next_value::<IgnoredAny>()?;
                }
                Ok(SettingKeys)
            }
        }
        d.deserialize_map(Keys)
    }
}

/// The field as a blob's provenance names it: the source for the annulus
/// and letters, an image's file name; at most 32 bytes.
pub fn field_label(field: &FieldSource) -> String {
    match field {
        FieldSource::Image(path) => name_prefix(
            &path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "image".into()),
        )
        .to_string(),
        other => name_prefix(&other.to_string()).to_string(),
    }
}

/// The `host train` flags of [`TrainConfig`]'s settings, as given: each
/// flag is the config field of the same name (its doc comment is the
/// flag's help), so a setting is declared once, in [`TrainConfig`]. Only
/// the flags given override a config file's values.
#[derive(Clone, Debug, Default)]
pub struct TrainFlags(ArgMatches);

/// Flags that may go with `--resume`: they say how long to run and where
/// to write, not what the run is.
const RESUMABLE: [&str; 4] = ["steps", "out", "name", "checkpoint_every"];

impl TrainFlags {
    /// The flags of a command line (without the program's name), e.g.
    /// `["--robots", "4"]`.
    pub fn parse<I, T>(args: I) -> Result<TrainFlags>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        let command = TrainFlags::augment_args(clap::Command::new("train").no_binary_name(true));
        Ok(TrainFlags(command.try_get_matches_from(args)?))
    }

    /// Writes every given flag into `config`.
    pub fn apply(&self, config: &mut TrainConfig) -> Result<()> {
        config.update_from_arg_matches(&self.0)?;
        if self.given_ids().any(|id| id == "select_every") {
            config.select = Some(SelectConfig::from_arg_matches(&self.0)?);
        }
        Ok(())
    }

    /// `--steps`, if given.
    pub fn steps(&self) -> Option<u64> {
        self.given_ids()
            .any(|id| id == "steps")
            .then(|| self.0.get_one::<u64>("steps").copied())
            .flatten()
    }

    /// The flags given that change what the run is (all but `--steps`,
    /// `--out`, `--name`, `--checkpoint-every`), for refusing them where a
    /// resumed run keeps its settings.
    pub fn given_settings(&self) -> Vec<String> {
        self.given_ids()
            .filter(|id| !RESUMABLE.contains(id))
            .map(|id| format!("--{}", id.replace('_', "-")))
            .collect()
    }

    /// The ids of the settings flags given on the command line (the
    /// matches also hold the rest of the command's arguments and the
    /// groups clap makes of flattened structs).
    fn given_ids(&self) -> impl Iterator<Item = &str> {
        let own = TrainFlags::augment_args(clap::Command::new("train"));
        let own: Vec<String> = own
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .collect();
        self.0.ids().map(|id| id.as_str()).filter(move |id| {
            own.iter().any(|o| o == id) && self.0.value_source(id) == Some(ValueSource::CommandLine)
        })
    }
}

impl FromArgMatches for TrainFlags {
    fn from_arg_matches(matches: &ArgMatches) -> std::result::Result<TrainFlags, clap::Error> {
        Ok(TrainFlags(matches.clone()))
    }

    fn update_from_arg_matches(
        &mut self,
        matches: &ArgMatches,
    ) -> std::result::Result<(), clap::Error> {
        self.0 = matches.clone();
        Ok(())
    }
}

impl Args for TrainFlags {
    fn augment_args(command: clap::Command) -> clap::Command {
        SelectConfig::augment_args(TrainConfig::augment_args(command))
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        SelectConfig::augment_args_for_update(TrainConfig::augment_args_for_update(command))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_names_what_it_changes_and_flags_win() {
        let text = "robots = 4\nfield = \"letter:L\"\n[learn]\nhasher = \"bits7\"\nalpha = 0.5\n[output]\nname = \"x\"\n";
        let mut c = TrainConfig::from_toml(text).unwrap();
        assert_eq!(
            (c.world.robots, c.world.pucks, c.learn.alpha),
            (Some(4), None, 0.5)
        );
        let world = &c.prepare().unwrap().config().clone();
        assert_eq!(
            (world.episode.stuck_limit, world.world.pucks),
            (50_000, 250)
        );
        let flags = TrainFlags::parse(["--alpha", "0.1", "--robots", "2", "--steps", "9"]).unwrap();
        flags.apply(&mut c).unwrap();
        assert_eq!(
            (
                c.world.robots,
                c.learn.alpha,
                c.learn.hasher.0.bits(),
                c.steps
            ),
            (Some(2), 0.1, 7, 9)
        );
        assert_eq!(flags.given_settings(), ["--alpha", "--robots"]);
        assert_eq!(flags.steps(), Some(9));
        c.validate().unwrap();
    }

    #[test]
    fn malformed_files_give_the_line() {
        for (text, says) in [
            ("robots = 4\npucks = = 3\n", ["line 2", "="]),
            ("robots = 4\n\nalpah = 0.3\n", ["line 3", "alpah"]),
            ("[learn]\nhasher = \"bits12\"\n", ["line 2", "bits12"]),
            // a world's setting, flattened into the config, keeps its line too
            ("steps = 9\nrobots = \"four\"\n", ["line 2", "four"]),
            ("steps = 9\nfield = \"letter:Q\"\n", ["line 2", "letter:Q"]),
        ] {
            let e = TrainConfig::from_toml(text).unwrap_err().to_string();
            assert!(says.iter().all(|s| e.contains(s)), "{text}: {e}");
        }
        // a table without lines names the key
        let mut table = toml::Table::new();
        table.insert("robot".into(), toml::Value::Integer(4));
        let e = TrainConfig::from_toml_table(table).unwrap_err().to_string();
        assert!(e.contains("`robot`"), "{e}");
    }

    #[test]
    fn names_derive_from_field_and_hasher_and_are_checked() {
        let mut c = TrainConfig::default();
        assert_eq!(c.name(), "annulus-original");
        c.world.field = FieldSource::Letter(sim::fields::letters::Letter::T);
        assert_eq!(c.name(), "letter-T-original");
        c.output.name = Some("../escape".into());
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("path separators"));
        c.output.name = Some("x".repeat(33));
        assert!(c.validate().is_err());
    }
}
