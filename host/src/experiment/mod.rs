//! `host experiment`: the thesis' experiments from TOML files ([`spec`]),
//! planned into seeded trials ([`plan`]), run in parallel and resumable
//! ([`runner`], [`trial`]), and reported ([`metric`], [`outputs`]).

pub mod metric;
pub mod outputs;
pub mod plan;
pub mod runner;
pub mod spec;
pub mod trial;

pub use runner::{run, RunOptions, RunReport};
pub use spec::ExperimentSpec;

use std::path::PathBuf;

/// The `host experiment` arguments.
#[derive(Clone, Debug, clap::Args)]
pub struct ExperimentArgs {
    /// annulus, transfer, letters, state-bits, obstacle, collisions (the
    /// files of experiments/, built in), or the path of a TOML file.
    pub experiment: String,
    /// Trials per arm.
    #[arg(long, default_value_t = 10)]
    pub trials: usize,
    /// Fraction of the thesis' step counts, for quick runs (e.g. 0.001).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Output directory [default: out/experiments/<name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Experiment seed, from which every trial's seed derives [default: the file's].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads [default: one per core].
    #[arg(long)]
    pub threads: Option<usize>,
}

impl ExperimentArgs {
    /// The run options these arguments give.
    pub fn options(&self) -> RunOptions {
        RunOptions {
            trials: self.trials,
            scale: self.scale,
            out: self.out.clone(),
            seed: self.seed,
            threads: self.threads,
        }
    }
}
