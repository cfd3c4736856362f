//! The outline of the robots' bodies: the thesis' disc, or the round skirt
//! with a pointed wedge at the front that the thesis' robots wear (section
//! 1.4, Figure 8; `docs/robot-sensors.md`, "The skirt's outline").
//!
//! In a file (units, in a world config; an arena file gives the tip in
//! millimetres instead, `crate::scenario::arena::SkirtShape`):
//!
//! ```toml
//! robot_shape = "disc"                   # the default
//! robot_shape = { wedge = { tip = 13.0 } }
//! ```

use crate::base::ranges;
use crate::config::validate::ConfigError;
use serde::{Deserialize, Serialize};

/// Every robot's outline. Pucks are always discs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum RobotShape {
    /// A circle of the robot radius: the thesis' simulated bodies.
    #[default]
    Disc,
    /// The round back, a circle of the robot radius around the robot's
    /// centre, and a wedge whose faces run from the tip, `tip` units
    /// straight ahead of the centre, tangent to the circle: the convex
    /// hull of the circle and the tip. Its full angle is `2 asin(r / tip)`;
    /// with a round back of fixed radius, the angle and the length fix
    /// each other (a face that cut into the circle would leave a notch).
    Wedge {
        /// The tip's distance from the centre, units (more than the robot
        /// radius).
        tip: f64,
    },
}

impl RobotShape {
    /// Whether this is the thesis' disc.
    pub fn is_disc(&self) -> bool {
        *self == RobotShape::Disc
    }

    /// The radius of the smallest circle around the centre that holds the
    /// outline of a robot of `robot_radius`: the tip's distance for a wedge.
    pub fn bounding_radius(&self, robot_radius: f64) -> f64 {
        match *self {
            RobotShape::Disc => robot_radius,
            RobotShape::Wedge { tip } => tip,
        }
    }

    /// Checks the tip against the robot radius: beyond the round back, at
    /// most three radii from the centre ([`ranges::TIP_RADII`]).
    pub fn validate(&self, robot_radius: f64) -> Result<(), ConfigError> {
        match *self {
            RobotShape::Disc => Ok(()),
            RobotShape::Wedge { tip } => Ok(ranges::TIP_RADII.check_as(
                "world.robot_shape.wedge.tip / world.robot_radius",
                tip / robot_radius,
            )?),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wedge_is_bounded_by_its_tip_and_its_tip_must_lie_beyond_the_round_back() {
        assert_eq!(RobotShape::Disc.bounding_radius(10.0), 10.0);
        let wedge = RobotShape::Wedge { tip: 13.0 };
        assert_eq!(wedge.bounding_radius(10.0), 13.0);
        assert!(wedge.validate(10.0).is_ok() && RobotShape::Disc.validate(10.0).is_ok());
        for tip in [10.0, 9.0, 30.5, f64::NAN] {
            let e = RobotShape::Wedge { tip }.validate(10.0).unwrap_err();
            assert!(
                e.to_string()
                    .contains("world.robot_shape.wedge.tip / world.robot_radius"),
                "{e}"
            );
        }
    }

    #[test]
    fn shapes_read_from_toml_as_documented() {
        #[derive(Deserialize)]
        struct File {
            robot_shape: RobotShape,
        }
        let read = |s: &str| toml::from_str::<File>(s).map(|f| f.robot_shape);
        assert_eq!(read("robot_shape = \"disc\"").unwrap(), RobotShape::Disc);
        assert_eq!(
            read("robot_shape = { wedge = { tip = 13.0 } }").unwrap(),
            RobotShape::Wedge { tip: 13.0 }
        );
        assert!(read("robot_shape = { wedge = { tip = 13.0, angle = 1.0 } }").is_err());
    }
}
