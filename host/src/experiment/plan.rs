//! From an experiment spec to the trials to run: step counts scaled, seeds
//! derived, and a hash of everything that determines each trial.
//!
//! Seeds: trial `t` of arm `a` in an experiment with seed `s` runs with
//! `mix(mix(mix(s) ^ fnv1a(a)) ^ t)`, where `fnv1a` is 64-bit FNV-1a over
//! the arm's name in UTF-8 and `mix` the SplitMix64 finaliser. A
//! pre-training of trial `t` uses the arm name `pretrain`, so arms with the
//! same pre-training settings (the transfer experiment's) share its table.

use super::spec::{ArmController, ArmSpec, ExperimentSpec};
use crate::train::format1::TrainConfigV1;
use crate::train::format2::TrainConfigV2;
use crate::train::format3::TrainConfigV3;
use crate::train::format4::TrainConfigV4;
use crate::train::format6::TrainConfigV6;
use crate::train::format7::TrainConfigV7;
use crate::train::{OutputConfig, TrainConfig};
use crc::{Crc, CRC_64_XZ};
use serde::Serialize;
use sim::base::ranges;
use sim::config::robot_shape::RobotShape;
use sim::scenario::{orbital_innies, Arena, THESIS_ROBOTS};
use std::path::PathBuf;

/// Version of `TrialResult`'s layout and meaning, and of the
/// simulator's results; part of the config hash, so results of another
/// version are re-run, not mixed in. 2: headings turn through our own
/// `sin_cos` (`sim::base::trig`) instead of the platform's. (The settings of the
/// thesis author's runs, `formation_check` and the others, left it at 2:
/// at their defaults every trial runs and means what it did, and keeps its
/// hash: see `hashed`. Runs whose robots wear the wedge-fronted skirt,
/// `tv75`'s since issue 30, also hash their outline, so their trials of the
/// disc-bodied TV are run again, while every disc run keeps its hash.)
pub const RESULT_FORMAT: u32 = 2;

/// Everything one trial needs.
#[derive(Clone, Debug, PartialEq)]
pub struct TrialPlan {
    /// The experiment's name.
    pub experiment: String,
    /// The arm's name.
    pub arm: String,
    /// Trial index, from 0.
    pub trial: usize,
    /// The controller.
    pub controller: ArmController,
    /// The run, scaled and seeded.
    pub config: TrainConfig,
    /// The pre-training the run starts from, if any.
    pub pretrain: Option<PretrainPlan>,
    /// The policy blob a policy arm runs.
    pub policy: Option<PathBuf>,
    /// Hash of the controller, config, pre-training (or the policy file's
    /// contents) and result format: a stored result with another hash is
    /// stale.
    pub hash: String,
    /// The hash of the same run with its puck count left unset, when the
    /// count is the screen arena's own (12 on the TV): how trials whose
    /// file left the count to the arena were hashed. A stored result of
    /// either hash is this trial's.
    pub alias: Option<String>,
}

impl TrialPlan {
    /// Whether a stored result of config hash `hash` is this trial's.
    pub fn matches(&self, hash: &str) -> bool {
        self.hash == hash || self.alias.as_deref() == Some(hash)
    }
}

/// A pre-training run, scaled and seeded.
#[derive(Clone, Debug, PartialEq)]
pub struct PretrainPlan {
    /// The training run.
    pub config: TrainConfig,
    /// Hash of the config: names the stored table.
    pub hash: String,
}

/// The SplitMix64 finaliser: a bijective mix of 64 bits.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// 64-bit FNV-1a.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xCBF2_9CE4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3)
    })
}

/// The seed of trial `trial` of arm `arm` (see the module docs).
pub fn trial_seed(experiment_seed: u64, arm: &str, trial: usize) -> u64 {
    mix(mix(mix(experiment_seed) ^ fnv1a(arm.as_bytes())) ^ trial as u64)
}

/// `steps` scaled, rounded, at least 1.
pub fn scaled(steps: u64, scale: f64) -> u64 {
    ((steps as f64 * scale).round() as u64).max(1)
}

