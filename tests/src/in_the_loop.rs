//! The firmware in the loop: N robots of the simulated world, each driven
//! by its own simavr instance running the release ELF (`docs/in-the-loop.md`).
//!
//! One ELF serves the swarm: each instance's identity record gets its
//! robot id in flash ([`Zumo::set_robot_id`]), so its role and choice
//! generator are its id's, by the firmware's own rule (odd ids are innies).
//! The simulator's robot `i` is an innie when `i < innies`; it gets the
//! `i`-th odd id if an innie, the next even id if an outie (0, 2, 4, ...).
//!
//! Each control period (one simulator step):
//! 1. every robot's stimulus comes from the robot sensor model's
//!    observation of the current world (noise included, as `host run`
//!    senses): the three sensors' continuous RC discharge times as delays
//!    on the pins, the camera model's blocks served on I2C by the emulated
//!    Pixy;
//! 2. each firmware runs to the end of its next decision; OCR1B/OCR1A and
//!    the direction pins become a signed motor command, and the robot
//!    profile ([`RobotProfile::unicycle`]) turns it into the unicycle
//!    speeds the simulator moves the robot with: the turn drives the world
//!    (with the actuation noise `host run` applies), the forward speed is
//!    checked against the world's (every action of a table has the same);
//! 3. the world advances one step, in the same step as the decision (as
//!    [`Simulation::step`] does with the policy controller), and an ended
//!    episode is reset: the world is moved, the firmware keeps running.
//!
//! The firmware boots, is calibrated by the real procedure on the model's
//! white and black screens ([`calibrate_and_drive`]) and starts driving
//! with button A before the first step. Its log frames are checked as they
//! arrive with the log replay's decision check ([`DecisionCheck`]) and
//! compared with the model's state of that robot in that period.

use crate::equivalence::cycles_of_us;
use crate::playback::calibrate_and_drive;
use crate::zumo::Zumo;
use anyhow::{bail, Context, Result};
use host::robot::replay::decisions::DecisionCheck;
use host::run_summary::RunSummary;
use serde::{Deserialize, Serialize};
use shared::{LogFrame, MotorCommand, PolicyBlob, RobotProfile, Role, RunMode, State};
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_setup::{SelectedSensors, SensorSetup};
use sim::scenario::Scenario;
use sim::sensors::robot::RobotSensors;
use sim::simulation::Simulation;
use std::collections::VecDeque;
use std::path::Path;
use std::time::Instant;

/// The motor command the pins drive: each duty signed by its direction
/// pin (high = reverse, inverted for a flipped motor): what
/// [`RobotProfile::outputs`] wrote, read back.
pub fn command_from_pins(
    profile: &RobotProfile,
    duties: (u16, u16),
    directions: (bool, bool),
) -> MotorCommand {
    let signed = |duty: u16, high: bool, flip: bool| {
        let duty = duty.min(shared::drive::MAX_MOTOR as u16) as i16;
        if high != flip {
            -duty
        } else {
            duty
        }
    };
    MotorCommand {
        left: signed(duties.0, directions.0, profile.flip_left),
        right: signed(duties.1, directions.1, profile.flip_right),
    }
}

/// The robot ids of a swarm of `robots` whose first `innies` are innies:
/// odd ids for the innies, even ones for the outies, each from the
/// smallest.
pub fn robot_ids(robots: usize, innies: usize) -> Result<Vec<u8>> {
    let (mut odd, mut even) = (1u32, 0u32);
    (0..robots)
        .map(|i| {
            let next = if i < innies { &mut odd } else { &mut even };
            let id = u8::try_from(*next).context("more than 128 robots of one role")?;
            *next += 2;
            Ok(id)
        })
        .collect()
}

/// The world settings of a run, as `host run` takes them (`--field`,
/// `--arena`, `--robots`, `--pucks`, `--noise`, `--seed`), with the robot's
/// senses.
#[derive(Clone, Debug)]
pub struct World {
    /// The field.
    pub field: sim::fields::source::FieldSource,
    /// The arena (`None`: tv75, the robot senses' default).
    pub arena: Option<sim::scenario::arena_choice::ArenaChoice>,
    /// Robots (`None`: the arena's).
    pub robots: Option<usize>,
    /// Pucks (`None`: the arena's).
    pub pucks: Option<usize>,
    /// Noise, multiples of the default.
    pub noise: f64,
    /// Seed.
    pub seed: u64,
}

