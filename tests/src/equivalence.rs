//! Sim-vs-firmware decision equivalence, the host side: robot states
//! sampled from simulated episodes with the robot sensor model, the
//! stimulus each one puts on the robot's pins and bus, what the firmware
//! must do with it (computed here from that stimulus and the simulator's
//! model, never from the firmware's log), the robot's choices among tied
//! actions as the simulator's policy controller makes them, the nudging of
//! stimuli away from quantisation edges, and the explanation of end-to-end
//! disagreements.
//! `docs/equivalence.md` describes the checks and their figures.

use anyhow::{bail, Context, Result};
use shared::{
    ActionId, ChoiceRng, DriveOutputs, LogFrame, MotorCommand, PixyBlock, PolicyBlob, RobotProfile,
    Role, State, StateHasher,
};
use sim::control::greedy::GreedyPolicy;
use sim::scenario::sensor_setup::{SelectedSensors, SensorSetup};
use sim::scenario::{Arena, ControllerChoice, Scenario};
use sim::{
    fields::source::FieldSource, scenario::arena::ArenaSpec, sensors::robot::RobotObservation,
    sensors::robot::RobotSensors,
};
use std::path::Path;

/// CPU cycles per Timer3 tick (clk/64): the RC time resolution.
pub const CYCLES_PER_TICK: u64 = 64;
/// CPU cycles per microsecond at 16 MHz.
pub const CYCLES_PER_US: f64 = 16.0;
/// How far (in ticks, on every sensor at once) a stimulus of the exact
/// check may move without changing its state.
pub const EDGE_MARGIN_TICKS: i32 = 2;
/// How far the nudge may move each of the three times, in ticks.
const NUDGE_REACH: i32 = 12;

/// A firmware build the simavr tests run: a policy, built as one robot.
pub struct Variant {
    /// The policy's file in `policies/`.
    pub policy: &'static str,
    /// Directory under `target/avr-none` of the ELF built with that policy.
    pub elf_dir: &'static str,
    /// The policy's hasher.
    pub hasher: StateHasher,
    /// The firmware's robot id (its role: odd ids are innies).
    pub robot_id: u8,
    /// The command that builds it.
    pub build: &'static str,
}

/// The 8-bit robot policy.
pub const EIGHT_BIT: Variant = Variant {
    policy: "robot-annulus-8bit.policy",
    elf_dir: "robot-annulus-8bit",
    hasher: StateHasher::Original,
    robot_id: 0,
    build: "FIRMWARE_POLICY=policies/robot-annulus-8bit.policy FIRMWARE_OUT=target/avr-none/robot-annulus-8bit \
            scripts/build-firmware",
};

/// The 10-bit robot policy.
pub const TEN_BIT: Variant = Variant {
    policy: "robot-annulus-10bit.policy",
    elf_dir: "robot-annulus-10bit",
    hasher: StateHasher::OriginalObstacle,
    robot_id: 0,
    build: "FIRMWARE_POLICY=policies/robot-annulus-10bit.policy FIRMWARE_HASHER=original-obstacle \
            FIRMWARE_OUT=target/avr-none/robot-annulus-10bit scripts/build-firmware",
};

/// A policy with ties (60 states with 2 best actions, 29 with 3, 28 with
/// 4): the firmware draws; built as robot 3, so that the generator is the
/// robot id's, not robot 0's.
pub const TIED: Variant = Variant {
    policy: "robot-annulus-8bit-tied.policy",
    elf_dir: "robot-annulus-8bit-tied",
    hasher: StateHasher::Original,
    robot_id: 3,
    build: "FIRMWARE_POLICY=policies/robot-annulus-8bit-tied.policy FIRMWARE_ROBOT_ID=3 \
            FIRMWARE_OUT=target/avr-none/robot-annulus-8bit-tied scripts/build-firmware",
};

/// The role policy in an innie's firmware (robot id 1), so that the role
/// bit takes part.
pub const ROLE: Variant = Variant {
    policy: "robot-annulus-role.policy",
    elf_dir: "robot-annulus-role",
    hasher: StateHasher::OriginalRole,
    robot_id: 1,
    build: "FIRMWARE_POLICY=policies/robot-annulus-role.policy FIRMWARE_HASHER=original-role FIRMWARE_ROBOT_ID=1 \
            FIRMWARE_OUT=target/avr-none/robot-annulus-role scripts/build-firmware",
};

