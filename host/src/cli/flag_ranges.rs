//! Every numeric flag of every command has a row in the plausible-ranges
//! table (`sim::base::ranges`, shown in `docs/ranges.md`).
//!
//! The test walks `clap`'s definition of `host` (every subcommand, nested
//! ones too, and every argument). A flag is numeric when its value parser
//! yields an integer or a float (`Option<u64>` and `Vec<f64>` fields
//! included); flags of composite values (`--marks 4x3`, `--shard K/N`,
//! `--corners`, `--bind`) check their parts themselves. A numeric flag
//! `--a-b` of `host CMD` is covered by the first row with one of these
//! keys: `host CMD --a-b`, `--a-b`, `a_b` (the key files use), or a key
//! of a section whose last part is `a_b` (`learn.alpha` for `--alpha`) or
//! whose whole dashed spelling is `a-b` (`select.every` for
//! `--select-every`).

use super::Cli;
use clap::CommandFactory;
use sim::base::ranges::{Range, SECTIONS};
use std::any::TypeId;

/// Whether a value parser's output is a number.
fn numeric(arg: &clap::Arg) -> bool {
    let id = arg.get_value_parser().type_id();
    [
        TypeId::of::<u8>(),
        TypeId::of::<u16>(),
        TypeId::of::<u32>(),
        TypeId::of::<u64>(),
        TypeId::of::<usize>(),
        TypeId::of::<i8>(),
        TypeId::of::<i16>(),
        TypeId::of::<i32>(),
        TypeId::of::<i64>(),
        TypeId::of::<isize>(),
        TypeId::of::<f32>(),
        TypeId::of::<f64>(),
    ]
    .iter()
    .any(|t| id == *t)
}

/// The row covering flag `--long` of `command` ("host search").
fn row_of(command: &str, long: &str) -> Option<&'static Range> {
    let rows = || SECTIONS.iter().flat_map(|(_, rows)| rows.iter().copied());
    let snake = long.replace('-', "_");
    let exact = [
        format!("{command} --{long}"),
        format!("--{long}"),
        snake.clone(),
    ];
    exact
        .iter()
        .find_map(|key| rows().find(|r| r.keys.contains(&key.as_str())))
        .or_else(|| {
            rows().find(|r| {
                r.keys.iter().any(|k| {
                    k.contains('.')
                        && (k.rsplit('.').next() == Some(snake.as_str())
                            || k.replace(['.', '_'], "-") == long)
                })
            })
        })
}

/// Every numeric flag of `command` and its subcommands, as
/// ("host search", "fitness-steps").
fn numeric_flags(command: &clap::Command, path: &str, out: &mut Vec<(String, String)>) {
    for arg in command.get_arguments() {
        if let Some(long) = arg.get_long().filter(|_| numeric(arg)) {
            out.push((path.to_string(), long.to_string()));
        }
    }
    for sub in command.get_subcommands() {
        numeric_flags(sub, &format!("{path} {}", sub.get_name()), out);
    }
}

#[test]
fn every_numeric_flag_of_every_command_has_a_row_in_the_ranges_table() {
    let mut flags = Vec::new();
    numeric_flags(&Cli::command(), "host", &mut flags);
    // the walk sees the flags it must: a float, an optional count, a list
    for (command, long) in [
        ("host search", "fitness-steps"),
        ("host search", "threads"),
        ("host replay", "counts-per-mm"),
        ("host experiment", "threads"),
        ("host policy gap", "seeds"),
    ] {
        assert!(
            flags.contains(&(command.to_string(), long.to_string())),
            "the walk misses {command} --{long}"
        );
    }
    let missing: Vec<String> = flags
        .iter()
        .filter(|(command, long)| row_of(command, long).is_none())
        .map(|(command, long)| format!("{command} --{long}"))
        .collect();
    assert!(
        missing.is_empty(),
        "numeric flags without a row in sim/src/base/ranges.rs (add one, enforce it, and show it in docs/ranges.md): {}",
        missing.join(", ")
    );
}

#[test]
fn a_flag_finds_its_own_row_before_a_key_of_the_same_last_part() {
    // `host render --every` is the animation's, not formation_check.every
    let render = row_of("host render", "every").map(Range::key);
    assert_eq!(render, Some("host render --every"));
    assert_eq!(
        row_of("host train", "check-every").map(Range::key),
        Some("formation_check.every")
    );
    assert_eq!(
        row_of("host train", "alpha").map(Range::key),
        Some("thresholds.outie")
    );
    assert_eq!(
        row_of("host train", "select-every").map(Range::key),
        Some("steps")
    );
    assert_eq!(row_of("host search", "no-such-flag"), None);
}

#[test]
fn the_n_step_row_is_the_learners_limit() {
    let most = sim::base::ranges::N_STEP.max;
    assert_eq!(most, f64::from(host::learn::MAX_N_STEP));
}
