//! Writes the stand-in policies of the equivalence tests,
//! `policies/robot-annulus-8bit.policy` and `policies/robot-annulus-10bit.policy`,
//! from `policies/oc-heuristic.policy` (see `tests::standin`). Refuses to
//! overwrite existing files unless `--force` is given: trained policies
//! replace the stand-ins.

use anyhow::{bail, Result};
use shared::StateHasher;
use std::path::Path;
use std::process::ExitCode;
use tests::standin::{standin, POLICY_10BIT, POLICY_8BIT};

fn run() -> Result<()> {
    let force = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--force") => true,
        Some(other) => bail!("unknown argument {other:?}; usage: standin-policies [--force]"),
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies");
    let oc = host::policy_file::read(&dir.join("oc-heuristic.policy"))?;
    for (file, hasher) in [(POLICY_8BIT, StateHasher::Original), (POLICY_10BIT, StateHasher::OriginalObstacle)] {
        let path = dir.join(file);
        if path.exists() && !force {
            println!("{} exists: kept (--force replaces it)", path.display());
            continue;
        }
        host::policy_file::write(&path, &standin(&oc, hasher)?)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