/// The policy search's annulus table (issue 31) in an innie's firmware.
pub const SEARCH_ANNULUS: Variant = Variant {
    policy: "robot-search-annulus.policy",
    elf_dir: "robot-search-annulus",
    hasher: StateHasher::OriginalRole,
    robot_id: 1,
    build: "FIRMWARE_POLICY=policies/robot-search-annulus.policy FIRMWARE_HASHER=original-role FIRMWARE_ROBOT_ID=1 \
            FIRMWARE_OUT=target/avr-none/robot-search-annulus scripts/build-firmware",
};

/// The general policy (one table for every shape, issue 31).
pub const GENERAL: Variant = Variant {
    policy: "robot-general.policy",
    elf_dir: "robot-general",
    hasher: StateHasher::Original,
    robot_id: 0,
    build:
        "FIRMWARE_POLICY=policies/robot-general.policy FIRMWARE_OUT=target/avr-none/robot-general \
            scripts/build-firmware",
};

/// The policy search's T table (issue 31), the 9-bit state's.
pub const SEARCH_T: Variant = Variant {
    policy: "robot-search-T.policy",
    elf_dir: "robot-search-T",
    hasher: StateHasher::Bits9,
    robot_id: 0,
    build: "FIRMWARE_POLICY=policies/robot-search-T.policy FIRMWARE_HASHER=bits9 \
            FIRMWARE_OUT=target/avr-none/robot-search-T scripts/build-firmware",
};

/// One robot's state in a simulated episode, with its raw stimulus.
#[derive(Clone, Debug)]
pub struct Sample {
    /// The field of the episode (`annulus`, `letter:T`, ...).
    pub field: String,
    /// Simulation step at which it was taken.
    pub step: u64,
    /// Which robot.
    pub robot: usize,
    /// The model's observation: discharge times, ticks, the camera frame,
    /// the reading.
    pub observation: RobotObservation,
}

/// Samples `count` robot states from episodes on `field` driven by the
/// greedy policy in `policy` with the default robot sensor model on the TV
/// (`tv75`) at the default noise, as the shipped policies were trained:
/// after `warmup` steps, every robot's observation every `every` steps.
pub fn sample_states(
    policy: &Path,
    field: FieldSource,
    count: usize,
    warmup: u64,
    every: u64,
    seed: u64,
) -> Result<Vec<Sample>> {
    let name = field.to_string();
    let scenario = Scenario {
        field,
        controller: ControllerChoice::Policy(policy.to_path_buf()),
        sensors: SensorSetup::Robot(Box::default()),
        seed,
        arena: Arena::Screen(Box::new(ArenaSpec::tv75())),
        noise: 1.0,
        ..Scenario::default()
    };
    let (mut sim, mut controller) = scenario.build()?;
    sim.run(&mut controller, warmup);
    let mut samples = Vec::with_capacity(count);
    while samples.len() < count {
        sim.run(&mut controller, every);
        let SelectedSensors::Robot(model) = sim.sensors() else {
            bail!("the scenario did not build the robot sensor model")
        };
        for (robot, observation) in model.observations().iter().enumerate() {
            if samples.len() == count {
                break;
            }
            samples.push(Sample {
                field: name.clone(),
                step: sim.totals().steps,
                robot,
                observation: observation.clone(),
            });
        }
    }
    Ok(samples)
}

/// What the firmware must do with a stimulus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expected {
    /// The hashed state.
    pub state: State,
    /// The policy's action.
    pub action: ActionId,
    /// The signed motor commands.
    pub command: MotorCommand,
    /// Duties and direction pins.
    pub outputs: DriveOutputs,
}

/// Computes [`Expected`] from raw stimuli: the robot sensor model's reading
/// (the firmware's calibration and classification, in `shared`), the
/// policy's hasher and table, and the Zumo's drive mixing.
pub struct Expectation<'a> {
    model: &'a RobotSensors,
    policy: &'a PolicyBlob,
    role: Role,
}

