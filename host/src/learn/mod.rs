//! Tabular Q-learning with one policy shared by all robots: the table
//! ([`qtable`]), the reward ([`reward`]) and the learning controller
//! ([`learner`]).

pub mod learner;
pub mod qtable;
pub mod reward;

pub use learner::{LearnConfig, QLearner, StateHasherName};
pub use qtable::{QParams, QTable};
pub use reward::Reward;
