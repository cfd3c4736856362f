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
