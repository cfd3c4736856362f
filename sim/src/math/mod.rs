//! The numbers every stage uses: plane vectors, our own `sin_cos`, floor
//! and rounding without libm, bit sets, the seeded generator and the
//! counter-based draws of the noise models. Depends on nothing else in the
//! crate.

pub(crate) mod bitset;
pub mod noise;
pub mod rng;
pub mod rounding;
pub mod trig;
pub mod vec2;
