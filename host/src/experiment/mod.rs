//! `host experiment`: the thesis' experiments from TOML files ([`spec`]),
//! planned into seeded trials ([`plan`]), run in parallel and resumable
//! ([`runner`], [`trial`]), and reported ([`metric`], [`figures`], [`outputs`],
//! [`pictures`]).

pub mod figures;
pub mod metric;
pub mod outputs;
pub mod pictures;
pub mod plan;
pub mod runner;
pub mod spec;
pub mod trial;

pub use runner::{run, RunOptions, RunReport};
pub use spec::ExperimentSpec;
