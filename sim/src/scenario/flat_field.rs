//! Flat-field correction of a screen arena: the panel's brightness gain
//! measured with a robot's own field sensors, and the image that evens it
//! out (`host field gain` measures, `host display --gain` shows;
//! `docs/display.md`, "Flat-field correction").
//!
//! **Measurement.** The display shows full white with a mark at each
//! point of a `columns x rows` [`GainGrid`] (the centres of equal tiles of
//! the screen). The robot stands centred in each mark in turn, facing the
//! screen's top (its [`Stance`]), and logs its raw discharge times;
//! [`mean_ticks`] averages each sensor's. A photo-transistor's discharge
//! time `t` falls as the light on it rises (`sensors::photo`: `1/t` is
//! `1/t_dark` plus the light times `1/t_bright - 1/t_dark`), so the light
//! is `1/t - 1/t_dark` up to the sensor's own scale: `t` from the mean
//! ticks (`(ticks + 0.5) * RC_TICK_US` less the poll latency), `t_dark`
//! from the robot's calibration on the black screen (the panel's
//! unevenness scales its light, and black has none). The sensors sit on the skirt's edge, up to
//! 80 mm from the mark's centre, a fifth of a tile: [`fit`] finds the
//! grid's gains and each sensor's scale that give the lights read at the
//! sensors' own points, by alternating the two (each sensor's scale from
//! the gains; each point's gain times its mark's read over predicted
//! light), [`FIT_ROUNDS`] rounds.
//!
//! **Correction.** Where the panel's gain is `g(p)`, field value `v` shows
//! the light `v^LIGHT_GAMMA g(p)`. Showing `v s(p)` instead, with
//! [`value_scale`] `s(p) = (g_min / g(p))^(1 / LIGHT_GAMMA)`, makes it
//! `v^LIGHT_GAMMA g_min` everywhere: the panel as even as its dimmest
//! point, at the cost of that much of its brightest white.

use crate::base::gain_grid::{GainGrid, GainGridError};
use crate::base::vec2::Vec2;
use crate::config::SimConfig;
use crate::fields::ScalarField;
use crate::scenario::arena::ArenaSpec;
use crate::sensors::photo::{PhotoSensorConfig, PhotoSensors};
use shared::calibration::{LIGHT_GAMMA, RC_TICK_US, RC_TIMEOUT_TICKS};
use shared::FieldCalibration;
use std::fmt;

/// Share of a sensor's readings at a mark dropped at each end before
/// averaging (frames taken while the robot was set down or picked up).
const TRIM: f64 = 0.1;

/// Rounds of the fit's alternation (each point's gain depends mostly on
/// its own mark, so it settles within a few dozen).
pub const FIT_ROUNDS: usize = 100;

/// How a robot stood at the marks and read them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stance {
    /// Its left, mid and right sensors' offsets from its centre, facing
    /// the screen's top (`-y`), arena units.
    pub sensor_offsets: [Vec2; 3],
    /// The screen's size, arena units.
    pub size: Vec2,
    /// Its firmware's delay from a pin's fall to the timer read, us.
    pub poll_latency_us: f64,
}

impl Stance {
    /// A robot with the sensors `photo` on `arena`, facing the top.
    pub fn of(arena: &ArenaSpec, photo: &PhotoSensorConfig) -> Stance {
        let mut config = SimConfig::default();
        let white = ScalarField::new(2, 2, vec![1.0; 4]);
        if let Some(white) = white {
            arena.apply(&mut config, &white);
        }
        let top = Vec2::new(0.0, -1.0);
        Stance {
            sensor_offsets: PhotoSensors::new(photo, &config.world)
                .points()
                .map(|p| p.rotated(top)),
            size: arena.size(),
            poll_latency_us: photo.poll_latency_us,
        }
    }
}

/// Why a measurement gives no gain.
#[derive(Clone, Debug, PartialEq)]
pub enum FlatFieldError {
    /// The grid itself.
    Grid(GainGridError),
    /// Not one reading per mark.
    Marks {
        /// Marks of the grid.
        expected: usize,
        /// Readings given.
        found: usize,
    },
    /// A sensor at a mark read nothing, or nothing brighter than black.
    NotLit {
        /// The mark, numbered from 1 row by row.
        mark: usize,
        /// 0 left, 1 mid, 2 right.
        sensor: usize,
        /// Its mean ticks there.
        ticks: f64,
        /// Its calibration's ticks on black.
        dark: u16,
    },
}

