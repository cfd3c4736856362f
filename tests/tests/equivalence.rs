//! Sim-vs-firmware decision equivalence on the real release firmware in
//! simavr (`docs/equivalence.md`).
//!
//! For each policy under test (the `policies/robot-annulus-*` tables of
//! the 8-bit, 10-bit and role hashers, and the searched annulus, general
//! and 9-bit T tables), robot states are sampled from simulated episodes
//! with the robot sensor model on the annulus and two letters, driven by
//! that policy.
//! Each state's stimulus goes on the emulated robot's pins (RC discharge
//! delays on the three sensor pins) and bus (the camera frame served on
//! I2C), one control period per state; the firmware's logged state and
//! action and its OCR1A/OCR1B writes are compared with what the host
//! computes from the stimulus. Where a state has several best actions
//! (the tied policy, `robot-annulus-8bit-tied`, a format version 2 blob)
//! the firmware draws from its generator: the host follows every period
//! since the firmware booted with the simulator's policy controller acting
//! for the firmware's robot id, so both must make the same draw in every
//! period and log it (`tests::equivalence::follow_log`).
//! - exact check: times nudged at least two ticks from every quantisation
//!   edge, 100 % agreement required;
//! - negative controls: mirrored expectations and another policy disagree;
//! - end to end: the model's own times, un-nudged; every disagreement must
//!   be explained by a raw time moved by at most one tick.
//!
//! The ELFs come from `scripts/test` (or `scripts/build-firmware` with
//! `FIRMWARE_OUT`); a missing or stale one fails with the command to run.

use rand::{RngExt, SeedableRng};
use shared::{ActionId, LogFrame, PixyBlock, PolicyBlob, PolicyTable, Role, State};
use sim::{
    base::rng::SimRng, fields::letters::Letter, fields::source::FieldSource,
    sensors::robot::RobotSensorConfig, sensors::robot::RobotSensors,
};
use std::collections::HashMap;
use std::time::Instant;
use tests::equivalence::{
    check_elf_embeds, cycles_of_ticks, cycles_of_us, explain, follow_log, mirrored, nudge,
    read_policy, sample_states, Decided, Expectation, Expected, Sample, Variant, EIGHT_BIT,
    GENERAL, ROLE, SEARCH_ANNULUS, SEARCH_T, TEN_BIT, TIED,
};
use tests::figures::{compiler_of, thousands, Figures};
use tests::playback::{driving_zumo, frames_since_boot, play, Observed, Stimulus};
use tests::zumo::firmware_elf_in;

/// The command that regenerates the figures in `docs/equivalence.md`.
const REGENERATE: &str = "UPDATE_FIGURES=1 cargo test -p tests --test equivalence";

/// States per field; three fields give over 1,000 per hasher.
const PER_FIELD: usize = 340;
const WARMUP_STEPS: u64 = 400;
const SAMPLE_EVERY: u64 = 37;
const BUDGET_CYCLES: u64 = 2_000;

/// Whether the firmware did exactly what was expected.
fn matches(o: &Observed, e: &Expected) -> bool {
    o.frame.state == e.state
        && o.frame.action == e.action
        && o.frame.motors == e.command
        && o.duties == (e.outputs.left.duty, e.outputs.right.duty)
        && o.directions == (e.outputs.left.dir_high, e.outputs.right.dir_high)
}

/// A policy of the same hasher and actions with seeded random entries.
fn random_policy(like: &PolicyBlob, seed: u64) -> PolicyBlob {
    let mut rng = SimRng::seed_from_u64(seed);
    let mut table = PolicyTable::new(like.hasher());
    for s in 0..like.hasher().num_states() as u16 {
        table.set(
            State(s),
            ActionId(rng.random_range(0..like.actions().len() as u8)),
        );
    }
    PolicyBlob::new(*like.actions(), table, like.provenance().clone()).expect("a valid blob")
}

