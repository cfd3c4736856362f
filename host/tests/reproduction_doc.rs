//! docs/reproduction.md is what `host experiment report` renders from its
//! template and the committed trials: every figure it states comes from the
//! trial files, and every claim its template checks still holds.

use std::path::Path;

#[test]
fn the_reproduction_page_is_what_the_committed_trials_give() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let stale = std::cell::RefCell::new(Vec::new());
    let log = |line: &str| stale.borrow_mut().push(line.to_string());
    if let Err(e) = host::experiment::report::check(&docs, &log) {
        panic!("{e:#}");
    }
    assert!(stale.borrow().is_empty(), "published trials the experiment files no longer plan: {:?}", stale.borrow());
}