impl<'a> Expectation<'a> {
    /// Expectations of `policy` on a robot of `role` (the firmware's, from
    /// its robot id) with sensor model `model`.
    pub fn new(model: &'a RobotSensors, policy: &'a PolicyBlob, role: Role) -> Expectation<'a> {
        Expectation {
            model,
            policy,
            role,
        }
    }

    /// The state of raw times (ticks) and a camera frame.
    pub fn state(&self, ticks: &[u16; 3], frame: &[PixyBlock]) -> State {
        self.policy
            .hasher()
            .hash_as(&self.model.reading(ticks, frame), self.role)
    }

    /// Everything the firmware must do with raw times and a frame when its
    /// choice generator stands at `choice` (the draw, if the state ties, is
    /// made on a copy).
    pub fn expect(&self, ticks: &[u16; 3], frame: &[PixyBlock], choice: ChoiceRng) -> Expected {
        let state = self.state(ticks, frame);
        let mut choice = choice;
        self.outcome(state, choice.pick(self.policy.sets().mask(state)))
    }

    /// The motor commands and outputs of `action` in `state`.
    pub fn outcome(&self, state: State, action: ActionId) -> Expected {
        let motors = RobotProfile::ZUMO.action_motors(self.policy.actions());
        Expected {
            state,
            action,
            command: motors.command(action),
            outputs: motors.outputs(action),
        }
    }
}

/// One decision of a robot as the simulator makes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decided {
    /// The period (the log frame's tick).
    pub tick: u32,
    /// The state decided on.
    pub state: State,
    /// The choice generator before the decision.
    pub before: ChoiceRng,
    /// The action taken.
    pub action: ActionId,
    /// Whether the decision drew (the state has two or more best actions).
    pub drew: bool,
}

/// Follows every decision a firmware made since it booted with the
/// simulator's policy controller ([`GreedyPolicy::act`]) acting for robot
/// `robot_id`, so that each tied decision draws the next number of
/// `ChoiceRng::for_robot(robot_id)`, as the firmware of that robot id must.
/// `frames` are the log's frames from the first period on; each period is
/// decided on `stimulus_state(tick)` where the test chose the stimulus,
/// on the firmware's logged state otherwise (periods before the first
/// stimulus, or held for the camera). Returns every decision and, for each
/// frame whose logged action or draw differs from it, a description
/// (empty when the firmware chose as the simulator does throughout).
pub fn follow_log(
    frames: &[LogFrame],
    policy: &PolicyBlob,
    robot_id: u8,
    stimulus_state: impl Fn(u32) -> Option<State>,
) -> Result<(Vec<Decided>, Vec<String>)> {
    if frames.first().map(|f| f.tick) != Some(1) {
        bail!("the log does not start at the firmware's first period");
    }
    if let Some(w) = frames.windows(2).find(|w| w[1].tick != w[0].tick + 1) {
        bail!(
            "the log misses periods {} to {}",
            w[0].tick + 1,
            w[1].tick - 1
        );
    }
    let mut robot = GreedyPolicy::new(policy.clone());
    let id = usize::from(robot_id);
    let (mut decided, mut differ) = (Vec::with_capacity(frames.len()), Vec::new());
    for f in frames {
        let state = stimulus_state(f.tick).unwrap_or(f.state);
        let before = robot.choice_rng(id);
        let action = robot.act(id, state);
        let drew = robot.choice_rng(id) != before;
        let logged = drew.then_some(before.state());
        if f.action != action || f.choice != logged {
            differ.push(format!(
                "period {}: state {state}, the simulator's robot {robot_id} takes {action:?} \
                 (generator before {:#06x}, drew: {drew}); the firmware logged state {}, {:?}, draw {:?}",
                f.tick,
                before.state(),
                f.state,
                f.action,
                f.choice
            ));
        }
        decided.push(Decided {
            tick: f.tick,
            state,
            before,
            action,
            drew,
        });
    }
    Ok((decided, differ))
}

