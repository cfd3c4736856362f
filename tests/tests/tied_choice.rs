//! The robot's choice among tied actions, on the release firmware in
//! simavr (`docs/equivalence.md`, "Tied actions"): the firmware of the
//! tied policy (`policies/robot-annulus-8bit-tied.policy`, robot id 3)
//! is shown a stimulus of every state of its hasher, round after round.
//! Every decision must be one of its state's best actions and the very
//! draw the simulator's robot 3 makes; the draws' positions within their
//! sets must be uniform within the bound stated at [`uniformity`]; and
//! `host replay` must recheck every sampled decision of the log the
//! firmware wrote, and catch one that was altered.

use host::robot::log_file;
use host::robot::replay::{replay, Stage};
use shared::{LogFrame, PixyBlock, PolicyBlob, Role, State};
use sim::sensors::robot::{RobotSensorConfig, RobotSensors};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::OnceLock;
use tests::equivalence::{
    check_elf_embeds, cycles_of_ticks, follow_log, nudge, read_policy, Decided, Expectation, TIED,
};
use tests::figures::{compiler_of, thousands, Figures};
use tests::playback::{
    driving_zumo, frames_of_stream, frames_since_boot, play, Observed, Stimulus,
};
use tests::zumo::{firmware_elf_in, PUCK_LEFT};

/// Rounds over every state: 12 x 256 periods, about 1,600 draws.
const ROUNDS: usize = 12;

const PUCK_RIGHT: PixyBlock = PixyBlock {
    x: 260,
    ..PUCK_LEFT
};

/// What one simavr session of the tied firmware did.
struct Run {
    policy: PolicyBlob,
    /// The firmware's ELF.
    elf: PathBuf,
    /// Each played period's stimulus state and what the firmware did.
    periods: Vec<(State, Observed)>,
    /// Every decision since boot, as the simulator's robot 3 makes it.
    decided: HashMap<u32, Decided>,
    /// Periods whose logged action or draw is not the simulator's.
    differ: Vec<String>,
    /// The firmware's serial stream.
    stream: Vec<u8>,
}

