//! The host side over the simulator (`sim`): the Q-learning trainer, the
//! thesis' experiments and their reports, the tools for real robots and
//! for the field on their TV, and the tools around policy blobs.
#![warn(missing_docs)]

pub mod atomic;
pub mod bench;
pub mod display;
pub mod experiment;
pub mod flashed;
pub mod flat_field;
pub mod inspect;
pub mod learn;
pub mod observe;
pub mod panel_file;
pub mod policy_file;
pub mod render;
pub mod report;
pub mod robot;
pub mod run_summary;
pub mod search;
pub mod shape;
pub mod train;