impl fmt::Display for FlatFieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FlatFieldError::Grid(e) => write!(f, "gain grid: {e}"),
            FlatFieldError::Marks { expected, found } => write!(
                f,
                "{found} marks measured, the grid has {expected}: measure every mark"
            ),
            FlatFieldError::NotLit {
                mark,
                sensor,
                ticks,
                dark,
            } => write!(
                f,
                "mark {mark}: the {} sensor read {ticks:.1} ticks, no brighter than black \
                 ({dark} ticks, timeout {RC_TIMEOUT_TICKS}): was the screen white and the robot on it?",
                ["left", "mid", "right"][*sensor]
            ),
        }
    }
}

impl core::error::Error for FlatFieldError {}

/// The mean of `ticks` without the highest and lowest tenth; `None` when
/// empty.
pub fn mean_ticks(ticks: &[u16]) -> Option<f64> {
    let mut sorted = ticks.to_vec();
    sorted.sort_unstable();
    let cut = (sorted.len() as f64 * TRIM) as usize;
    let kept = sorted.get(cut..sorted.len() - cut)?;
    if kept.is_empty() {
        return None;
    }
    Some(kept.iter().map(|t| f64::from(*t)).sum::<f64>() / kept.len() as f64)
}

/// The panel's gain at the points of a `columns x rows` grid, normalised
/// to a mean of 1, from each mark's mean ticks of the three sensors (row
/// by row) on full white, the robot's `calibration` (its dark ticks) and
/// how it stood.
pub fn fit(
    columns: usize,
    rows: usize,
    marks: &[[f64; 3]],
    calibration: &FieldCalibration,
    stance: &Stance,
) -> Result<GainGrid, FlatFieldError> {
    let mut grid = GainGrid::uniform(columns, rows, 1.0);
    grid.validate().map_err(FlatFieldError::Grid)?;
    if marks.len() != columns * rows {
        return Err(FlatFieldError::Marks {
            expected: columns * rows,
            found: marks.len(),
        });
    }
    let time_us = |ticks: f64| (ticks + 0.5) * f64::from(RC_TICK_US) - stance.poll_latency_us;
    let mut lights = vec![[0.0; 3]; marks.len()];
    for (k, mark) in marks.iter().enumerate() {
        for (sensor, &ticks) in mark.iter().enumerate() {
            let dark = calibration.ranges[sensor].dark;
            let light = 1.0 / time_us(ticks) - 1.0 / time_us(f64::from(dark));
            if !(ticks < f64::from(RC_TIMEOUT_TICKS) && light > 0.0) {
                return Err(FlatFieldError::NotLit {
                    mark: k + 1,
                    sensor,
                    ticks,
                    dark,
                });
            }
            lights[k][sensor] = light;
        }
    }
    let at_sensors = |grid: &GainGrid| -> Vec<[f64; 3]> {
        (0..marks.len())
            .map(|k| {
                let centre = grid.point(k, stance.size);
                stance
                    .sensor_offsets
                    .map(|o| grid.at(centre + o, stance.size))
            })
            .collect()
    };
    for _ in 0..FIT_ROUNDS {
        let predicted = at_sensors(&grid);
        let scales: [f64; 3] = std::array::from_fn(|sensor| {
            lights.iter().map(|l| l[sensor]).sum::<f64>()
                / predicted.iter().map(|p| p[sensor]).sum::<f64>()
        });
        for (k, gain) in grid.gains.iter_mut().enumerate() {
            let read: f64 = (0..3).map(|i| lights[k][i] / scales[i]).sum();
            *gain *= read / predicted[k].iter().sum::<f64>();
        }
    }
    let mean = grid.gains.iter().sum::<f64>() / grid.gains.len() as f64;
    grid.gains.iter_mut().for_each(|g| *g /= mean);
    grid.validate().map_err(FlatFieldError::Grid)?;
    Ok(grid)
}

