//! `host view --log`: a robot's recorded log checked against its policy
//! ([`playback`]) beside the world it drove on, as the document and field
//! image [`view::RecordingView`] serves.
//!
//! The document (JSON): `log` and `policy` (the files' names), `world` (the
//! arena's size, the robots' radius and outline: [`view::session::Hello`])
//! and `playback` ([`playback::Playback`] and `frames`, the list of
//! [`playback::PlaybackFrame`]s). It is written frame by frame as the log
//! is read, so that the document is the only thing that grows with the
//! log; a log is read no further than [`ranges::VIEW_LOG_FILE`] allows.

use super::log_file;
use super::replay::odometry::OdometrySettings;
use super::replay::playback::Player;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use sim::base::ranges;
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

/// The document's first fields.
#[derive(Serialize)]
struct Head {
    log: String,
    policy: String,
    world: Hello,
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
    let (sim, _) = scenario.build()?;
    let world = Hello::of(&sim, Vec::new());
    let mut player = Player::new(&blob, odometry, world.arena);
    let name = |p: &Path| {
        p.file_name()
            .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
    };
    let head = Head {
        log: name(log),
        policy: name(policy),
        world,
    };
    let encode = "cannot encode the checked log";
    // {"log":...,"world":...,"playback":{"frames":[...],"hasher":...}}
    let mut document = serde_json::to_vec(&head).context(encode)?;
    document.pop();
    document.extend_from_slice(b",\"playback\":{\"frames\":[");
    let mut failed = None;
    log_file::read_each(log, &ranges::VIEW_LOG_FILE, &mut |entry| {
        let Some(frame) = player.entry(&entry) else {
            return;
        };
        // after the list's '[' the first frame, after a frame's '}' a comma
        if document.last() == Some(&b'}') {
            document.push(b',');
        }
        if let Err(e) = serde_json::to_writer(&mut document, &frame) {
            failed.get_or_insert(e);
        }
    })?;
    if let Some(e) = failed {
        return Err(e).context(encode);
    }
    let playback = player.finish();
    if playback.frames == 0 {
        bail!(
            "{}: no frame decodes ({} damaged records or frames)",
            log.display(),
            playback.damaged
        );
    }
    let rest = serde_json::to_vec(&playback).context(encode)?;
    document.extend_from_slice(b"],");
    document.extend_from_slice(&rest[1..]);
    document.push(b'}');
    Ok(LogView {
        document,
        field_png: session::field_png(&sim).map_err(anyhow::Error::msg)?,
        frames: playback.frames,
        diverged: playback.diverged,
    })
}