fn samples_of(policy: &std::path::Path) -> Vec<Sample> {
    let fields = [
        (FieldSource::Annulus, 11),
        (FieldSource::Letter(Letter::T), 12),
        (FieldSource::Letter(Letter::L), 13),
    ];
    let mut samples = Vec::new();
    for (field, seed) in fields {
        let name = field.to_string();
        let s = sample_states(policy, field, PER_FIELD, WARMUP_STEPS, SAMPLE_EVERY, seed)
            .unwrap_or_else(|e| panic!("sampling on {name}: {e:#}"));
        samples.extend(s);
    }
    samples
}

/// How often the firmware's raw time differs from the stimulus' ticks by
/// each amount, over every sensor reading.
fn offsets_of<'a>(pairs: impl Iterator<Item = (&'a [u16; 3], &'a LogFrame)>) -> Vec<(i32, usize)> {
    let mut counts: HashMap<i32, usize> = HashMap::new();
    for (ticks, frame) in pairs {
        for (raw, t) in frame.raw_times.iter().zip(ticks) {
            *counts.entry(i32::from(*raw) - i32::from(*t)).or_default() += 1;
        }
    }
    let mut counts: Vec<_> = counts.into_iter().collect();
    counts.sort();
    counts
}

fn percent(n: usize, of: usize) -> f64 {
    100.0 * n as f64 / of as f64
}

