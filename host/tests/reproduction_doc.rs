//! docs/reproduction.md and docs/robot-sensors.md are what `host
//! experiment report` renders from their templates and the committed
//! trials: every figure they state comes from the trial files, and every
//! claim their templates check still holds.

use std::path::Path;

#[test]
fn the_rendered_pages_are_what_the_committed_trials_give() {
    // as a user runs the report: from the repository root, against which
    // experiment files name their sensor configs and policies
    std::env::set_current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("..")).unwrap();
    let docs = Path::new("docs");
    let stale = std::cell::RefCell::new(Vec::new());
    let log = |line: &str| stale.borrow_mut().push(line.to_string());
    if let Err(e) =
        host::experiment::report::check(docs, &host::experiment::report::DOCUMENTS, &log)
    {
        panic!("{e:#}");
    }
    assert!(
        stale.borrow().is_empty(),
        "published trials the experiment files no longer plan: {:?}",
        stale.borrow()
    );
}

/// The page compares the three arms of the Original hash on the annulus
/// (annulus RL, collisions Original, state bits' 8 bits) as one setting
/// drawn with three sets of seeds: their settings must be identical.
#[test]
fn the_arms_the_page_calls_one_setting_have_identical_settings() {
    use host::experiment::spec::ExperimentSpec;
    let arms = [
        ("annulus", "RL"),
        ("collisions", "Original"),
        ("state-bits", "8 bits (Original)"),
        ("obstacle", "8 bits (Original)"),
    ];
    let settings: Vec<String> = arms
        .iter()
        .map(|(experiment, arm)| {
            let spec = ExperimentSpec::load(experiment).unwrap();
            let arm = spec.arm(arm).unwrap();
            assert!(arm.pretrain.is_none() && arm.policy.is_none());
            format!("{:?} {:?}", arm.controller, arm.config)
        })
        .collect();
    for (s, (experiment, arm)) in settings.iter().zip(arms) {
        assert_eq!(
            s, &settings[0],
            "{experiment} {arm:?} differs from annulus RL"
        );
    }
}

/// The summary's first-formation row shows means, the statistic its
/// verdicts test, and gives orbital construction a verdict too.
#[test]
fn the_summary_judges_first_formations_by_the_mean_it_shows_for_every_system() {
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduction.md"),
    )
    .unwrap();
    let row = page
        .lines()
        .find(|l| l.starts_with("| Annulus: first formation"))
        .expect("the summary has a first-formation row");
    assert!(row.contains("(mean over the trials that formed)"), "{row}");
    assert!(!row.contains("median"), "{row}");
    for system in ["OC: ", "RL: ", "RL2: "] {
        assert!(row.contains(system), "no verdict for {system}: {row}");
    }
}

/// Rows 2 and 3 of the collisions table run the code's obstacle discs and
/// test success on Eval: its column does not claim the text's settings
/// without saying which it does not follow.
#[test]
fn the_collisions_table_says_where_its_text_column_follows_the_code() {
    let table = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduction/collisions/table.md"),
    )
    .unwrap();
    assert!(!table.contains("| text: "), "a bare text column");
    assert!(table.contains("| text*: Formations"), "{table}");
    assert!(
        table.contains("Text*: the text's settings but for")
            && table.contains("radius r/4")
            && table.contains("tested on Eval"),
        "the caption explains the asterisk"
    );
}

/// One training run's table at a glance, as the author's instrumented
/// program or `host train` printed it.
#[derive(Debug, Default)]
struct TableAtEnd {
    formations: f64,
    stuck: f64,
    states: f64,
    shares: Vec<f64>,
    median: f64,
    p90: f64,
    tied: f64,
}

/// The number `skip` + 1 tokens after `key` among whitespace-separated
/// tokens.
fn after_skipping(tokens: &[&str], key: &str, skip: usize) -> f64 {
    let at = tokens
        .iter()
        .position(|t| *t == key)
        .unwrap_or_else(|| panic!("no {key} in {tokens:?}"));
    tokens[at + 1 + skip].trim_end_matches(',').parse().unwrap()
}

