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
