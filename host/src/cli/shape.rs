//! `host shape`'s options: the image, the budget, and the world's
//! settings, a training config's own flags (`--sensors`, `--arena`,
//! `--noise`, `--seed`, `--pucks`, `--out`, `--name`), defaulting to the
//! robot's on the TV at the default noise.

use super::learn::ROBOT_WORLD_HELPS;
use super::scenario::{apply_world_flags, train_config_args};
use clap::{ArgMatches, Args, FromArgMatches};
use host::search::config::default_world;
use host::shape::ShapeRequest;
use host::train::config::field_label;
use sim::fields::source::FieldSource;
use std::path::PathBuf;

/// `host shape`'s options.
#[derive(Clone, Debug)]
pub struct ShapeArgs {
    own: ShapeOwnArgs,
    world: ArgMatches,
}

/// What only `host shape` takes.
#[derive(Clone, Debug, Args)]
struct ShapeOwnArgs {
    /// The shape: a PNG or JPEG image drawn light on dark (the shape the
    /// brightest part), or a built-in field (annulus, letter:T, thesis:T, ...).
    #[arg(value_name = "IMAGE")]
    image: FieldSource,
    /// Minutes the run may take on this machine, turned at the start into
    /// the search's generations from a measured step rate.
    #[arg(long, default_value_t = 20.0)]
    budget_minutes: f64,
    /// The search's generations instead of the budget's.
    #[arg(long)]
    generations: Option<u64>,
    /// Invert the image first: for a shape drawn dark on light.
    #[arg(long)]
    invert: bool,
    /// The fraction of every step count (the search's worlds, the
    /// distillation, the report's worlds): 0.01 for a quick look.
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
}

/// The training config's flags `host shape` takes.
const WORLD_FLAGS: [&str; 7] = ["sensors", "arena", "noise", "seed", "pucks", "out", "name"];

impl Args for ShapeArgs {
    fn augment_args(command: clap::Command) -> clap::Command {
        let mut command = ShapeOwnArgs::augment_args(command).args(train_config_args(&WORLD_FLAGS));
        for (id, help) in ROBOT_WORLD_HELPS {
            command = command.mut_arg(id, |a| a.help(help));
        }
        command
            .mut_arg("out", |a| {
                a.required(true)
                    .help("Directory of the outputs: <name>.policy, .report.json, .report.md, .png, .search.json and the state, .shape.json")
            })
            .mut_arg("name", |a| {
                a.help("Name of the outputs and of the policy (at most 32 bytes, no path separators) [default: the image's file name without its extension]")
            })
            .mut_arg("pucks", |a| {
                a.help("Number of pucks [default: the shape's by the puck rule, docs/policy-search.md]")
            })
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        ShapeArgs::augment_args(command)
    }
}

impl FromArgMatches for ShapeArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<ShapeArgs, clap::Error> {
        Ok(ShapeArgs {
            own: ShapeOwnArgs::from_arg_matches(matches)?,
            world: matches.clone(),
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = ShapeArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

impl ShapeArgs {
    /// The request these flags make; errors name the flag.
    pub fn request(self) -> anyhow::Result<ShapeRequest> {
        let own = self.own;
        sim::base::ranges::SHAPE_BUDGET.check_as("--budget-minutes", own.budget_minutes)?;
        sim::base::ranges::SCALE.check_as("--scale", own.scale)?;
        if let Some(generations) = own.generations {
            sim::base::ranges::GENERATIONS.check_count("--generations", generations)?;
        }
        let mut world = default_world();
        world.world.field = own.image.clone();
        apply_world_flags(&self.world, &mut world.world)?;
        if let Some(dir) = self.world.get_one::<PathBuf>("out") {
            world.output.dir = dir.clone();
        }
        world.output.name = Some(match self.world.get_one::<String>("name") {
            Some(name) => name.clone(),
            None => field_label(&own.image).replace(':', "-"),
        });
        world.validate()?;
        Ok(ShapeRequest {
            world,
            invert: own.invert,
            budget_minutes: own.budget_minutes,
            generations: own.generations,
            scale: own.scale,
        })
    }
}
