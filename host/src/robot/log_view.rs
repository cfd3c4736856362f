//! `host view --log`: a robot's recorded log checked against its policy
//! ([`playback`]) beside the world it drove on, as the document and field
//! image [`view::RecordingView`] serves.
//!
//! The document (JSON): `log` and `policy` (the files' names), `world` (the
//! arena's size, the robots' radius and outline: [`view::session::Hello`])
//! and `playback` ([`playback::Playback`]).

use super::log_file;
use super::replay::odometry::OdometrySettings;
use super::replay::playback::{self, Playback};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use sim::scenario::Scenario;
use std::path::Path;
use view::session::{self, Hello};

/// What the page is served.
pub struct LogView {
    /// The document, JSON.
    pub document: Vec<u8>,
    /// The field the robot drove on, as the live view draws it.
    pub field_png: Vec<u8>,
    /// Frames that decoded.
    pub frames: usize,
    /// Of them, frames with a divergent stage.
    pub diverged: u64,
}

#[derive(Serialize)]
struct Document<'a> {
    log: String,
    policy: String,
    world: Hello,
    playback: &'a Playback,
}

/// Reads the log and the policy, checks every frame and draws `scenario`'s
/// field; fails, naming the file, when one cannot be read or no frame of
/// the log decodes.
pub fn log_view(
    log: &Path,
    policy: &Path,
    scenario: &Scenario,
    odometry: OdometrySettings,
) -> Result<LogView> {
    let blob = sim::control::policy_file::read(policy)?;
    let recording = log_file::read(log)?;
    let (sim, _) = scenario.build()?;
    let world = Hello::of(&sim, Vec::new());
    let played = playback::playback(&recording, &blob, odometry, world.arena);
    if played.frames.is_empty() {
        bail!(
            "{}: no frame decodes ({} damaged records or frames)",
            log.display(),
            played.damaged
        );
    }
    let name = |p: &Path| {
        p.file_name()
            .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
    };
    let document = serde_json::to_vec(&Document {
        log: name(log),
        policy: name(policy),
        world,
        playback: &played,
    })
    .context("cannot encode the checked log")?;
    Ok(LogView {
        document,
        field_png: session::field_png(&sim).map_err(anyhow::Error::msg)?,
        frames: played.frames.len(),
        diverged: played.diverged,
    })
}