/// The settings as a hash sees them: an innie count equal to orbital
/// construction's on the field counts as unset (the same run either way;
/// a role hasher's count is its run's, the flashed swarm's unless set),
/// and settings that use nothing newer than checkpoint format 1, 2, 3, 4,
/// 6 or 7 are hashed in its
/// layout ([`TrainConfigV1`] to [`TrainConfigV7`]), so that trials run
/// before the newer settings existed keep their hashes; settings with one
/// added since format 7 away from its default hash as the JSON of the
/// whole [`TrainConfig`] (so a new setting keeps every earlier hash and
/// needs no rule here). (Those formats'
/// runs had wall segments: a run in the thesis' square that clamps at its
/// border, the default since, is of the newest layout and hashes anew.) Settings with the robot's
/// senses also hash their model's version
/// ([`sim::sensors::robot::MODEL_VERSION`]): trials of another model are
/// run again.
#[derive(Serialize)]
#[serde(untagged)]
enum Hashed {
    V1(TrainConfigV1),
    V2(TrainConfigV2),
    V3(TrainConfigV3),
    V4(TrainConfigV4),
    V6(TrainConfigV6),
    V7(TrainConfigV7),
    Current(TrainConfig),
    /// Settings with the robot's senses, and the version of their model.
    RobotSenses {
        model: u32,
        settings: Box<Hashed>,
    },
    /// Settings whose robots are not discs, and their outline.
    Outline {
        robot_shape: RobotShape,
        settings: Box<Hashed>,
    },
}

/// [`Hashed`] settings of `config`.
fn hashed(config: &TrainConfig) -> Hashed {
    let mut c = config.clone();
    let robots = c.world.robots.unwrap_or(THESIS_ROBOTS);
    if c.learn.hasher.0.has_role_bit() {
        c.innies = Some(c.role_innies(robots));
    }
    if c.innies == Some(orbital_innies(&c.world.field, robots)) {
        c.innies = None;
    }
    let robot_senses = c.world.sensors.is_robot();
    let settings = match TrainConfigV7::of(&c) {
        None => Hashed::Current(c),
        Some(v7) => {
            if TrainConfigV6::of(&v7).is_none() {
                Hashed::V7(v7)
            } else if let Some(v1) = TrainConfigV1::of(&v7) {
                Hashed::V1(v1)
            } else if let Some(v2) = TrainConfigV2::of(&v7) {
                Hashed::V2(v2)
            } else if let Some(v3) = TrainConfigV3::of(&v7) {
                Hashed::V3(v3)
            } else if let Some(v4) = TrainConfigV4::of(&v7) {
                Hashed::V4(v4)
            } else if let Some(v6) = TrainConfigV6::of(&v7) {
                Hashed::V6(v6)
            } else {
                Hashed::V7(v7)
            }
        }
    };
    let settings = if robot_senses {
        Hashed::RobotSenses {
            model: sim::sensors::robot::MODEL_VERSION,
            settings: Box::new(settings),
        }
    } else {
        settings
    };
    match robot_shape(config) {
        RobotShape::Disc => settings,
        robot_shape => Hashed::Outline {
            robot_shape,
            settings: Box::new(settings),
        },
    }
}

/// The outline of the run's robots: its screen arena's (an arena file
/// that cannot be read fails the run itself, and hashes as discs).
fn robot_shape(config: &TrainConfig) -> RobotShape {
    match config.arena_choice().arena() {
        Ok(Arena::Screen(spec)) => spec.robot_shape_units(),
        Ok(Arena::Square(_)) | Err(_) => RobotShape::Disc,
    }
}

/// Whether two settings give the same run (a stored pre-training's).
pub fn same_run(a: &TrainConfig, b: &TrainConfig) -> bool {
    hash(&hashed(a)) == hash(&hashed(b))
}

/// CRC-64 (XZ) of a value's JSON, as 16 hex digits.
pub(crate) fn hash(value: &impl Serialize) -> String {
    let json = serde_json::to_vec(value).unwrap_or_default();
    format!("{:016x}", Crc::<u64>::new(&CRC_64_XZ).checksum(&json))
}

