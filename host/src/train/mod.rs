//! Training: a run's settings ([`config`]), the learning loop over any
//! sensor model ([`trainer`]), its checkpoint file ([`checkpoint`]; the
//! layouts of the earlier formats 1 to 7: [`format1`], [`format2`],
//! [`format3`], [`format4`], [`format6`], [`format7`]) and the `host train` command
//! ([`command`]), shown live with `--view` ([`watch`]).

pub mod checkpoint;
pub mod command;
pub mod config;
pub mod distil;
pub mod format1;
pub mod format2;
pub mod format3;
pub mod format4;
pub mod format6;
pub mod format7;
pub mod selection;
pub mod trainer;
pub mod watch;

pub use command::{train, TrainReport, TrainRequest};
pub use config::{OutputConfig, TrainConfig, TrainFlags};
pub use trainer::{Trainer, TrainingState};
