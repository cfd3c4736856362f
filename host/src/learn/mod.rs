//! Tabular Q-learning with one policy shared by all robots.

pub mod qtable;

pub use qtable::{QParams, QTable};
