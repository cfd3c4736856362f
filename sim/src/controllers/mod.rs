//! The controllers that need nothing but the simulator: orbital
//! construction (the thesis' Algorithm 2), a greedy policy table, and
//! uniformly random turns.

pub mod greedy;
pub mod orbital;
pub mod random;

pub use greedy::GreedyPolicy;
pub use orbital::{OrbitalConfig, OrbitalConstruction};
pub use random::RandomTurns;