fn equivalence(v: &Variant) {
    let started = Instant::now();
    let (path, policy) = read_policy(v.policy).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(
        policy.hasher(),
        v.hasher,
        "{} has the wrong hasher",
        path.display()
    );
    let elf = firmware_elf_in(v.elf_dir, v.build);
    check_elf_embeds(&elf, &policy, v.build).unwrap_or_else(|e| panic!("{e:#}"));

    let config = RobotSensorConfig::default();
    let model = RobotSensors::new(&config, &sim::config::WorldConfig::default());
    let role = Role::of_robot_id(v.robot_id);
    let expectation = Expectation::new(&model, &policy, role);
    let samples = samples_of(&path);
    assert!(samples.len() >= 1000, "{} samples", samples.len());
    let state_of = |frame: &[PixyBlock]| {
        let frame = frame.to_vec();
        let e = &expectation;
        move |t: &[u16; 3]| e.state(t, &frame)
    };

    // Exact check: nudged stimuli, mid-tick delays.
    let nudged: Vec<[u16; 3]> = samples
        .iter()
        .map(|s| {
            nudge(&s.observation.ticks, &state_of(&s.observation.frame))
                .unwrap_or_else(|| panic!("no robust stimulus near {:?}", s.observation.ticks))
        })
        .collect();
    let nudged_count = samples
        .iter()
        .zip(&nudged)
        .filter(|(s, n)| s.observation.ticks != **n)
        .count();

    let mut z = driving_zumo(&elf, &model, config.field.poll_latency_us, true);
    let mut holding = false;
    let stimuli: Vec<Stimulus<'_>> = samples
        .iter()
        .zip(&nudged)
        .map(|(s, t)| Stimulus {
            cycles: t.map(|t| cycles_of_ticks(t, config.field.poll_latency_us)),
            frame: &s.observation.frame,
        })
        .collect();
    let observed = play(&mut z, &stimuli, &mut holding);
    // End to end: the model's own discharge times, not nudged.
    let stimuli: Vec<Stimulus<'_>> = samples
        .iter()
        .map(|s| Stimulus {
            cycles: s.observation.discharge_us.map(cycles_of_us),
            frame: &s.observation.frame,
        })
        .collect();
    let observed_e2e = play(&mut z, &stimuli, &mut holding);

    // Every period since boot decided by the simulator's robot of this
    // firmware's id: the exact check's on its stimulus' state, the others
    // on the state the firmware logged.
    let stimulus_states: HashMap<u32, State> = samples
        .iter()
        .zip(&nudged)
        .zip(&observed)
        .map(|((s, t), o)| (o.frame.tick, expectation.state(t, &s.observation.frame)))
        .collect();
    let frames = frames_since_boot(&z);
    let (decisions, differ) = follow_log(&frames, &policy, v.robot_id, |tick| {
        stimulus_states.get(&tick).copied()
    })
    .unwrap_or_else(|e| panic!("{e:#}"));
    let decided: HashMap<u32, Decided> = decisions.iter().map(|d| (d.tick, *d)).collect();
    let at = |o: &Observed| decided[&o.frame.tick];
    let draws_since_boot = decisions.iter().filter(|d| d.drew).count();

    // Exact check: nudged stimuli, mid-tick delays.
    let expected: Vec<Expected> = observed
        .iter()
        .map(|o| {
            let d = at(o);
            expectation.outcome(d.state, d.action)
        })
        .collect();
    let exact_draws = observed.iter().filter(|o| at(o).drew).count();
    let mut histogram = [0usize; 4];
    for e in &expected {
        histogram[e.action.index()] += 1;
    }
    assert!(
        histogram.iter().all(|&n| n > 0),
        "the sample does not exercise all four actions: {histogram:?}"
    );
    let mismatches: Vec<String> = observed
        .iter()
        .zip(&expected)
        .zip(&samples)
        .filter(|((o, e), _)| !matches(o, e))
        .map(|((o, e), s)| {
            format!(
                "{} step {} robot {}: expected {e:?}, firmware {:?} duties {:?}",
                s.field, s.step, s.robot, o.frame, o.duties
            )
        })
        .collect();
    let exact = samples.len() - mismatches.len();
    let exact_offsets = offsets_of(nudged.iter().zip(&observed).map(|(t, o)| (t, &o.frame)));

    // Negative controls on the same firmware periods, each drawing (where
    // its state ties) from the generator as it stood in that period.
    let mirror_mismatches = samples
        .iter()
        .zip(&nudged)
        .zip(&observed)
        .filter(|((s, t), o)| {
            let (mt, mf) = mirrored(t, &s.observation.frame);
            !matches(o, &expectation.expect(&mt, &mf, at(o).before))
        })
        .count();
    let other = random_policy(&policy, 99);
    let other_expectation = Expectation::new(&model, &other, role);
    let other_mismatches = samples
        .iter()
        .zip(&nudged)
        .zip(&observed)
        .filter(|((s, t), o)| {
            !matches(
                o,
                &other_expectation.expect(t, &s.observation.frame, at(o).before),
            )
        })
        .count();

    let (mut agree, mut explained, mut unexplained) = (0, Vec::new(), Vec::new());
    let offsets = offsets_of(
        samples
            .iter()
            .zip(&observed_e2e)
            .map(|(s, o)| (&s.observation.ticks, &o.frame)),
    );
    for (s, o) in samples.iter().zip(&observed_e2e) {
        let ticks = &s.observation.ticks;
        // Whatever state the firmware reached, it acted on it as the
        // simulator's robot does (`differ`, over every period).
        let own = expectation.expect(ticks, &s.observation.frame, at(o).before);
        if o.frame.state == own.state {
            agree += 1;
        } else {
            match explain(ticks, o.frame.state, &state_of(&s.observation.frame)) {
                Some(m) => explained.push(m),
                None => unexplained.push(format!(
                    "{} step {} robot {}: model ticks {ticks:?} state {}, firmware raw {:?} state {}",
                    s.field, s.step, s.robot, own.state, o.frame.raw_times, o.frame.state
                )),
            }
        }
    }
    let e2e_action_agree = samples
        .iter()
        .zip(&observed_e2e)
        .filter(|(s, o)| {
            expectation
                .expect(&s.observation.ticks, &s.observation.frame, at(o).before)
                .action
                == o.frame.action
        })
        .count();

    let cycles = z.decision_cycles();
    let worst = *cycles.iter().max().expect("decision markers");
    let mean = cycles.iter().sum::<u64>() as f64 / cycles.len() as f64;
    let n = samples.len();
    println!(
        "== {} ({} hasher), {}",
        v.policy,
        v.hasher.name(),
        elf.display()
    );
    println!("samples: {n} (annulus, letter:T, letter:L; {PER_FIELD} each); actions over the sample {histogram:?}");
    println!(
        "exact check: {exact}/{n} match ({:.1} %), {nudged_count} stimuli nudged ({:.1} %)",
        percent(exact, n),
        percent(nudged_count, n)
    );
    println!(
        "choices: {exact_draws}/{n} exact-check periods drew among tied actions; {} periods since boot followed, \
         {draws_since_boot} draws, {} differ from the simulator's robot {}",
        decisions.len(),
        differ.len(),
        v.robot_id
    );
    println!("exact check: firmware raw time minus stimulus ticks (per sensor reading): {exact_offsets:?}");
    println!(
        "negative controls: mirrored expectations mismatch {mirror_mismatches}/{n} ({:.1} %), another policy {other_mismatches}/{n} ({:.1} %)",
        percent(mirror_mismatches, n),
        percent(other_mismatches, n)
    );
    println!(
        "end to end: state agreement {agree}/{n} ({:.1} %), action agreement {e2e_action_agree}/{n} ({:.1} %), \
         {} disagreements explained by a one-tick move, {} unexplained",
        percent(agree, n),
        percent(e2e_action_agree, n),
        explained.len(),
        unexplained.len()
    );
    println!("end to end: firmware raw time minus model ticks (per sensor reading): {offsets:?}");
    println!(
        "cycles per decision over {} decisions: min {}, mean {mean:.0}, max {worst}",
        cycles.len(),
        cycles.iter().min().unwrap_or(&0)
    );
    println!("wall time {:.1} s", started.elapsed().as_secs_f64());

    let pct = |k: usize| {
        format!(
            "{} / {} ({:.1} %)",
            thousands(k as u64),
            thousands(n as u64),
            percent(k, n)
        )
    };
    let offsets_text = |o: &[(i32, usize)]| {
        o.iter()
            .map(|(d, c)| format!("{d:+}: {}", thousands(*c as u64)))
            .collect::<Vec<_>>()
            .join(", ")
            .replace("+0", "0")
    };
    let mut figures = Figures::new(&compiler_of(&elf));
    figures.fixed(&["states checked", &thousands(n as u64)]);
    figures.fixed(&[
        "actions over the sample (0..3)",
        &histogram.map(|h| thousands(h as u64)).join(", "),
    ]);
    figures.fixed(&[
        "calibration by the procedure (white, then black) = the simulator's",
        "yes",
    ]);
    figures.fixed(&["exact check", &pct(exact)]);
    figures.fixed(&["stimuli nudged", &pct(nudged_count)]);
    figures.fixed(&[
        "exact-check periods that drew among tied actions (the simulator's robot of the firmware's id drew the same)",
        &pct(exact_draws),
    ]);
    figures.fixed(&["mirrored expectations mismatch", &pct(mirror_mismatches)]);
    figures.fixed(&["another policy mismatches", &pct(other_mismatches)]);
    figures.compiled(&[
        "firmware raw time - stimulus ticks (exact check, per reading)",
        &offsets_text(&exact_offsets),
    ]);
    figures.compiled(&[
        "periods since boot whose logged action and draw are the simulator's robot's",
        &format!(
            "{} of {} ({} draws)",
            thousands((decisions.len() - differ.len()) as u64),
            thousands(decisions.len() as u64),
            thousands(draws_since_boot as u64)
        ),
    ]);
    figures.compiled(&["end-to-end state agreement", &pct(agree)]);
    figures.compiled(&["end-to-end action agreement", &pct(e2e_action_agree)]);
    figures.compiled(&[
        "disagreements explained by a one-tick move",
        &thousands(explained.len() as u64),
    ]);
    figures.compiled(&[
        "unexplained disagreements",
        &thousands(unexplained.len() as u64),
    ]);
    figures.compiled(&[
        "firmware raw time - model ticks (end to end, per reading)",
        &offsets_text(&offsets),
    ]);
    figures.compiled(&[
        "cycles per decision (min / mean / max)",
        &format!(
            "{} / {} / {}",
            thousands(*cycles.iter().min().unwrap_or(&0)),
            thousands(mean.round() as u64),
            thousands(worst)
        ),
    ]);

    // The host read the log over USB all the while, whole frames that decode.
    let (usb, requests, _) = z.usb_background();
    let usb_frames: Vec<&[u8]> = usb.split(|b| *b == LogFrame::DELIMITER).collect();
    let decoded = usb_frames
        .iter()
        .filter(|f| LogFrame::decode(f).is_ok())
        .count();
    println!(
        "USB: {} bytes, {decoded} frames decoded, {requests} control requests answered meanwhile",
        usb.len()
    );
    assert!(
        decoded >= n && requests as usize >= n,
        "USB streamed {decoded} frames and answered {requests} requests over {n} periods"
    );

    assert!(
        differ.is_empty(),
        "{} of {} periods chose otherwise than the simulator's robot {}, first: {:#?}",
        differ.len(),
        decisions.len(),
        v.robot_id,
        &differ[..differ.len().min(5)]
    );
    let tied_states = (0..v.hasher.num_states() as u16)
        .filter(|s| policy.sets().mask(State(*s)).count_ones() > 1)
        .count();
    assert!(
        tied_states == 0 || exact_draws * 10 >= n,
        "a policy with {tied_states} tied states drew in only {exact_draws} of {n} periods: the check does not exercise the draw"
    );
    assert!(
        mismatches.is_empty(),
        "{} of {n} periods differ, first: {:#?}",
        mismatches.len(),
        &mismatches[..mismatches.len().min(5)]
    );
    assert!(
        mirror_mismatches * 10 >= n,
        "mirrored expectations mismatch only {mirror_mismatches} of {n}: the check is too weak"
    );
    assert!(
        other_mismatches * 4 >= n,
        "another policy mismatches only {other_mismatches} of {n}: the check is too weak"
    );
    assert!(
        unexplained.is_empty(),
        "unexplained end-to-end disagreements: {unexplained:#?}"
    );
    assert!(
        worst <= BUDGET_CYCLES,
        "a decision took {worst} cycles, budget {BUDGET_CYCLES}"
    );

    let header = ["figure", &format!("{} ({})", v.policy, v.hasher.name())];
    match figures.check("docs/equivalence.md", v.elf_dir, &header, REGENERATE) {
        Ok(_) => {}
        Err(e) => panic!("{e:#}"),
    }
}

#[test]
fn the_8bit_firmware_decides_as_the_simulator() {
    equivalence(&EIGHT_BIT);
}

#[test]
fn the_10bit_firmware_decides_as_the_simulator() {
    equivalence(&TEN_BIT);
}

#[test]
fn the_firmware_of_a_tied_policy_draws_as_the_simulators_robot_of_its_id() {
    equivalence(&TIED);
}

#[test]
fn the_role_firmware_of_an_innie_decides_as_the_simulator() {
    equivalence(&ROLE);
}

#[test]
fn the_firmware_of_the_searched_annulus_policy_decides_as_the_simulator() {
    equivalence(&SEARCH_ANNULUS);
}

#[test]
fn the_firmware_of_the_general_policy_decides_as_the_simulator() {
    equivalence(&GENERAL);
}

#[test]
fn the_firmware_of_the_searched_t_policy_with_9_bit_states_decides_as_the_simulator() {
    equivalence(&SEARCH_T);
}
