//! Direct policy search over the exported table (`host search`, issue 31):
//! a cross-entropy method over each state's action ([`cem`]), candidates
//! scored by the formations they make driving worlds of a run's settings
//! ([`fitness`]), and the command that runs it ([`command`]) with its
//! settings ([`config`]).

pub mod cem;
pub mod command;
pub mod config;
pub mod fitness;

pub use command::{search, SearchReport, SearchRequest};
pub use config::{SearchConfig, Start};
