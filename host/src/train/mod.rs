//! Training: a run's settings ([`config`]), the learning loop over any
//! sensor model ([`trainer`]), its checkpoint file ([`checkpoint`]; the
//! layout of format 1: [`format1`]) and the `host train` command
//! ([`command`]).

pub mod checkpoint;
pub mod format1;
pub mod command;
pub mod config;
pub mod trainer;

pub use command::{train, TrainReport, TrainRequest};
pub use config::{OutputConfig, TrainConfig, TrainOverrides};
pub use trainer::{Trainer, TrainingState};
