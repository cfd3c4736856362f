//! Sensor readings as observations: a small float vector per robot, or
//! the hashed state the thesis' policies look up.

use crate::settings::{ObservationKind, READING_LEN};
use shared::SensorReading;

/// Every world's observations, world after world, robot after robot.
#[derive(Clone, Debug, PartialEq)]
pub enum Observations {
    /// [`READING_LEN`] floats per robot.
    Readings(Vec<f32>),
    /// One state per robot.
    States(Vec<i64>),
}

/// A buffer element an observation is written into.
pub trait ObservationValue: Copy + Default + Send + Sync {
    /// Values per robot.
    fn per_robot(kind: ObservationKind) -> usize;
    /// Writes one robot's observation (`per_robot` values).
    fn write(kind: ObservationKind, reading: &SensorReading, out: &mut [Self]);
    /// The buffer as [`Observations`].
    fn wrap(values: Vec<Self>) -> Observations;
}

impl ObservationValue for f32 {
    fn per_robot(_: ObservationKind) -> usize {
        READING_LEN
    }

    fn write(_: ObservationKind, r: &SensorReading, out: &mut [f32]) {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        out.copy_from_slice(&[
            r.left.to_f32(),
            r.mid.to_f32(),
            r.right.to_f32(),
            flag(r.puck_left),
            flag(r.puck_right),
            flag(r.obstacle_left),
            flag(r.obstacle_right),
        ]);
    }

    fn wrap(values: Vec<f32>) -> Observations {
        Observations::Readings(values)
    }
}

impl ObservationValue for i64 {
    fn per_robot(_: ObservationKind) -> usize {
        1
    }

    fn write(kind: ObservationKind, r: &SensorReading, out: &mut [i64]) {
        // The batch keeps states in i64 only for the state kind.
        if let ObservationKind::State(hasher) = kind {
            out[0] = i64::from(hasher.hash(r).0);
        }
    }

    fn wrap(values: Vec<i64>) -> Observations {
        Observations::States(values)
    }
}

/// Writes the observations of `readings` (one world's robots) into `out`.
pub fn write_all<T: ObservationValue>(
    kind: ObservationKind,
    readings: &[SensorReading],
    out: &mut [T],
) {
    let per = T::per_robot(kind);
    for (reading, chunk) in readings.iter().zip(out.chunks_exact_mut(per)) {
        T::write(kind, reading, chunk);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::{FieldValue, StateHasher};

    #[test]
    fn a_reading_becomes_field_values_then_flags_and_a_state_its_hash() {
        let r = SensorReading {
            left: FieldValue::from_f32(0.35),
            mid: FieldValue::from_f32(0.4),
            right: FieldValue::from_f32(0.45),
            puck_left: true,
            ..SensorReading::default()
        };
        let mut floats = [0.0f32; READING_LEN];
        write_all(ObservationKind::Reading, &[r], &mut floats);
        assert_eq!(floats[3..], [1.0, 0.0, 0.0, 0.0]);
        assert!((floats[1] - 0.4).abs() < 1e-4);
        let mut state = [0i64];
        write_all(
            ObservationKind::State(StateHasher::Original),
            &[r],
            &mut state,
        );
        // The thesis' worked example (docs/state-hash.md).
        assert_eq!(state, [101]);
    }
}
