//! Tabular Q-learning with one policy shared by all robots: the table
//! ([`qtable`]), the learning controller ([`learner`]), rewarded by
//! `sim::episodes::reward`, its n-step returns' waiting steps
//! ([`returns`]), a learned table frozen ([`frozen`]), and a greedy table
//! carried into a finer state ([`lift`]).

pub mod frozen;
pub mod learner;
pub mod lift;
pub mod qtable;
pub mod returns;

pub use frozen::FrozenLearner;
pub use learner::{LearnConfig, QLearner, StateHasherName, Updates};
pub use qtable::{QParams, QTable, TableSummary};
pub use returns::{PendingSteps, MAX_N_STEP};
