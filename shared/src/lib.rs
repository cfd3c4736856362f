//! The contract between the host trainer and the Zumo firmware.
//!
//! Everything both sides must compute identically lives here, in plain
//! integer arithmetic that the ATmega32U4 runs exactly and cheaply:
//!
//! - [`FieldValue`] and [`SensorReading`]: what one robot perceives in one
//!   control step, in fixed point;
//! - [`StateHasher`]: reading -> [`State`], with the canonical bit layout of
//!   `docs/state-hash.md`;
//! - [`ActionTable`]: the angular speeds a policy chooses among;
//! - [`PolicyTable`]: the greedy policy, 2 bits per state;
//! - [`ActionSets`]: each state's best actions, 4 bits per state, and
//!   [`ChoiceRng`], the robot's seeded choice among them;
//! - [`PolicyBlob`]: the versioned, checksummed file that carries a policy
//!   from the trainer to the firmware;
//! - [`FieldCalibration`]: RC discharge times -> the field values the
//!   screen showed, as the robot's photo-transistors are read;
//! - [`CameraConfig`]: Pixy camera blocks -> puck and obstacle bits;
//! - [`RobotProfile`]: an action's unicycle speeds -> motor commands;
//! - [`LogFrame`]: what the robot reports each control period;
//! - [`FirmwareIdentity`]: the policy and robot a firmware image is for.
//!
//! The crate is `no_std` and allocation-free so that the firmware links
//! the very same code the simulator runs.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod action;
pub mod action_sets;
pub mod blob;
pub mod calibration;
pub mod camera;
pub mod choice;
pub mod drive;
pub mod field;
pub mod hasher;
pub mod identity;
pub mod log;
pub mod policy;
pub mod reading;

pub use action::{ActionId, ActionTable, ActionTableError};
pub use action_sets::ActionSets;
pub use blob::{BlobError, PolicyBlob, Provenance, TrainedFor};
pub use calibration::{FieldCalibration, FieldScales, SensorCurve, SensorRange, SensorScale};
pub use camera::{BlobSummary, CameraConfig, ImageRegion, PixyBlock};
pub use choice::ChoiceRng;
pub use drive::{ActionMotors, DriveOutputs, MotorCommand, MotorOutput, RobotProfile};
pub use field::FieldValue;
pub use hasher::{Role, State, StateHasher, StateInputs};
pub use identity::FirmwareIdentity;
pub use log::{Faults, LogError, LogFrame, RunMode};
pub use policy::PolicyTable;
pub use reading::SensorReading;