/// Sensor times (ticks) and a camera frame that the expectation hashes to
/// `state` (8-bit original layout: pucks, left < mid, right < mid, mid
/// bin), at least two ticks from every quantisation edge.
fn stimulus_of(
    e: &Expectation<'_>,
    model: &RobotSensors,
    state: State,
) -> ([u16; 3], Vec<PixyBlock>) {
    let s = state.0;
    let frame: Vec<PixyBlock> = [(1, PUCK_LEFT), (2, PUCK_RIGHT)]
        .into_iter()
        .filter(|(bit, _)| s & bit != 0)
        .map(|(_, b)| b)
        .collect();
    // each sensor's value at every tick
    let values: Vec<[f32; 3]> = (0..=500u16)
        .map(|t| {
            let r = model.reading(&[t; 3], &[]);
            [r.left.to_f32(), r.mid.to_f32(), r.right.to_f32()]
        })
        .collect();
    let tick_for = |sensor: usize, value: f32| {
        (0..=500u16)
            .min_by(|a, b| {
                let d = |t: &u16| (values[usize::from(*t)][sensor] - value).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap_or(0)
    };
    let mid = (f32::from(s >> 4) + 0.5) / 16.0;
    let side = |less: bool| (if less { mid - 0.02 } else { mid + 0.02 }).clamp(0.0, 1.0);
    let ticks = [
        tick_for(0, side(s & 4 != 0)),
        tick_for(1, mid),
        tick_for(2, side(s & 8 != 0)),
    ];
    let robust = nudge(&ticks, &|t: &[u16; 3]| e.state(t, &frame))
        .unwrap_or_else(|| panic!("no robust stimulus for state {state} near {ticks:?}"));
    assert_eq!(
        e.state(&robust, &frame),
        state,
        "stimulus {robust:?} {frame:?}"
    );
    (robust, frame)
}

fn run() -> &'static Run {
    static RUN: OnceLock<Run> = OnceLock::new();
    RUN.get_or_init(|| {
        let (_, policy) = read_policy(TIED.policy).unwrap_or_else(|e| panic!("{e:#}"));
        let elf = firmware_elf_in(TIED.elf_dir, TIED.build);
        check_elf_embeds(&elf, &policy, TIED.build).unwrap_or_else(|e| panic!("{e:#}"));
        let config = RobotSensorConfig::default();
        let model = RobotSensors::new(&config, &sim::config::WorldConfig::default());
        let expectation = Expectation::new(&model, &policy, Role::of_robot_id(TIED.robot_id));
        let latency = config.field.poll_latency_us;
        let stimuli: Vec<(State, [u16; 3], Vec<PixyBlock>)> = (0..TIED.hasher.num_states() as u16)
            .map(|s| {
                let (ticks, frame) = stimulus_of(&expectation, &model, State(s));
                (State(s), ticks, frame)
            })
            .collect();
        let rounds: Vec<&(State, [u16; 3], Vec<PixyBlock>)> =
            (0..ROUNDS).flat_map(|_| stimuli.iter()).collect();
        let played: Vec<Stimulus<'_>> = rounds
            .iter()
            .map(|(_, ticks, frame)| Stimulus {
                cycles: ticks.map(|t| cycles_of_ticks(t, latency)),
                frame,
            })
            .collect();
        let mut z = driving_zumo(&elf, &model, latency, false);
        let observed = play(&mut z, &played, &mut false);
        let states: HashMap<u32, State> = rounds
            .iter()
            .zip(&observed)
            .map(|((s, _, _), o)| (o.frame.tick, *s))
            .collect();
        let frames = frames_since_boot(&z);
        let (decisions, differ) =
            follow_log(&frames, &policy, TIED.robot_id, |t| states.get(&t).copied())
                .unwrap_or_else(|e| panic!("{e:#}"));
        Run {
            periods: rounds.iter().map(|(s, _, _)| *s).zip(observed).collect(),
            decided: decisions.iter().map(|d| (d.tick, *d)).collect(),
            differ,
            stream: z.uart_bytes().to_vec(),
            policy,
            elf,
        }
    })
}

#[test]
fn every_state_is_decided_among_its_best_actions_with_the_simulators_draw() {
    let r = run();
    assert!(
        r.differ.is_empty(),
        "{:#?}",
        &r.differ[..r.differ.len().min(5)]
    );
    let mut drawn_in = [0usize; 5];
    for (state, o) in &r.periods {
        let mask = r.policy.sets().mask(*state);
        assert_eq!(o.frame.state, *state, "period {}", o.frame.tick);
        assert!(
            mask & (1 << o.frame.action.0) != 0,
            "state {state}: action {:?} is not among its best {mask:04b}",
            o.frame.action
        );
        let d = r.decided[&o.frame.tick];
        assert_eq!(o.frame.action, d.action, "period {}", o.frame.tick);
        assert_eq!(d.drew, mask.count_ones() > 1);
        assert_eq!(o.frame.choice, d.drew.then_some(d.before.state()));
        drawn_in[mask.count_ones() as usize] += 1;
    }
    // every state of the hasher, every round, and the tied ones drew
    assert_eq!(r.periods.len(), ROUNDS * 256);
    let tied = (0..256u16)
        .filter(|&s| r.policy.sets().mask(State(s)).count_ones() > 1)
        .count();
    assert!(tied > 100, "a policy with many ties: {tied} states");
    assert_eq!(drawn_in[2..].iter().sum::<usize>(), ROUNDS * tied);
}

/// The chi-square statistic's 0.999 quantile for 1, 2 and 3 degrees of
/// freedom (sets of 2, 3 and 4 actions).
const CHI_SQUARE_999: [f64; 3] = [10.828, 13.816, 16.266];

/// Uniformity of the draws, per set size n (2, 3, 4): over the N draws in
/// sets of n actions, how often each position k (the k-th best action of
/// the set, 0..n) was taken. The bound: the chi-square statistic
/// sum (c_k - N/n)^2 / (N/n) at most its 0.999 quantile with n - 1 degrees
/// of freedom (independent uniform draws exceed it once in 1,000), and
/// every share c_k / N within 4 standard deviations of a binomial
/// proportion, 4 sqrt((1/n)(1 - 1/n) / N), of 1/n. The generator's own bias
/// (at most n / 65,536 per action) is far below either. The draws are the
/// firmware's, logged in simavr; the positions are taken from the logged
/// action in the state's set.
fn uniformity(r: &Run) -> Vec<(u32, usize, Vec<usize>, f64, f64)> {
    let mut counts: HashMap<u32, Vec<usize>> = HashMap::new();
    for (state, o) in &r.periods {
        let mask = r.policy.sets().mask(*state);
        let n = mask.count_ones();
        if n < 2 {
            continue;
        }
        // position of the action among the set's actions, lowest first
        let k = (mask & ((1u8 << o.frame.action.0) - 1)).count_ones() as usize;
        counts.entry(n).or_insert_with(|| vec![0; n as usize])[k] += 1;
    }
    let mut out = Vec::new();
    for n in 2..=4u32 {
        let c = counts.remove(&n).unwrap_or_default();
        let total: usize = c.iter().sum();
        let expected = total as f64 / f64::from(n);
        let chi: f64 = c
            .iter()
            .map(|&k| (k as f64 - expected).powi(2) / expected)
            .sum();
        let worst = c
            .iter()
            .map(|&k| (k as f64 / total as f64 - 1.0 / f64::from(n)).abs())
            .fold(0.0, f64::max);
        out.push((n, total, c, chi, worst));
    }
    out
}

#[test]
fn the_firmwares_draws_are_uniform_among_tied_actions_within_the_stated_bound() {
    const REGENERATE: &str = "UPDATE_FIGURES=1 cargo test -p tests --test tied_choice";
    let r = run();
    let mut figures = Figures::new(&compiler_of(&r.elf));
    figures.fixed(&[
        "periods played",
        &format!(
            "{} ({ROUNDS} rounds of every state)",
            thousands(r.periods.len() as u64)
        ),
        "-",
    ]);
    let mut failures = Vec::new();
    for (n, total, counts, chi, worst) in uniformity(r) {
        let p = 1.0 / f64::from(n);
        let bound = 4.0 * (p * (1.0 - p) / total as f64).sqrt();
        let chi_bound = CHI_SQUARE_999[n as usize - 2];
        println!(
            "sets of {n}: {total} draws, positions {counts:?}, chi-square {chi:.2} (bound {chi_bound}), \
             largest share deviation {worst:.4} (bound {bound:.4})"
        );
        if total < 300 || chi > chi_bound || worst > bound {
            failures.push(format!("sets of {n}: {total} draws, positions {counts:?}"));
        }
        figures.fixed(&[
            &format!("draws among {n} tied actions"),
            &thousands(total as u64),
            "at least 300",
        ]);
        figures.compiled(&[
            &format!("sets of {n}: draws of each position (lowest action first)"),
            &counts
                .iter()
                .map(|c| thousands(*c as u64))
                .collect::<Vec<_>>()
                .join(", "),
            "-",
        ]);
        figures.compiled(&[
            &format!("sets of {n}: chi-square, df = {}", n - 1),
            &format!("{chi:.2}"),
            &format!("{chi_bound} (0.999 quantile)"),
        ]);
        figures.compiled(&[
            &format!("sets of {n}: largest deviation of a share from 1/{n}"),
            &format!("{worst:.4}"),
            &format!("{bound:.4} (4 sd)"),
        ]);
    }
    assert!(
        failures.is_empty(),
        "not uniform within the bound: {failures:#?}"
    );
    match figures.check(
        "docs/equivalence.md",
        "tied-choice",
        &["figure", "value", "bound"],
        REGENERATE,
    ) {
        Ok(_) => {}
        Err(e) => panic!("{e:#}"),
    }
}

#[test]
fn replay_rechecks_every_sampled_decision_of_the_firmwares_log_and_catches_an_altered_one() {
    let r = run();
    let frames = frames_of_stream(&r.stream);
    let draws = frames.iter().filter(|f| f.choice.is_some()).count();
    assert!(draws >= ROUNDS * 133, "{draws} draws logged");
    let report = replay(
        &log_file::parse(&r.stream).expect("the firmware's stream parses"),
        &r.policy,
        None,
        Default::default(),
    );
    assert_eq!(
        (report.frames, report.damaged, report.diverged),
        (frames.len() as u64, 0, 0),
        "{report}"
    );

    // One drawn decision changed to another of its state's best actions,
    // the frame re-encoded: the replay finds exactly that period, at the policy.
    let i = frames
        .iter()
        .rposition(|f| f.choice.is_some() && r.policy.sets().mask(f.state).count_ones() == 4)
        .expect("a draw among four actions");
    let mut altered = frames.clone();
    altered[i].action.0 = (altered[i].action.0 + 1) % 4;
    let mut stream = Vec::new();
    for f in &altered {
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let len = f.encode(&mut buf);
        stream.extend_from_slice(&buf[..len]);
    }
    let report = replay(
        &log_file::parse(&stream).expect("a re-encoded stream parses"),
        &r.policy,
        None,
        Default::default(),
    );
    assert_eq!(report.diverged, 1, "{report}");
    let first = &report.first_divergences[0];
    assert_eq!(
        (first.tick, first.stages[0]),
        (frames[i].tick, Stage::Policy)
    );
    // and the drawn decisions replayed are the ones the simulator's robot made
    assert!(frames
        .iter()
        .filter(|f| f.choice.is_some())
        .all(|f| r.decided[&f.tick].drew));
}
