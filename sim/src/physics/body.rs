//! Circle bodies and the robots that drive some of them.

use crate::base::vec2::Vec2;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// A circle in the arena: a robot or a puck.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Centre.
    pub pos: Vec2,
    /// Velocity, units per step.
    pub vel: Vec2,
    /// Radius.
    pub radius: f64,
    /// Mass, 10 x radius.
    pub mass: f64,
    /// Whether the body was in a contact during the last step; with a
    /// non-zero velocity this is what makes a body "awake" (checked for
    /// contacts) in the next step.
    pub in_contact: bool,
}

impl Body {
    /// Mass per unit of radius.
    pub(crate) const MASS_PER_RADIUS: f64 = 10.0;

    /// A body at rest.
    pub fn new(pos: Vec2, radius: f64) -> Body {
        Body {
            pos,
            vel: Vec2::ZERO,
            radius,
            mass: Self::MASS_PER_RADIUS * radius,
            in_contact: false,
        }
    }
}

/// The two robot types of orbital construction. Learning robots and the
/// other controllers use outies' sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobotKind {
    /// Nudges pucks inwards (towards higher field values); orbits at T_o.
    Outie,
    /// Nudges pucks outwards; orbits at T_i; has its own puck-sensor layout.
    Innie,
}

impl RobotKind {
    /// The role a role-aware state hash reads ([`shared::Role`]).
    pub const fn role(self) -> shared::Role {
        match self {
            RobotKind::Outie => shared::Role::Outie,
            RobotKind::Innie => shared::Role::Innie,
        }
    }
}

/// A unicycle robot: a heading, constant forward speed; an action only turns it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Robot {
    /// Heading, radians; 0 faces +x, positive turns clockwise on screen.
    pub heading: f64,
    /// The unit vector of `heading`, cached so each heading change costs
    /// one `sin_cos`.
    pub direction: Vec2,
    /// Innie or outie.
    pub kind: RobotKind,
}

impl Robot {
    /// A robot facing `heading`.
    pub fn new(heading: f64, kind: RobotKind) -> Robot {
        Robot {
            heading,
            direction: Vec2::from_angle(heading),
            kind,
        }
    }

    /// Turns by `angle` radians (positive = right). The heading is kept
    /// within [-pi, pi] (whole turns are dropped), where its sine and
    /// cosine are most accurate.
    pub fn turn(&mut self, angle: f64) {
        if angle != 0.0 {
            let heading = self.heading + angle;
            self.heading = if heading.abs() > PI {
                heading - TAU * (heading / TAU).round()
            } else {
                heading
            };
            self.direction = Vec2::from_angle(self.heading);
        }
    }
}