/// The trials of every arm: `trials` per arm, steps scaled by `scale`,
/// seeds derived from `seed`.
pub fn plans(spec: &ExperimentSpec, trials: usize, scale: f64, seed: u64) -> Vec<TrialPlan> {
    plans_of_format(spec, trials, scale, seed, RESULT_FORMAT)
}

/// [`plans`] with the hashes that result format `format` gave them (to
/// tell whether a stored trial of an earlier format is of these settings).
pub fn plans_of_format(
    spec: &ExperimentSpec,
    trials: usize,
    scale: f64,
    seed: u64,
    format: u32,
) -> Vec<TrialPlan> {
    let mut out = Vec::new();
    for arm in &spec.arms {
        for trial in 0..trials {
            let mut config = arm.config.clone();
            config.steps = scaled(config.steps, scale);
            config.world.seed = trial_seed(seed, &arm.name, trial);
            config.output = OutputConfig::default();
            let (pretrain, trial_hash) = hashes(arm, &config, trial, scale, seed, format);
            // the same run with the count left to the arena, as trials
            // before the puck rule were hashed
            let mut unset = config.clone();
            unset.world.pucks = None;
            let alias = (config.world.pucks.is_some()
                && config.world.pucks == arena_pucks(&config))
            .then(|| hashes(arm, &unset, trial, scale, seed, format).1);
            out.push(TrialPlan {
                experiment: spec.name.clone(),
                arm: arm.name.clone(),
                trial,
                controller: arm.controller,
                config,
                pretrain,
                policy: arm.policy.clone(),
                hash: trial_hash,
                alias,
            });
        }
    }
    out
}

/// The pre-training plan of trial `trial` of `arm` run as `config`, and the
/// trial's hash.
fn hashes(
    arm: &ArmSpec,
    config: &TrainConfig,
    trial: usize,
    scale: f64,
    seed: u64,
    format: u32,
) -> (Option<PretrainPlan>, String) {
    let pretrain = arm.pretrain.as_ref().map(|p| {
        let mut pre = config.clone();
        pre.world.robots = p.robots.or(arm.config.world.robots);
        pre.steps = scaled(p.steps, scale);
        pre.world.seed = trial_seed(seed, "pretrain", trial);
        PretrainPlan {
            hash: hash(&(format, hashed(&pre))),
            config: pre,
        }
    });
    let trial_hash = match &arm.policy {
        // an unreadable file hashes as none: its trials fail naming it
        Some(path) => {
            let blob = ranges::read_file(path, &ranges::POLICY_FILE)
                .map(|b| hash(&b))
                .ok();
            hash(&(format, arm.controller, hashed(config), blob))
        }
        None => hash(&(
            format,
            arm.controller,
            hashed(config),
            pretrain.as_ref().map(|p| &p.hash),
        )),
    };
    (pretrain, trial_hash)
}

/// The puck count of the run's screen arena, if it is on a screen.
fn arena_pucks(config: &TrainConfig) -> Option<usize> {
    match config.arena_choice().arena() {
        Ok(Arena::Screen(spec)) => Some(spec.pucks),
        Ok(Arena::Square(_)) | Err(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_follow_the_documented_derivation() {
        // SplitMix64's first output from state 0 is mix(0)
        assert_eq!(mix(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(fnv1a(b""), 0xCBF2_9CE4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xAF63_DC4C_8601_EC8C);
        let s = trial_seed(1, "RL", 3);
        assert_eq!(s, mix(mix(mix(1) ^ fnv1a(b"RL")) ^ 3));
        assert_ne!(s, trial_seed(1, "RL", 4));
        assert_ne!(s, trial_seed(1, "OC", 3));
        assert_ne!(s, trial_seed(2, "RL", 3));
    }

    #[test]
    fn scaling_rounds_and_keeps_a_step() {
        assert_eq!(scaled(5_000_000, 0.001), 5000);
        assert_eq!(scaled(100, 0.0001), 1);
        assert_eq!(scaled(2_000_000, 1.0), 2_000_000);
    }
}