impl World {
    /// The scenario `host run --sensors robot` builds of these settings.
    pub fn scenario(&self) -> Result<Scenario> {
        host::train::TrainConfig {
            world: WorldChoices {
                field: self.field.clone(),
                sensors: sim::scenario::sensor_choice::SensorChoice::Robot(None),
                arena: self.arena.clone(),
                robots: self.robots,
                pucks: self.pucks,
                noise: self.noise,
                seed: self.seed,
                ..Default::default()
            },
            ..host::train::TrainConfig::default()
        }
        .scenario()
    }
}

/// One robot's firmware and what the loop has seen of it.
struct Firmware<'p> {
    zumo: Zumo,
    /// Its robot id.
    id: u8,
    /// Its role, by the firmware's rule.
    role: Role,
    /// The replay's check over every frame since boot.
    check: DecisionCheck<'p>,
    /// Periods played whose frames have not arrived: (tick, the motor
    /// command read from the pins, the model's state).
    pending: VecDeque<(u32, MotorCommand, State)>,
    /// The tick of the last decision.
    tick: u64,
    /// Its cycle markers' spans so far.
    marks: MarkTally,
}

/// A sum of cycle spans and their number.
#[derive(Clone, Copy, Debug, Default)]
struct Tally {
    sum: u64,
    n: u64,
}

impl Tally {
    fn mean(self) -> f64 {
        self.sum as f64 / self.n.max(1) as f64
    }
}

/// The spans between one robot's cycle markers, fed in order as they
/// arrive (the markers themselves are dropped): from each marker `from`
/// to the next `to` for sensing (4 to 1), deciding (1 to 2) and logging
/// (2 to 3), as `Zumo`'s span methods measure them, and between
/// consecutive period starts (4).
#[derive(Clone, Debug, Default)]
struct MarkTally {
    open: [Option<u64>; 3],
    spans: [Tally; 3],
    last_start: Option<u64>,
    periods: Tally,
}

impl MarkTally {
    /// The (from, to) markers of `spans`: sensing, deciding, logging.
    const SPANS: [(u8, u8); 3] = [(4, 1), (1, 2), (2, 3)];

    fn feed(&mut self, marks: &[(u8, u64)]) {
        for &(v, cycle) in marks {
            for (k, (from, to)) in Self::SPANS.into_iter().enumerate() {
                if v == from {
                    self.open[k] = Some(cycle);
                } else if v == to {
                    if let Some(start) = self.open[k].take() {
                        self.spans[k].sum += cycle - start;
                        self.spans[k].n += 1;
                    }
                }
            }
            if v == 4 {
                if let Some(last) = self.last_start.replace(cycle) {
                    self.periods.sum += cycle - last;
                    self.periods.n += 1;
                }
            }
        }
    }
}

/// The counters of a closed-loop run, beside `host run`'s summary.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LoopCounts {
    /// Control periods played (robots x steps).
    pub periods: u64,
    /// CPU cycles simulated, summed over the robots.
    pub avr_cycles: u64,
    /// Periods whose log frame arrived and was checked.
    pub periods_checked: u64,
    /// Checked periods whose logged state and action are what the policy
    /// gives for the firmware's own logged readings (the log replay's
    /// check: no stage diverged), the robot driving, without faults.
    pub periods_consistent: u64,
    /// Checked periods whose logged state is the model's state of that
    /// robot in that period.
    pub periods_state_agree: u64,
    /// Periods whose wheel speeds came from the pins: the firmware made
    /// exactly one decision since the last step and the command read from
    /// its pins is the one its log frame records.
    pub periods_from_pins: u64,
    /// Periods whose forward speed from the pins differs from the world's
    /// by more than one motor command step.
    pub forward_mismatches: u64,
    /// CPU cycles of the busy wait fast-forwarded rather than simulated
    /// instruction by instruction (`Zumo::skip_waits`), summed over the
    /// robots; part of `avr_cycles`.
    pub cycles_skipped: u64,
}

