//! Experiment reports: statistics and charts.

pub mod chart;
pub mod stats;
