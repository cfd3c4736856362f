//! The simulator of policy-guided puck construction by robot swarms.
//!
//! Rooms by concern, each importing only from the rooms listed before it
//! (`tests/tests/module_graph.rs` checks the order):
//!
//! 1. [`base`]: vectors, trig, rounding, bit sets, seeded random draws,
//!    the text form of named choices;
//! 2. [`fields`]: scalar fields, the letter images, where a field comes from;
//! 3. [`config`]: every setting of a simulation, plain data with defaults
//!    and validation (world, physics, disc sensors, episodes);
//! 4. [`physics`]: bodies, the broad phase over a grid, contacts in one
//!    canonical order, impulses;
//! 5. [`world`]: the arena's bodies and robots, stepped through physics;
//! 6. [`sensors`]: sensor models turning the world into readings (the
//!    thesis' discs, the Zumo's photo-transistors and Pixy camera);
//! 7. [`episodes`]: Eval, the learning rewards, episode starts and ends;
//! 8. [`control`]: the controller hook and the controllers (orbital
//!    construction, a greedy policy table, random turns);
//! 9. [`simulation`]: the step loop and its episodes;
//! 10. [`scenario`]: a simulation built from a few choices, screen arenas
//!     and the image they show, the choice of sensor model;
//! 11. [`render`]: drawing a world.
//!
//! A step's data flows world -> physics -> sensors -> controller -> turns.
//! Every random choice comes from a seeded [`base::rng::SimRng`]; the whole
//! state is serde-serialisable for bit-exact checkpoints. The crate reads
//! field images and policy files, and writes no files.
#![warn(missing_docs)]

pub mod base;

pub mod fields;

pub mod config;

pub mod physics;

pub mod world;

pub mod sensors;

pub mod episodes;

pub mod control;

pub mod simulation;

pub mod scenario;

pub mod render;
