//! The actions a policy chooses among.

use core::fmt;
use serde::{Deserialize, Serialize};

/// Index of an action in an [`ActionTable`], `0 .. table.len()`.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub struct ActionId(pub u8);

impl ActionId {
    /// The action as a table index.
    pub const fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for ActionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// Why an action table was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ActionTableError {
    /// Fewer than [`ActionTable::MIN_ACTIONS`] or more than [`ActionTable::MAX_ACTIONS`].
    CountOutOfRange(usize),
    /// A speed is NaN or infinite.
    NonFiniteSpeed,
}

impl fmt::Display for ActionTableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ActionTableError::CountOutOfRange(n) => write!(
                f,
                "action count {n} is out of range ({}..={})",
                ActionTable::MIN_ACTIONS,
                ActionTable::MAX_ACTIONS
            ),
            ActionTableError::NonFiniteSpeed => {
                f.write_str("an action speed is not a finite number")
            }
        }
    }
}

impl core::error::Error for ActionTableError {}

/// Unicycle actions: the robot always drives at `forward_speed` (units per
/// step) and an action sets its angular speed (radians per step; positive
/// turns right, clockwise on screen with y down).
///
/// 2 to 4 actions, so that a policy entry fits in 2 bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActionTable {
    angular: [f32; ActionTable::MAX_ACTIONS],
    len: u8,
    forward_speed: f32,
}

impl ActionTable {
    /// Fewest actions a table may hold.
    pub const MIN_ACTIONS: usize = 2;
    /// Most actions a table may hold (2 bits per policy entry).
    pub const MAX_ACTIONS: usize = 4;
    /// The thesis' forward speed, units per step.
    pub const DEFAULT_FORWARD_SPEED: f32 = 2.0;
    /// The thesis' angular speeds, radians per step.
    pub const DEFAULT_ANGULAR: [f32; 4] = [0.3, 0.15, -0.15, -0.3];

    /// A table of the given angular speeds and forward speed.
    pub fn new(angular: &[f32], forward_speed: f32) -> Result<ActionTable, ActionTableError> {
        if !(Self::MIN_ACTIONS..=Self::MAX_ACTIONS).contains(&angular.len()) {
            return Err(ActionTableError::CountOutOfRange(angular.len()));
        }
        if !forward_speed.is_finite() || angular.iter().any(|w| !w.is_finite()) {
            return Err(ActionTableError::NonFiniteSpeed);
        }
        let mut table = [0.0; Self::MAX_ACTIONS];
        table[..angular.len()].copy_from_slice(angular);
        Ok(ActionTable {
            angular: table,
            len: angular.len() as u8,
            forward_speed,
        })
    }

    /// Number of actions.
    pub const fn len(&self) -> usize {
        self.len as usize
    }

    /// Always false: a table holds at least two actions.
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// The angular speeds, one per action.
    pub fn angular_speeds(&self) -> &[f32] {
        &self.angular[..self.len()]
    }

    /// Angular speed of an action, or `None` if the id is out of range.
    pub fn angular(&self, action: ActionId) -> Option<f32> {
        self.angular_speeds().get(action.index()).copied()
    }

    /// Forward speed, units per step.
    pub const fn forward_speed(&self) -> f32 {
        self.forward_speed
    }

    /// Every action id of the table.
    pub fn ids(&self) -> impl Iterator<Item = ActionId> {
        (0..self.len).map(ActionId)
    }
}

impl Default for ActionTable {
    /// The thesis' four actions at forward speed 2.0.
    fn default() -> ActionTable {
        ActionTable {
            angular: Self::DEFAULT_ANGULAR,
            len: 4,
            forward_speed: Self::DEFAULT_FORWARD_SPEED,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_thesis_table() {
        let t = ActionTable::default();
        assert_eq!(t.angular_speeds(), &[0.3, 0.15, -0.15, -0.3]);
        assert_eq!(t.forward_speed(), 2.0);
        assert_eq!(t.angular(ActionId(3)), Some(-0.3));
        assert_eq!(t.angular(ActionId(4)), None);
        assert_eq!(t.ids().count(), 4);
    }

    #[test]
    fn two_to_four_finite_actions() {
        assert_eq!(
            ActionTable::new(&[0.3], 2.0),
            Err(ActionTableError::CountOutOfRange(1))
        );
        assert_eq!(
            ActionTable::new(&[0.1; 5], 2.0),
            Err(ActionTableError::CountOutOfRange(5))
        );
        assert_eq!(
            ActionTable::new(&[0.1, f32::NAN], 2.0),
            Err(ActionTableError::NonFiniteSpeed)
        );
        assert_eq!(
            ActionTable::new(&[0.1, 0.2], f32::INFINITY),
            Err(ActionTableError::NonFiniteSpeed)
        );
        let t = ActionTable::new(&[0.3, -0.3], 1.5).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.angular_speeds(), &[0.3, -0.3]);
    }
}
