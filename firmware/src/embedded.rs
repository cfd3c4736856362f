//! The policy embedded at build time (`build.rs`): its hasher, the packed
//! greedy table and each action's motor outputs.
include!(concat!(env!("OUT_DIR"), "/policy.rs"));