/// What `in-the-loop --json` prints: `host run`'s summary and the loop's
/// counters and shares.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoopSummary {
    /// The run's counters, as `host run` prints them.
    #[serde(flatten)]
    pub run: RunSummary,
    /// The loop's counters.
    #[serde(flatten)]
    pub counts: LoopCounts,
    /// `periods_consistent / periods_checked` (must be 1).
    pub decisions_consistent: f64,
    /// `periods_state_agree / periods_checked`.
    pub state_agreement: f64,
    /// Periods per second of wall time.
    pub periods_per_second: f64,
    /// Where the simulated CPU cycles of a period go, means over every
    /// period since boot of every robot.
    pub cycles: CycleBudget,
    /// Share of the wall time spent stepping the world (physics, sensing,
    /// evaluation); the rest is simavr's.
    pub world_time_share: f64,
}

/// Mean CPU cycles per control period, by what the firmware does in them
/// (its GPIOR0 markers): reading the sensors (RC timing, the camera on
/// I2C), deciding, logging, and waiting for the next period (a busy wait:
/// simavr cannot wake from SLEEP), which simavr simulates cycle by cycle.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CycleBudget {
    /// Cycles of one period (16 MHz x 20 ms).
    pub period: f64,
    /// Buttons, RC timing of the field sensors, the camera's read.
    pub sensing: f64,
    /// The decision: hash, table, motor writes.
    pub decision: f64,
    /// EEPROM, LEDs, the log frame.
    pub logging: f64,
    /// The rest: waiting for the next period.
    pub waiting: f64,
    /// Of the waiting, the cycles fast-forwarded (not simulated).
    pub waiting_skipped: f64,
}

/// N firmware instances driving the simulated world.
pub struct InTheLoop<'p> {
    sim: Simulation<SelectedSensors>,
    policy: &'p PolicyBlob,
    profile: RobotProfile,
    robots: Vec<Firmware<'p>>,
    turns: Vec<f32>,
    counts: LoopCounts,
    /// A fixed stimulus every robot gets instead of its observation's.
    fixed: Option<Stimulus>,
    /// Wall time spent stepping the world.
    world_seconds: f64,
    /// Every log frame checked, with its robot's id, if recording.
    recorded: Option<Vec<(u8, LogFrame)>>,
}

/// A stimulus held fixed: RC delays in CPU cycles and a camera frame.
#[derive(Clone, Debug)]
pub struct Stimulus {
    /// Each field sensor's RC delay, cycles after its pin becomes an input.
    pub cycles: [u64; 3],
    /// The blocks the Pixy serves.
    pub frame: Vec<shared::PixyBlock>,
}

