//! `host experiment`: the thesis' experiments from TOML files ([`spec`]),
//! planned into seeded trials ([`plan`]), run in parallel and resumable
//! ([`runner`], [`trial`]) or one at a time on the live view ([`watch`]), reusing other runs' identical trials ([`reuse`]), in shards over machines ([`shard`], [`merge`]),
//! and reported ([`metric`], [`figures`], [`outputs`], [`pictures`]); campaigns of
//! searches, training runs and evaluations ([`campaign`]); the
//! published trials ([`published`]) render `docs/reproduction.md`
//! ([`report`], [`template`], with the learners side by side: [`side_by_side`]).

pub mod campaign;
pub mod figures;
pub mod merge;
pub mod metric;
pub mod outputs;
pub mod pictures;
pub mod plan;
pub mod published;
pub mod report;
pub mod reuse;
pub mod runner;
pub mod shard;
pub mod side_by_side;
pub mod spec;
pub mod template;
pub mod trial;
pub mod watch;

pub use runner::{run, RunOptions, RunReport};
pub use spec::ExperimentSpec;
