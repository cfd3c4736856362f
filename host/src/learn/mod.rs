//! Tabular Q-learning with one policy shared by all robots: the table
//! ([`qtable`]) and the learning controller ([`learner`]), rewarded by
//! `sim::episodes::reward`.

pub mod learner;
pub mod qtable;

pub use learner::{LearnConfig, LearnerRules, QLearner, StateHasherName, Updates};
pub use qtable::{QParams, QTable, TableSummary};
