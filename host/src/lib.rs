//! The host side: simulator, trainer, and the tools around policy blobs.
#![warn(missing_docs)]

pub mod atomic;
pub mod bench;
pub mod controller;
pub mod experiment;
pub mod inspect;
pub mod learn;
pub mod policy_file;
pub mod render;
pub mod report;
pub mod robot;
pub mod scenario;
pub mod sensor_choice;
pub mod sim;
pub mod train;