/// The same scene seen in a mirror: left and right times swapped, blocks
/// mirrored about the image's centre column. (A negative control: the
/// firmware must disagree with expectations computed from it.)
pub fn mirrored(ticks: &[u16; 3], frame: &[PixyBlock]) -> ([u16; 3], Vec<PixyBlock>) {
    let width = shared::camera::IMAGE_WIDTH - 1;
    let frame = frame
        .iter()
        .map(|b| PixyBlock {
            x: width - b.x,
            ..*b
        })
        .collect();
    ([ticks[2], ticks[1], ticks[0]], frame)
}

/// Whether every move of the three times by up to [`EDGE_MARGIN_TICKS`]
/// each keeps the state: the stimulus is at least that far from every
/// quantisation edge of the hash.
pub fn is_robust(ticks: &[u16; 3], state_of: &impl Fn(&[u16; 3]) -> State) -> bool {
    let state = state_of(ticks);
    let m = EDGE_MARGIN_TICKS;
    (-m..=m).all(|a| {
        (-m..=m).all(|b| {
            (-m..=m).all(|c| moved(ticks, [a, b, c]).is_none_or(|t| state_of(&t) == state))
        })
    })
}

/// `ticks` moved by `delta`, or `None` if a time would leave 0..=65535.
fn moved(ticks: &[u16; 3], delta: [i32; 3]) -> Option<[u16; 3]> {
    let mut out = [0; 3];
    for i in 0..3 {
        out[i] = u16::try_from(i32::from(ticks[i]) + delta[i]).ok()?;
    }
    Some(out)
}

/// Every move within `reach` ticks per time, smallest total move first.
fn moves(reach: i32) -> Vec<[i32; 3]> {
    let mut all: Vec<[i32; 3]> = (-reach..=reach)
        .flat_map(|a| (-reach..=reach).flat_map(move |b| (-reach..=reach).map(move |c| [a, b, c])))
        .collect();
    all.sort_by_key(|d| (d.iter().map(|v| v.abs()).sum::<i32>(), *d));
    all
}

/// A stimulus for the exact check: `ticks` itself if it is robust,
/// otherwise the nearest robust times with the same state, or failing
/// that the nearest robust times at all (their state then is the one
/// expected). `None` only if nothing within reach is robust.
pub fn nudge(ticks: &[u16; 3], state_of: &impl Fn(&[u16; 3]) -> State) -> Option<[u16; 3]> {
    if is_robust(ticks, state_of) {
        return Some(*ticks);
    }
    let state = state_of(ticks);
    let candidates: Vec<[u16; 3]> = moves(NUDGE_REACH)
        .into_iter()
        .filter_map(|d| moved(ticks, d))
        .collect();
    candidates
        .iter()
        .find(|t| state_of(t) == state && is_robust(t, state_of))
        .or_else(|| candidates.iter().find(|t| is_robust(t, state_of)))
        .copied()
}

/// Explains an end-to-end disagreement: a move of each time by at most its
/// resolution (one tick) under which the times hash to `firmware_state`
/// (the camera's blocks are served exactly, so they never move).
pub fn explain(
    ticks: &[u16; 3],
    firmware_state: State,
    state_of: &impl Fn(&[u16; 3]) -> State,
) -> Option<[i32; 3]> {
    moves(1)
        .into_iter()
        .find(|d| moved(ticks, *d).is_some_and(|t| state_of(&t) == firmware_state))
}

/// The RC delay (CPU cycles after the pin becomes an input) of a discharge
/// time, for the end-to-end check: the model's continuous time.
pub fn cycles_of_us(us: f64) -> u64 {
    (us * CYCLES_PER_US).round() as u64
}

/// The RC delay for the exact check that the firmware, with its timing
/// latency `latency_us`, reads as `ticks`: the middle of that tick.
pub fn cycles_of_ticks(ticks: u16, latency_us: f64) -> u64 {
    let middle = u64::from(ticks) * CYCLES_PER_TICK + CYCLES_PER_TICK / 2;
    middle.saturating_sub(cycles_of_us(latency_us))
}

