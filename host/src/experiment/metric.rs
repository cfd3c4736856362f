//! The figures an experiment table can report, by name (their values over
//! an arm's trials are [`super::figures`]').

use serde::{Deserialize, Serialize};

/// A reported figure of an arm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Formations per trial.
    Formations,
    /// Stuck episodes per trial.
    Stuck,
    /// Steps of a trial over its mean formations (the thesis' Table 5
    /// "Steps/Form": 5,000,000 / 113.7 = 43,975).
    StepsPerFormation,
    /// Step of the first formation, over the trials that formed one.
    FirstFormation,
    /// Robot-robot collisions per 1000 steps.
    #[serde(rename = "collisions_per_1000")]
    CollisionsPer1000,
    /// Mean formations over those of the table's `ratio_to` arm.
    FormationsRatio,
    /// States of the Q-table updated at least once, at the end.
    StatesVisited,
    /// Simulation speed of a trial.
    StepsPerSecond,
}

impl Metric {
    /// Column header.
    pub fn label(self) -> &'static str {
        match self {
            Metric::Formations => "Formations",
            Metric::Stuck => "Stuck",
            Metric::StepsPerFormation => "Steps/Form",
            Metric::FirstFormation => "First formation (step)",
            Metric::CollisionsPer1000 => "Collisions/1000 steps",
            Metric::FormationsRatio => "Formations ratio",
            Metric::StatesVisited => "States visited",
            Metric::StepsPerSecond => "Steps/s",
        }
    }
}
