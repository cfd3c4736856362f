//! Errors of settings that cannot be simulated, and the checks of the rules
//! between settings (each setting's own range is in [`crate::base::ranges`]).

use crate::base::ranges::RangeError;
use std::fmt;

/// A setting that cannot be simulated, with the offending value.
#[derive(Clone, Debug, PartialEq)]
pub enum ConfigError {
    /// A number outside its allowed range.
    OutOfRange {
        /// The setting, as in a config file (`world.robot_radius`).
        name: String,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A number outside its plausible range ([`crate::base::ranges`]).
    Implausible(RangeError),
    /// The bodies' total area exceeds what circles can fill in the arena.
    TooManyBodies {
        /// Robots plus pucks.
        bodies: usize,
        /// Their total area.
        area: f64,
        /// The most that densest circle packing fits in the arena.
        capacity: f64,
    },
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigError::OutOfRange { name, value, expected } => write!(f, "{name} = {value}: {expected}"),
            ConfigError::Implausible(e) => e.fmt(f),
            ConfigError::TooManyBodies { bodies, area, capacity } => write!(
                f,
                "{bodies} bodies cover {area:.0} square units, more than fit in the arena ({capacity:.0})"
            ),
        }
    }
}

impl std::error::Error for ConfigError {}

impl From<RangeError> for ConfigError {
    fn from(e: RangeError) -> ConfigError {
        ConfigError::Implausible(e)
    }
}

/// Checks that `value` satisfies `ok`, or names it.
pub fn check(name: &str, value: f64, ok: bool, expected: &'static str) -> Result<(), ConfigError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            name: name.to_string(),
            value,
            expected,
        })
    }
}

/// Checks that `value` is a finite number greater than zero.
pub fn positive(name: &str, value: f64) -> Result<(), ConfigError> {
    check(name, value, value > 0.0, "must be positive")
}
