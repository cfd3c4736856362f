//! One decision: raw RC times and Pixy blocks -> motor outputs.
//!
//! Calibrate the three times, classify the blocks, hash the reading with
//! the policy's hasher (`shared`, the trainer's code), look the state's
//! best actions up in the packed sets, pick one with the robot's
//! [`ChoiceRng`] (no draw when there is one), and take that action's motor
//! outputs, computed at build time. Integer-only: this is the code path the
//! 2,000-cycle budget covers. It cannot panic: every index is masked into
//! its table.

use shared::{
    ActionId, ActionMotors, ActionSets, BlobSummary, CameraConfig, ChoiceRng, DriveOutputs,
    FieldScales, FieldValue, MotorCommand, PixyBlock, Role, SensorReading, State, StateHasher,
};

/// Read access to the packed best-action sets (in flash on the robot).
pub trait PolicyBytes {
    /// The byte at `index`; `index` is below the table's length.
    fn byte(&self, index: usize) -> u8;
}

impl PolicyBytes for [u8] {
    fn byte(&self, index: usize) -> u8 {
        self.get(index).copied().unwrap_or(0)
    }
}

/// Everything a decision computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decision {
    /// Calibrated left, mid, right field values.
    pub values: [FieldValue; 3],
    /// The camera's sensor bits.
    pub blobs: BlobSummary,
    /// The hashed state.
    pub state: State,
    /// The policy's action: the state's best action, or the one the
    /// generator picked among several.
    pub action: ActionId,
    /// The action's motor commands.
    pub command: MotorCommand,
    /// The action's pin-level outputs.
    pub outputs: DriveOutputs,
}

/// The decision's fixed inputs: calibration curves, camera classification,
/// hasher, the robot's role (read by the role hasher only), policy table
/// and per-action motor outputs. It borrows the curves
/// (three of them take 246 bytes, which the robot keeps in one place).
#[derive(Clone, Copy, Debug)]
pub struct Decider<'a, P: PolicyBytes + ?Sized> {
    scales: &'a FieldScales,
    camera: CameraConfig,
    hasher: StateHasher,
    role: Role,
    policy: &'a P,
    motors: ActionMotors,
}

impl<'a, P: PolicyBytes + ?Sized> Decider<'a, P> {
    /// A decider with the curves of the robot's calibration
    /// (`FieldCalibration::scales`, or `FieldScales::calibrate` in place).
    /// `policy` holds `hasher.num_states() / 2` packed bytes
    /// ([`ActionSets::packed`]).
    pub fn new(
        scales: &'a FieldScales,
        camera: CameraConfig,
        hasher: StateHasher,
        role: Role,
        policy: &'a P,
        motors: ActionMotors,
    ) -> Self {
        Decider {
            scales,
            camera,
            hasher,
            role,
            policy,
            motors,
        }
    }

