//! What every room uses: plane vectors, our own `sin_cos`, floor and
//! rounding without libm, bit sets, a smooth gain over a rectangle, the seeded generator, the
//! counter-based draws of the noise models, [`crate::text_form!`], the one
//! way a named choice (a field, a sensor model, an arena, a reward, a
//! hasher) reads from and writes to config files, and [`ranges`], the
//! plausible range of every setting and the size limit of every file read.
//! Depends on nothing else in the crate.

pub mod bitset;
pub mod gain_grid;
pub mod noise;
pub mod ranges;
pub mod rng;
pub mod rounding;
mod text_form;
pub mod trig;
pub mod vec2;
