//! `host field gain`: the panel's brightness gain measured from a robot's
//! logs, one per mark of `host display`'s marks screen
//! ([`sim::scenario::flat_field`] does the arithmetic), and the gain file
//! that `host display --gain` and `host field export --gain` read
//! (`docs/display.md`, "Flat-field correction").
//!
//! A mark's log is a recording (`host monitor --out`) or a raw capture of
//! the robot standing in the mark on full white: its idle frames' raw
//! times are averaged per sensor ([`flat_field::mean_ticks`]); the dark
//! times come from the calibration the frames carry (every
//! [`LogFrame::CALIBRATION_EVERY`] frames), which must be one and the same
//! across the logs.

use crate::atomic;
use crate::robot::log_file;
use anyhow::{bail, Context, Result};
use shared::{Faults, FieldCalibration, LogFrame, RunMode};
use sim::base::gain_grid::GainGrid;
use sim::base::ranges;
use sim::base::vec2::Vec2;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::flat_field::{self, Stance};
use sim::sensors::photo::PhotoSensorConfig;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Columns and rows of marks, `COLUMNSxROWS` on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MarkGrid {
    /// Marks across.
    pub columns: usize,
    /// Marks down.
    pub rows: usize,
}

impl FromStr for MarkGrid {
    type Err = String;

    fn from_str(s: &str) -> Result<MarkGrid, String> {
        let sides = s.split_once(['x', 'X']).and_then(|(c, r)| {
            Some(MarkGrid {
                columns: c.trim().parse().ok()?,
                rows: r.trim().parse().ok()?,
            })
        });
        let grid = sides.ok_or_else(|| format!("{s:?} is not COLUMNSxROWS (for instance 4x3)"))?;
        GainGrid::uniform(grid.columns, grid.rows, 1.0)
            .validate()
            .map_err(|e| format!("{s:?}: {e}"))?;
        Ok(grid)
    }
}

impl fmt::Display for MarkGrid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.columns, self.rows)
    }
}

impl MarkGrid {
    /// Where its marks lie on `arena`, mm from the screen's top-left, row
    /// by row ([`GainGrid::point`]).
    pub fn points_mm(&self, arena: &ArenaSpec) -> Vec<[f64; 2]> {
        let grid = GainGrid::uniform(self.columns, self.rows, 1.0);
        let size = Vec2::new(arena.screen_mm[0], arena.screen_mm[1]);
        (0..self.columns * self.rows)
            .map(|k| {
                let p = grid.point(k, size);
                [p.x, p.y]
            })
            .collect()
    }
}

/// Reads and checks a gain file; errors name it.
pub fn read(path: &Path) -> Result<GainGrid> {
    let bytes = ranges::read_file(path, &ranges::SETTINGS_FILE)
        .with_context(|| format!("cannot read gain file {}", path.display()))?;
    let text = String::from_utf8(bytes)
        .with_context(|| format!("gain file {} is not UTF-8 text", path.display()))?;
    let grid: GainGrid =
        toml::from_str(&text).with_context(|| format!("gain file {}", path.display()))?;
    grid.validate()
        .with_context(|| format!("gain file {}", path.display()))?;
    Ok(grid)
}

/// Writes `grid` to `path` atomically, a comment line first.
pub fn write(path: &Path, grid: &GainGrid, comment: &str) -> Result<()> {
    let body = toml::to_string(grid).context("cannot encode the gain grid")?;
    atomic::write(path, format!("# {comment}\n{body}").as_bytes())
}

/// One mark's readings: each sensor's mean ticks, and the calibrations
/// its frames carried.
fn mark_readings(path: &Path, mark: usize) -> Result<([f64; 3], Vec<FieldCalibration>)> {
    let recording = log_file::read(path)?;
    let mut ticks = [vec![], vec![], vec![]];
    let mut calibrations = vec![];
    for entry in &recording.entries {
        let Some(frame) = entry.log_frame() else {
            continue;
        };
        if frame.faults.contains(Faults::NO_CALIBRATION) {
            bail!(
                "log {} (mark {mark}): the robot has no calibration; calibrate it first (button B, then `host display`'s calibration)",
                path.display()
            );
        }
        calibrations.extend(frame.calibration);
        if frame.mode == RunMode::Idle {
            for (sensor, t) in ticks.iter_mut().enumerate() {
                t.push(frame.raw_times[sensor]);
            }
        }
    }
    let means = ticks.map(|t| flat_field::mean_ticks(&t));
    match means {
        [Some(l), Some(m), Some(r)] => Ok(([l, m, r], calibrations)),
        _ => bail!(
            "log {} (mark {mark}) has no frame of the robot standing idle: record a few seconds with the robot in the mark",
            path.display()
        ),
    }
}

/// The panel's gain from one log per mark of `marks` (row by row from the
/// top-left), of a robot with the field sensors `photo` on `arena`.
pub fn measure(
    arena: &ArenaSpec,
    marks: MarkGrid,
    photo: &PhotoSensorConfig,
    logs: &[PathBuf],
) -> Result<GainGrid> {
    let expected = marks.columns * marks.rows;
    if logs.len() != expected {
        bail!(
            "{} logs given, the {marks} marks need {expected}: one per mark, row by row from the top-left",
            logs.len()
        );
    }
    let mut readings = Vec::with_capacity(expected);
    let mut calibration: Option<(FieldCalibration, &Path)> = None;
    for (k, path) in logs.iter().enumerate() {
        let (mark, seen) = mark_readings(path, k + 1)?;
        for c in seen {
            match calibration {
                Some((first, at)) if first != c => bail!(
                    "log {} carries another calibration than log {}: the robot was recalibrated between marks; measure every mark again",
                    path.display(),
                    at.display()
                ),
                Some(_) => {}
                None => calibration = Some((c, path)),
            }
        }
        readings.push(mark);
    }
    let Some((calibration, _)) = calibration else {
        bail!(
            "no log carries the robot's calibration (sent every {} frames): record one mark for longer",
            LogFrame::CALIBRATION_EVERY
        );
    };
    let stance = Stance::of(arena, photo);
    Ok(flat_field::fit(
        marks.columns,
        marks.rows,
        &readings,
        &calibration,
        &stance,
    )?)
}