    /// Decides for one period's raw times and blocks, drawing from
    /// `choice` when the state has two or more best actions.
    pub fn decide(
        &self,
        times: &[u16; 3],
        blocks: &[PixyBlock],
        choice: &mut ChoiceRng,
    ) -> Decision {
        let values = self.scales.values(times);
        let blobs = self.camera.classify(blocks);
        let state = self
            .hasher
            .hash_as(&SensorReading::from_parts(values, blobs), self.role);
        let masked = State(state.0 & (self.hasher.num_states() as u16 - 1));
        let byte = self.policy.byte(ActionSets::byte_index(masked));
        let action = choice.pick(ActionSets::mask_in_byte(byte, masked));
        Decision {
            values,
            blobs,
            state,
            action,
            command: self.motors.command(action),
            outputs: self.motors.outputs(action),
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::config::{CAMERA, UNCALIBRATED};
    use crate::embedded;
    use shared::{FieldCalibration, PolicyBlob, RobotProfile, SensorRange};

    fn motors_of(blob: &PolicyBlob) -> ActionMotors {
        RobotProfile::ZUMO.action_motors(blob.actions())
    }

    #[test]
    fn the_embedded_policy_matches_its_blob_for_every_state() {
        let blob = PolicyBlob::decode(embedded::POLICY_BLOB).unwrap();
        assert_eq!(blob.hasher(), embedded::HASHER);
        assert_eq!(blob.sets().packed(), &embedded::POLICY_SETS[..]);
        assert_eq!(motors_of(&blob), embedded::MOTORS);
        let cal = FieldCalibration {
            ranges: [SensorRange {
                bright: 40,
                dark: 440,
            }; 3],
        };
        let scales = cal.scales();
        let d = Decider::new(
            &scales,
            CAMERA,
            embedded::HASHER,
            Role::Outie,
            &embedded::POLICY_SETS[..],
            embedded::MOTORS,
        );
        // Walk states through readings: every (left < mid, right < mid, mid bin, pucks) combination.
        let k = embedded::HASHER.mid_bits();
        let curve = scales.0[1];
        for bin in 0..(1u16 << k) {
            // A time whose value lies in the bin: the one closest to its middle.
            let middle = (f32::from(bin) + 0.5) / f32::from(1u16 << k);
            let in_bin = (40..=440u16).filter(|&t| curve.value(t).bin(k) == bin);
            let mid_time = in_bin
                .min_by(|&a, &b| {
                    let off = |t: u16| (curve.value(t).to_f32() - middle).abs();
                    off(a).total_cmp(&off(b))
                })
                .unwrap_or_else(|| panic!("no whole-tick time reads bin {bin}"));
            for bits in 0..16u8 {
                // A longer time is darker: reads less than mid.
                let left_time = if bits & 4 != 0 {
                    mid_time + 1
                } else {
                    mid_time
                };
                let right_time = if bits & 8 != 0 {
                    mid_time + 1
                } else {
                    mid_time
                };
                let mut blocks = std::vec::Vec::new();
                if bits & 1 != 0 {
                    blocks.push(PixyBlock {
                        signature: 1,
                        x: 10,
                        y: 150,
                        width: 5,
                        height: 5,
                        angle: 0,
                    });
                }
                if bits & 2 != 0 {
                    blocks.push(PixyBlock {
                        signature: 1,
                        x: 300,
                        y: 150,
                        width: 5,
                        height: 5,
                        angle: 0,
                    });
                }
                let mut choice = ChoiceRng::for_robot(0);
                let mut expected_choice = choice;
                let dec = d.decide(&[left_time, mid_time, right_time], &blocks, &mut choice);
                let expected_state = State(u16::from(bits) | bin << 4);
                assert_eq!(dec.state, expected_state);
                let action = expected_choice.pick(blob.sets().mask(expected_state));
                assert_eq!(choice, expected_choice);
                assert_eq!(dec.action, action);
                assert_eq!(dec.command, embedded::MOTORS.commands[action.index()]);
            }
        }
    }

    #[test]
    fn uncalibrated_timeouts_are_dark_and_never_panic() {
        let scales = UNCALIBRATED.scales();
        let d = Decider::new(
            &scales,
            CAMERA,
            embedded::HASHER,
            Role::Outie,
            &embedded::POLICY_SETS[..],
            embedded::MOTORS,
        );
        let mut choice = ChoiceRng::for_robot(0);
        let dec = d.decide(&[u16::MAX; 3], &[], &mut choice);
        assert_eq!(dec.values, [FieldValue::ZERO; 3]);
        assert_eq!(dec.state, State(0));
        // A short policy slice reads zeros instead of panicking.
        let scales = UNCALIBRATED.scales();
        let d = Decider::new(
            &scales,
            CAMERA,
            StateHasher::OriginalObstacle,
            Role::Outie,
            &[0u8; 3][..],
            embedded::MOTORS,
        );
        assert_eq!(d.decide(&[0; 3], &[], &mut choice).action, ActionId(0));
    }

    #[test]
    fn a_tied_state_is_decided_by_the_generator_and_only_among_its_best_actions() {
        let scales = UNCALIBRATED.scales();
        // every state: actions 1 and 3 tie
        let sets = [0b1010_1010u8; 128];
        let d = Decider::new(
            &scales,
            CAMERA,
            StateHasher::Original,
            Role::Outie,
            &sets[..],
            embedded::MOTORS,
        );
        let mut choice = ChoiceRng::for_robot(7);
        let mut counts = [0u32; 4];
        for _ in 0..4000 {
            let mut expected = ChoiceRng::from_state(choice.state());
            let dec = d.decide(&[100, 200, 300], &[], &mut choice);
            assert_eq!(dec.action, expected.pick(0b1010));
            assert_eq!(choice, expected);
            counts[dec.action.index()] += 1;
        }
        assert_eq!((counts[0], counts[2]), (0, 0));
        assert!(counts[1].abs_diff(2000) < 150, "{counts:?}");
    }
}