impl<'p> InTheLoop<'p> {
    /// Boots one firmware per robot of `scenario` (its sensors must be the
    /// robot model) from `elf`, and calibrates and starts each. `policy` is
    /// what its decisions are checked against: the one the ELF embeds
    /// (`equivalence::check_elf_embeds`), or another for a negative control.
    pub fn new(elf: &Path, policy: &'p PolicyBlob, scenario: &Scenario) -> Result<InTheLoop<'p>> {
        let SensorSetup::Robot(sensor_config) = &scenario.sensors else {
            bail!("the firmware in the loop needs the robot sensor model (--sensors robot)");
        };
        let latency_us = sensor_config.field.poll_latency_us;
        let (sim, _) = scenario.build_with_policy(policy.clone())?;
        let model = robot_model(&sim)?;
        let world = sim.config().world.clone();
        let ids = robot_ids(world.robots, world.innies)?;
        let mut robots = Vec::with_capacity(ids.len());
        for id in ids {
            let mut zumo = Zumo::boot_elf(elf);
            zumo.set_robot_id(id)?;
            zumo.run_ms(40);
            calibrate_and_drive(&mut zumo, model, latency_us);
            zumo.skip_waits(true);
            let tick = zumo.decisions();
            robots.push(Firmware {
                zumo,
                id,
                role: Role::of_robot_id(id),
                check: DecisionCheck::new(policy),
                pending: VecDeque::new(),
                tick,
                marks: MarkTally::default(),
            });
        }
        let mut run = InTheLoop {
            turns: vec![0.0; robots.len()],
            sim,
            policy,
            profile: RobotProfile::ZUMO,
            robots,
            counts: LoopCounts::default(),
            fixed: None,
            world_seconds: 0.0,
            recorded: None,
        };
        run.check_frames()?;
        Ok(run)
    }

    /// The simulation.
    pub fn simulation(&self) -> &Simulation<SelectedSensors> {
        &self.sim
    }

    /// Each robot's id.
    pub fn robot_ids(&self) -> Vec<u8> {
        self.robots.iter().map(|r| r.id).collect()
    }

    /// The counters so far.
    pub fn counts(&self) -> &LoopCounts {
        &self.counts
    }

    /// Whether the firmwares' busy waits are fast-forwarded (the default;
    /// `Zumo::skip_waits`) or simulated cycle by cycle.
    pub fn skip_waits(&mut self, on: bool) {
        for r in &mut self.robots {
            r.zumo.skip_waits(on);
        }
    }

    /// Keeps every log frame checked from now on, with its robot's id
    /// ([`InTheLoop::recorded_frames`]).
    pub fn record_frames(&mut self) {
        self.recorded.get_or_insert_with(Vec::new);
    }

    /// The frames kept since [`InTheLoop::record_frames`], in the order
    /// checked.
    pub fn recorded_frames(&self) -> &[(u8, LogFrame)] {
        self.recorded.as_deref().unwrap_or(&[])
    }

    /// Gives every robot `stimulus` from now on instead of what its
    /// sensors see (`None`: their observations again); the model state the
    /// frames are compared with stays the observation's.
    pub fn hold_stimulus(&mut self, stimulus: Option<Stimulus>) {
        self.fixed = stimulus;
    }

    /// One control period of every robot and one step of the world.
    pub fn step(&mut self) -> Result<()> {
        let model = robot_model(&self.sim)?;
        let hasher = self.policy.hasher();
        let forward = self.sim.config().world.forward_speed as f32;
        let (forward_step, _) = self.profile.unicycle(MotorCommand { left: 1, right: 1 });
        for (i, r) in self.robots.iter_mut().enumerate() {
            let o = &model.observations()[i];
            match &self.fixed {
                Some(fixed) => {
                    r.zumo.set_sensor_cycles(fixed.cycles.map(Some));
                    r.zumo.show(&fixed.frame);
                }
                None => {
                    r.zumo
                        .set_sensor_cycles(o.discharge_us.map(|us| Some(cycles_of_us(us))));
                    r.zumo.show(&o.frame);
                }
            }
            let tick = r.zumo.run_to_decision();
            let command = command_from_pins(&self.profile, r.zumo.duties(), r.zumo.directions());
            let (pin_forward, turn) = self.profile.unicycle(command);
            self.turns[i] = turn;
            if (pin_forward - forward).abs() > forward_step {
                self.counts.forward_mismatches += 1;
            }
            let state = hasher.hash_as(&model.reading(&o.ticks, &o.frame), r.role);
            if tick == r.tick + 1 {
                r.pending.push_back((tick as u32, command, state));
            }
            r.tick = tick;
            self.counts.periods += 1;
        }
        let world = Instant::now();
        let report = self.sim.advance(&self.turns, false);
        if report.end.is_some() {
            self.sim.reset_episode();
        }
        self.world_seconds += world.elapsed().as_secs_f64();
        self.check_frames()
    }

    /// Runs `steps` steps and summarises them.
    pub fn run(&mut self, steps: u64) -> Result<LoopSummary> {
        let start = Instant::now();
        for _ in 0..steps {
            self.step()?;
        }
        // The last period's frame: sent within the period.
        for r in &mut self.robots {
            r.zumo.run_ms(10);
        }
        self.check_frames()?;
        let seconds = start.elapsed().as_secs_f64();
        self.counts.avr_cycles = self.robots.iter().map(|r| r.zumo.cycles()).sum();
        self.counts.cycles_skipped = self.robots.iter().map(|r| r.zumo.cycles_skipped()).sum();
        let cycles = self.cycle_budget();
        let c = &self.counts;
        let share = |n: u64| {
            if c.periods_checked == 0 {
                0.0
            } else {
                n as f64 / c.periods_checked as f64
            }
        };
        Ok(LoopSummary {
            run: RunSummary::new(self.sim.totals(), seconds),
            decisions_consistent: share(c.periods_consistent),
            state_agreement: share(c.periods_state_agree),
            periods_per_second: c.periods as f64 / seconds.max(f64::MIN_POSITIVE),
            counts: c.clone(),
            cycles,
            world_time_share: self.world_seconds / seconds.max(f64::MIN_POSITIVE),
        })
    }

    /// Mean cycles per period over every robot's periods since boot.
    fn cycle_budget(&self) -> CycleBudget {
        let (mut period, mut sensing, mut decision, mut logging, mut skipped) =
            (0.0, 0.0, 0.0, 0.0, 0.0);
        for r in &self.robots {
            let m = &r.marks;
            period += m.periods.mean();
            sensing += m.spans[0].mean();
            decision += m.spans[1].mean();
            logging += m.spans[2].mean();
            skipped += r.zumo.cycles_skipped() as f64 / m.periods.n.max(1) as f64;
        }
        let n = self.robots.len().max(1) as f64;
        CycleBudget {
            period: period / n,
            sensing: sensing / n,
            decision: decision / n,
            logging: logging / n,
            waiting: (period - sensing - decision - logging) / n,
            waiting_skipped: skipped / n,
        }
    }

    /// Checks every log frame that arrived since the last call, then drops
    /// the checked serial bytes and tallies and drops the cycle markers (a
    /// long run's memory stays bounded).
    fn check_frames(&mut self) -> Result<()> {
        for r in &mut self.robots {
            r.marks.feed(&r.zumo.take_marks());
            let frames = r.zumo.frames();
            r.zumo.forget_frames();
            for frame in frames {
                let f = frame.map_err(|e| anyhow::anyhow!("robot {}: a log frame: {e}", r.id))?;
                if let Some(recorded) = &mut self.recorded {
                    recorded.push((r.id, f));
                }
                let consistent = r.check.frame(0, &f).stages.is_empty();
                while r.pending.front().is_some_and(|p| p.0 < f.tick) {
                    r.pending.pop_front();
                }
                if let Some(&(tick, command, state)) = r.pending.front() {
                    if tick == f.tick {
                        r.pending.pop_front();
                        count(&mut self.counts, &f, consistent, command, state);
                    }
                }
            }
        }
        Ok(())
    }
}

/// One published run (an element of `docs/in-the-loop-runs.json`'s
/// array): the settings it ran with (`field`, `policy`, `seed`; the others
/// are ignored here) and what `in-the-loop --json --compare` printed.
#[derive(Clone, Debug, Deserialize)]
pub struct PublishedRun {
    /// `--field`.
    pub field: String,
    /// `--policy`.
    pub policy: String,
    /// `--seed`.
    pub seed: u64,
    /// Steps run.
    pub steps: u64,
    /// Formations in the loop.
    pub formations: u64,
    /// Periods played.
    pub periods: u64,
    /// Periods whose turn came from the pins.
    pub periods_from_pins: u64,
    /// Share of consistent decisions.
    pub decisions_consistent: f64,
    /// Share of states agreeing with the model's.
    pub state_agreement: f64,
    /// Wall-clock speed.
    pub periods_per_second: f64,
    /// CPU cycles simulated.
    pub avr_cycles: u64,
    /// CPU cycles fast-forwarded (absent: none).
    #[serde(default)]
    pub cycles_skipped: u64,
    /// Where a period's cycles went.
    pub cycles: CyclesOfRun,
    /// `host run`'s summary of the same steps and seed (`None`: run
    /// without `--compare`).
    pub simulator: Option<SimulatorRun>,
}

/// A published run's [`CycleBudget`] (`waiting_skipped` absent: 0).
#[derive(Clone, Debug, Deserialize)]
pub struct CyclesOfRun {
    /// Cycles of a period.
    pub period: f64,
    /// Sensing.
    pub sensing: f64,
    /// Deciding.
    pub decision: f64,
    /// Logging.
    pub logging: f64,
    /// Waiting.
    pub waiting: f64,
    /// Of the waiting, fast-forwarded.
    #[serde(default)]
    pub waiting_skipped: f64,
}

/// The part of `host run`'s summary a published run's table shows.
#[derive(Clone, Debug, Deserialize)]
pub struct SimulatorRun {
    /// Formations.
    pub formations: u64,
}

/// The tables `docs/in-the-loop.md` shows of the published runs (the
/// JSON array of [`PublishedRun`]): each run's formations, checks and
/// speed, a sum row per policy and field of more than one run, then each
/// run's cycles.
pub fn runs_tables(json: &str) -> Result<String> {
    let runs: Vec<PublishedRun> =
        serde_json::from_str(json).context("the published runs are not a JSON array of runs")?;
    let k = crate::figures::thousands;
    let stem = |p: &str| {
        Path::new(p)
            .file_stem()
            .map_or(p.to_string(), |s| s.to_string_lossy().into_owned())
    };
    let mut out = vec![
        "| policy | field | seed | steps | formations (loop) | formations (`host run`) | decisions consistent | state agreement | periods from the pins | periods per second |".to_string(),
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |".to_string(),
    ];
    // Per policy and field: runs, steps, formations in the loop and in
    // `host run` (`None` once a run was not compared).
    let mut groups: Vec<(String, String, u64, u64, u64, Option<u64>)> = Vec::new();
    for r in &runs {
        let host = r.simulator.as_ref().map(|s| s.formations);
        out.push(format!(
            "| {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {} of {} | {:.0} |",
            stem(&r.policy),
            r.field,
            r.seed,
            k(r.steps),
            r.formations,
            host.map_or(String::new(), |f| f.to_string()),
            r.decisions_consistent,
            r.state_agreement,
            k(r.periods_from_pins),
            k(r.periods),
            r.periods_per_second
        ));
        let key = (stem(&r.policy), r.field.clone());
        let i = match groups.iter().position(|g| (&g.0, &g.1) == (&key.0, &key.1)) {
            Some(i) => i,
            None => {
                groups.push((key.0, key.1, 0, 0, 0, Some(0)));
                groups.len() - 1
            }
        };
        let g = &mut groups[i];
        g.2 += 1;
        g.3 += r.steps;
        g.4 += r.formations;
        g.5 = g.5.zip(host).map(|(a, b)| a + b);
    }
    let summed = groups.into_iter().filter(|g| g.2 > 1);
    for (policy, field, runs, steps, loop_formations, host_formations) in summed {
        let (host, ratio) = match host_formations {
            Some(h) => (
                h.to_string(),
                format!("ratio {:.2}", loop_formations as f64 / h.max(1) as f64),
            ),
            None => (String::new(), String::new()),
        };
        out.push(format!(
            "| {policy} | {field}: sum | {runs} runs | {} | {loop_formations} | {host} | | | | {ratio} |",
            k(steps)
        ));
    }
    out.push(String::new());
    out.push("| policy | field | seed | AVR cycles | fast-forwarded | period | sensing | deciding | logging | waiting | of it fast-forwarded |".to_string());
    out.push(
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |".to_string(),
    );
    for r in &runs {
        let c = &r.cycles;
        let n = |x: f64| k(x.round() as u64);
        out.push(format!(
            "| {} | {} | {} | {} | {:.0} % | {} | {} | {} | {} | {} | {} |",
            stem(&r.policy),
            r.field,
            r.seed,
            k(r.avr_cycles),
            100.0 * r.cycles_skipped as f64 / r.avr_cycles.max(1) as f64,
            n(c.period),
            n(c.sensing),
            n(c.decision),
            n(c.logging),
            n(c.waiting),
            n(c.waiting_skipped)
        ));
    }
    Ok(out.join("\n"))
}

/// Counts one played period's frame.
fn count(c: &mut LoopCounts, f: &LogFrame, consistent: bool, command: MotorCommand, state: State) {
    c.periods_checked += 1;
    let driving = f.mode == RunMode::Driving && f.faults == shared::Faults::NONE;
    c.periods_consistent += u64::from(consistent && driving);
    c.periods_state_agree += u64::from(f.state == state);
    c.periods_from_pins += u64::from(f.motors == command);
}

/// The simulation's robot sensor model.
fn robot_model(sim: &Simulation<SelectedSensors>) -> Result<&RobotSensors> {
    match sim.sensors() {
        SelectedSensors::Robot(model) => Ok(model),
        _ => bail!("the scenario did not build the robot sensor model"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pins_read_back_the_command_the_profile_wrote() {
        let profile = RobotProfile::ZUMO;
        for (left, right) in [(150, 150), (341, -41), (-41, 341), (0, -400), (54, 246)] {
            let command = MotorCommand { left, right };
            let o = profile.outputs(command);
            let pins = (
                (o.left.duty, o.right.duty),
                (o.left.dir_high, o.right.dir_high),
            );
            assert_eq!(command_from_pins(&profile, pins.0, pins.1), command);
        }
    }

    #[test]
    fn innies_get_odd_ids_and_outies_even_ones() {
        assert_eq!(robot_ids(5, 2).unwrap(), [1, 3, 0, 2, 4]);
        assert_eq!(robot_ids(3, 0).unwrap(), [0, 2, 4]);
    }
}