/// The factor on the field value at `p` of a screen of `size` that evens
/// out the panel's gain `grid`: `(g_min / g(p))^(1 / LIGHT_GAMMA)`, at most 1.
pub fn value_scale(grid: &GainGrid, p: Vec2, size: Vec2) -> f64 {
    (grid.min() / grid.at(p, size)).powf(1.0 / f64::from(LIGHT_GAMMA))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::noise::{self, Purpose};
    use crate::scenario::arena::FieldFit;
    use crate::sensors::photo::PhotoNoise;
    use crate::sensors::robot_noise::RobotNoise;

    /// What a robot standing in each mark of a 4 x 3 grid on full white
    /// reads over `frames` control periods, through the sensor model (its
    /// RC jitter, tick quantisation and poll latency) on a panel of gain
    /// `panel`; and its calibration.
    fn measure(
        panel: &GainGrid,
        noise: &RobotNoise,
        frames: u64,
    ) -> (Vec<[f64; 3]>, FieldCalibration) {
        let arena = ArenaSpec {
            fit: FieldFit::Stretch,
            ..ArenaSpec::tv75()
        };
        let white = ScalarField::new(2, 2, vec![1.0; 4]).expect("a 2 x 2 field");
        let mut config = SimConfig::default();
        arena.apply(&mut config, &white);
        let photo = PhotoSensors::new(&PhotoSensorConfig::default(), &config.world);
        let (layout, size) = (arena.field_layout(&white), arena.size());
        let marks = (0..12)
            .map(|k| {
                let mut ticks = [vec![], vec![], vec![]];
                for frame in 0..frames {
                    let mut rng = noise::stream(7, Purpose::Discharge, frame, k as u64);
                    let reading = photo.read(
                        panel.point(k, size),
                        Vec2::new(0.0, -1.0),
                        &white,
                        &layout,
                        Some(PhotoNoise {
                            noise,
                            grid: panel,
                            arena: size,
                            rng: &mut rng,
                        }),
                    );
                    for (sensor, t) in ticks.iter_mut().enumerate() {
                        t.push(reading.ticks[sensor]);
                    }
                }
                ticks.map(|t| mean_ticks(&t).expect("frames were read"))
            })
            .collect();
        (marks, photo.calibration())
    }

    fn stance() -> Stance {
        Stance::of(&ArenaSpec::tv75(), &PhotoSensorConfig::default())
    }

    /// The relative standard deviation of `f` over a 64 x 36 lattice of
    /// the screen.
    fn unevenness(f: impl Fn(Vec2) -> f64) -> f64 {
        let size = ArenaSpec::tv75().size();
        let values: Vec<f64> = (0..64 * 36)
            .map(|k| {
                let (i, j) = ((k % 64) as f64 + 0.5, (k / 64) as f64 + 0.5);
                f(Vec2::new(i * size.x / 64.0, j * size.y / 36.0))
            })
            .collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
        var.sqrt() / mean
    }

    #[test]
    fn measured_through_the_robots_own_sensors_the_correction_leaves_under_a_twentieth_of_the_panels_unevenness(
    ) {
        // the model's panel at twice the default unevenness, read with the
        // default RC jitter over 100 periods (2 s) per mark
        let noise = RobotNoise::randomised();
        let size = ArenaSpec::tv75().size();
        for seed in 1..=5 {
            let panel = noise.scaled(2.0).brightness_grid(seed, 0);
            let (marks, calibration) = measure(&panel, &noise, 100);
            let fitted = fit(4, 3, &marks, &calibration, &stance()).expect("every mark lit");
            let before = unevenness(|p| panel.at(p, size));
            // the light of full white once the display shows value_scale
            let after = unevenness(|p| {
                panel.at(p, size) * value_scale(&fitted, p, size).powf(f64::from(LIGHT_GAMMA))
            });
            assert!(
                after < 0.05 * before,
                "seed {seed}: unevenness {before:.4} before, {after:.4} after"
            );
        }
    }

    #[test]
    fn the_corrected_light_is_the_dimmest_points_everywhere() {
        let grid = RobotNoise::randomised().brightness_grid(3, 0);
        let size = ArenaSpec::tv75().size();
        for k in 0..200 {
            let p = Vec2::new(k as f64 * 1.3 % size.x, k as f64 * 0.7 % size.y);
            let s = value_scale(&grid, p, size);
            assert!(s <= 1.0);
            let light = s.powf(f64::from(LIGHT_GAMMA)) * grid.at(p, size);
            assert!((light - grid.min()).abs() < 1e-12);
        }
    }

    #[test]
    fn a_mark_that_reads_no_light_or_a_missing_mark_is_named() {
        let panel = GainGrid::uniform(4, 3, 1.0);
        let (mut marks, calibration) = measure(&panel, &RobotNoise::NONE, 3);
        let even = fit(4, 3, &marks, &calibration, &stance()).expect("every mark lit");
        assert!(even.gains.iter().all(|g| (g - 1.0).abs() < 1e-9));
        marks[4][1] = f64::from(RC_TIMEOUT_TICKS);
        let e = fit(4, 3, &marks, &calibration, &stance())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("mark 5: the mid sensor"), "{e}");
        let e = fit(4, 3, &marks[..11], &calibration, &stance()).unwrap_err();
        assert_eq!(
            e,
            FlatFieldError::Marks {
                expected: 12,
                found: 11
            }
        );
        assert!(fit(1, 3, &marks, &calibration, &stance()).is_err());
    }

    #[test]
    fn the_trimmed_mean_drops_a_tenth_at_each_end() {
        let mut ticks = vec![40u16; 18];
        ticks.extend([500, 1]);
        assert_eq!(mean_ticks(&ticks), Some(40.0));
        assert_eq!(mean_ticks(&[]), None);
        assert_eq!(mean_ticks(&[41, 42]), Some(41.5));
    }
}
