//! The generator behind every random choice of a simulation.

/// PCG 128/64: fast, small, and serialisable for bit-exact checkpoints.
pub type SimRng = rand_pcg::Pcg64;