/// The number after `key` among whitespace-separated tokens.
fn after(tokens: &[&str], key: &str) -> f64 {
    after_skipping(tokens, key, 0)
}

/// The author's program's last lines (`END`, `ACTIONS_TOTAL`, `QSTATS`).
fn author_run(text: &str) -> TableAtEnd {
    let mut run = TableAtEnd::default();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"END") => {
                run.formations = after(&t, "formations");
                run.stuck = after(&t, "stuck");
            }
            Some(&"ACTIONS_TOTAL") => {
                run.shares = t[1..].iter().map(|v| v.parse().unwrap()).collect()
            }
            Some(&"QSTATS") => {
                run.states = after(&t, "visited_states");
                run.tied = after(&t, "states_with_tied_max");
                run.median = after(&t, "q50");
                run.p90 = after(&t, "q90");
            }
            _ => {}
        }
    }
    run
}

/// `host train`'s report.
fn our_run(text: &str) -> TableAtEnd {
    let mut run = TableAtEnd::default();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"formations") => run.formations = t[1].parse().unwrap(),
            Some(&"stuck") => run.stuck = t[2].parse().unwrap(),
            Some(&"states") => run.states = t[2].parse().unwrap(),
            Some(&"actions") => run.shares = t[2..].iter().map_while(|v| v.parse().ok()).collect(),
            Some(&"values,") => {
                run.median = after(&t, "median");
                run.p90 = after_skipping(&t, "90", 1); // "90 % -5.629,"
            }
            Some(&"tied") => run.tied = after(&t, "in"),
            _ => {}
        }
    }
    run
}

/// The side-by-side table of the learners' insides is what the runs under
/// docs/reproduction/side-by-side/ printed: the author's program and ours,
/// the same letters, length and number of runs.
#[test]
fn the_side_by_side_of_the_learned_tables_is_what_the_runs_printed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduction");
    // one space between words, as the rows and claims are written
    let template = std::fs::read_to_string(root.join("template.md"))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let mean = |runs: &[TableAtEnd], f: &dyn Fn(&TableAtEnd) -> f64| {
        runs.iter().map(f).sum::<f64>() / runs.len() as f64
    };
    let mut missing = Vec::new();
    for letter in ["T", "V"] {
        let mut formations = Vec::new();
        for (program, dir, read) in [
            (
                "the author's",
                "author",
                author_run as fn(&str) -> TableAtEnd,
            ),
            ("ours", "ours", our_run),
        ] {
            let runs: Vec<TableAtEnd> = (1..=4)
                .map(|k| {
                    let path = root.join(format!("side-by-side/{dir}/{letter}-{k}.txt"));
                    read(&std::fs::read_to_string(&path).unwrap())
                })
                .collect();
            assert!(runs.iter().all(|r| r.shares.len() == 4), "{runs:?}");
            formations.push(runs.iter().map(|r| r.formations).collect::<Vec<f64>>());
            let shares: Vec<String> = (0..4)
                .map(|a| format!("{:.3}", mean(&runs, &|r| r.shares[a])))
                .collect();
            let row = format!(
                "| {letter} | {program} | {} | {:.1} | {:.1} | {:.1} | {} | {:.2} | {:.2} | {:.0} |",
                runs.len(),
                mean(&runs, &|r| r.formations),
                mean(&runs, &|r| r.stuck),
                mean(&runs, &|r| r.states),
                shares.join(", "),
                mean(&runs, &|r| r.median),
                mean(&runs, &|r| r.p90),
                runs.iter().map(|r| r.tied).sum::<f64>(),
            );
            if !template.contains(&row) {
                missing.push(row);
            }
        }
        let p = host::report::stats::permutation_p(&formations[0], &formations[1]).unwrap();
        let claim = format!("p {p:.2} on {letter}");
        if !template.contains(&claim) {
            missing.push(claim);
        }
    }
    assert!(
        missing.is_empty(),
        "rows the template should hold:\n{}",
        missing.join("\n")
    );
}
