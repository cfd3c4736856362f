//! Campaigns: experiments made of stages (searches, training runs,
//! evaluations, publications), each stage able to continue from an earlier
//! stage's table, so that a shipped table's whole lineage is one file. The
//! file's format is [`file`]'s; [`run`] runs a campaign and [`publish`]
//! renders its published results into the docs.

pub mod file;
pub mod publish;
pub mod run;

pub use file::Campaign;
pub use run::{run, CampaignReport};