/// Reads a policy of `policies/` (by file name); the error says how to get one.
pub fn read_policy(file: &str) -> Result<(std::path::PathBuf, PolicyBlob)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../policies")
        .join(file);
    if !path.exists() {
        bail!(
            "{} is missing: train it with `host train --sensors robot` (policies/README.md)",
            path.display()
        );
    }
    let blob = sim::control::policy_file::read(&path)?;
    Ok((path, blob))
}

/// Fails unless the ELF embeds `policy`'s packed best-action sets (a
/// stale build).
pub fn check_elf_embeds(elf: &Path, policy: &PolicyBlob, rebuild: &str) -> Result<()> {
    let bytes = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
    let table = policy.sets().packed();
    if !bytes.windows(table.len()).any(|w| w == table) {
        bail!(
            "{} does not embed this policy's table (a stale build): rebuild it with `{rebuild}`",
            elf.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::StateHasher;
    use sim::sensors::robot::RobotSensorConfig;

    /// A toy state: the mid time's bin of 10 ticks, and left < right.
    fn toy(t: &[u16; 3]) -> State {
        State(t[1] / 10 * 2 + u16::from(t[0] < t[2]))
    }

    #[test]
    fn robustness_means_two_ticks_from_every_edge() {
        assert!(is_robust(&[5, 15, 50], &toy));
        assert!(
            !is_robust(&[5, 18, 50], &toy),
            "18 + 2 crosses the bin edge at 20"
        );
        assert!(!is_robust(&[5, 11, 50], &toy));
        assert!(
            !is_robust(&[49, 15, 50], &toy),
            "left and right within 2 ticks"
        );
    }

    #[test]
    fn nudges_keep_the_state_and_move_as_little_as_possible() {
        assert_eq!(nudge(&[5, 15, 50], &toy), Some([5, 15, 50]));
        let n = nudge(&[5, 18, 50], &toy).unwrap();
        assert_eq!(n, [5, 17, 50]);
        assert_eq!(toy(&n), toy(&[5, 18, 50]));
        let n = nudge(&[49, 15, 50], &toy).unwrap();
        assert!(
            is_robust(&n, &toy) && toy(&n) == toy(&[49, 15, 50]),
            "{n:?}"
        );
    }

    #[test]
    fn disagreements_are_explained_only_within_one_tick() {
        // 19 -> bin 1; the firmware read 20 -> bin 2: explained by +1.
        let firmware = toy(&[5, 20, 50]);
        assert_eq!(explain(&[5, 19, 50], firmware, &toy), Some([0, 1, 0]));
        // Two ticks away: not explained.
        assert_eq!(explain(&[5, 18, 50], firmware, &toy), None);
    }

    #[test]
    fn mirroring_swaps_sides_and_the_hash_notices() {
        let model = RobotSensors::new(
            &RobotSensorConfig::default(),
            &sim::config::WorldConfig::default(),
        );
        let policy = read_policy("robot-annulus-10bit.policy").unwrap().1;
        assert_eq!(policy.hasher(), StateHasher::OriginalObstacle);
        let e = Expectation::new(&model, &policy, shared::Role::Outie);
        let puck = PixyBlock {
            signature: 1,
            x: 40,
            y: 150,
            width: 30,
            height: 20,
            angle: 0,
        };
        let ticks = [100, 200, 300];
        let (mt, mf) = mirrored(&ticks, &[puck]);
        assert_eq!(mt, [300, 200, 100]);
        assert_eq!(mf[0].x, 279);
        let (s, m) = (e.state(&ticks, &[puck]), e.state(&mt, &mf));
        // left brighter than mid (not below), right darker; puck left -> mirrored.
        assert_eq!(s.0 & 0b1111, 0b1001);
        assert_eq!(m.0 & 0b1111, 0b0110);
        assert_eq!(s.0 >> 4, m.0 >> 4);
    }

    #[test]
    fn stimulus_delays_sit_mid_tick_or_at_the_modelled_time() {
        assert_eq!(cycles_of_ticks(10, 0.0), 672);
        assert_eq!(cycles_of_ticks(10, 2.0), 640);
        assert_eq!(cycles_of_us(100.03), 1600);
    }
}
