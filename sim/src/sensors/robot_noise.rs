//! The robot sensor model's noise, for domain randomisation: the
//! photo-transistors' discharge-time jitter, the screen's uneven
//! brightness, and the camera's block jitter, missed and spurious blocks
//! and dropped frames. Without noise ([`RobotNoise::NONE`], the default)
//! the model is exactly the noiseless one. Every draw comes from
//! [`crate::base::noise`], a function of the world's seed, the episode or step
//! and the robot.

use crate::base::gain_grid::GainGrid;
use crate::base::noise::{self, Purpose, Stream};
use crate::base::ranges;
use crate::base::rounding::round_half_away_within;
use crate::config::validate::ConfigError;
use serde::{Deserialize, Serialize};
use shared::camera::{IMAGE_HEIGHT, IMAGE_WIDTH};
use shared::PixyBlock;

/// Columns and rows of the screen's brightness grid.
const BRIGHTNESS_GRID: (usize, usize) = (4, 3);

/// The sensor noise models; every field is optional in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotNoise {
    /// Standard deviation of each discharge time, relative to it.
    pub rc_jitter: f64,
    /// Standard deviation of the screen's brightness, relative to its
    /// mean, at the 4 x 3 points of a smooth gain drawn per episode
    /// (bilinear between them, [`GainGrid`]): an unevenly lit panel.
    pub brightness: f64,
    /// Standard deviation of each block's centre and size, pixels.
    pub block_jitter_px: f64,
    /// Probability that a block the camera should report is missed.
    pub block_miss: f64,
    /// Probability per frame of a spurious block (of a puck or a robot,
    /// anywhere in the image).
    pub spurious_block: f64,
    /// Probability that no new frame reaches the robot in a period (it
    /// uses the frame before, as the firmware does).
    pub frame_drop: f64,
}

impl Default for RobotNoise {
    /// [`RobotNoise::NONE`].
    fn default() -> RobotNoise {
        RobotNoise::NONE
    }
}

impl RobotNoise {
    /// No noise: the model's exact readings.
    pub const NONE: RobotNoise = RobotNoise {
        rc_jitter: 0.0,
        brightness: 0.0,
        block_jitter_px: 0.0,
        block_miss: 0.0,
        spurious_block: 0.0,
        frame_drop: 0.0,
    };

    /// The default noise (`--randomise`), each figure's source in
    /// `docs/robot-sensors.md`: discharge times +-1 %, the panel's
    /// brightness +-5 %, block edges +-1 pixel, 5 % of blocks missed, a
    /// spurious block in 2 % of frames, 5 % of periods without a new frame.
    pub fn randomised() -> RobotNoise {
        RobotNoise {
            rc_jitter: 0.01,
            brightness: 0.05,
            block_jitter_px: 1.0,
            block_miss: 0.05,
            spurious_block: 0.02,
            frame_drop: 0.05,
        }
    }

    /// This noise with every amount times `k` (probabilities capped at 1).
    pub fn scaled(&self, k: f64) -> RobotNoise {
        RobotNoise {
            rc_jitter: self.rc_jitter * k,
            brightness: self.brightness * k,
            block_jitter_px: self.block_jitter_px * k,
            block_miss: (self.block_miss * k).min(1.0),
            spurious_block: (self.spurious_block * k).min(1.0),
            frame_drop: (self.frame_drop * k).min(1.0),
        }
    }

    /// Checks every amount; the error names the setting.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ranges::RELATIVE_NOISE.check(self.rc_jitter)?;
        ranges::RELATIVE_NOISE.check_as("noise.brightness", self.brightness)?;
        ranges::IMAGE_PX.check_as("noise.block_jitter_px", self.block_jitter_px)?;
        for (name, value) in [
            ("noise.block_miss", self.block_miss),
            ("noise.spurious_block", self.spurious_block),
            ("noise.frame_drop", self.frame_drop),
        ] {
            ranges::PROBABILITY.check_as(name, value)?;
        }
        Ok(())
    }

    /// The screen's brightness gains of an episode at `BRIGHTNESS_GRID`
    /// points.
    pub(crate) fn brightness_grid(&self, seed: u64, episode: u64) -> GainGrid {
        let (columns, rows) = BRIGHTNESS_GRID;
        if self.brightness == 0.0 {
            return GainGrid::uniform(columns, rows, 1.0);
        }
        let mut rng = noise::stream(seed, Purpose::Brightness, episode, 0);
        GainGrid {
            columns,
            rows,
            gains: (0..columns * rows)
                .map(|_| 1.0 + self.brightness * noise::normal(&mut rng))
                .collect(),
        }
    }

    /// A discharge time with its jitter.
    pub(crate) fn jitter_discharge(&self, us: f64, rng: &mut Stream) -> f64 {
        if self.rc_jitter == 0.0 {
            us
        } else {
            us * (1.0 + self.rc_jitter * noise::normal(rng))
        }
    }

    /// A frame as the camera reports it with this noise: missed blocks
    /// dropped, the others jittered, maybe a spurious one (of signature
    /// `puck` or `robot`) at the end of its signature's blocks.
    pub(crate) fn perturb_frame(
        &self,
        frame: &mut Vec<PixyBlock>,
        puck: u16,
        robot: u16,
        rng: &mut Stream,
    ) {
        if self.block_miss > 0.0 {
            frame.retain(|_| !noise::chance(rng, self.block_miss));
        }
        if self.block_jitter_px > 0.0 {
            let jitter = |v: u16, limit: u16, rng: &mut Stream| {
                let moved = f64::from(v) + self.block_jitter_px * noise::normal(rng);
                round_half_away_within(moved, limit)
            };
            for b in frame.iter_mut() {
                b.x = jitter(b.x, IMAGE_WIDTH - 1, rng);
                b.y = jitter(b.y, IMAGE_HEIGHT - 1, rng);
                b.width = jitter(b.width, IMAGE_WIDTH, rng).max(1);
                b.height = jitter(b.height, IMAGE_HEIGHT, rng).max(1);
            }
        }
        if noise::chance(rng, self.spurious_block) {
            let signature = if noise::chance(rng, 0.5) { puck } else { robot };
            let block = PixyBlock {
                signature,
                x: (rng_unit(rng) * f64::from(IMAGE_WIDTH - 1)) as u16,
                y: (rng_unit(rng) * f64::from(IMAGE_HEIGHT - 1)) as u16,
                width: 4 + (rng_unit(rng) * 20.0) as u16,
                height: 4 + (rng_unit(rng) * 20.0) as u16,
                angle: 0,
            };
            // The Pixy sends signature 1's blocks, then 2's.
            let at = frame
                .iter()
                .position(|b| b.signature > signature)
                .unwrap_or(frame.len());
            frame.insert(at, block);
        }
    }
}

fn rng_unit(rng: &mut Stream) -> f64 {
    noise::symmetric(rng, 0.5) + 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_noise_changes_nothing() {
        let n = RobotNoise::NONE;
        let mut rng = noise::stream(1, Purpose::Camera, 0, 0);
        assert_eq!(n.jitter_discharge(321.5, &mut rng), 321.5);
        let blocks = vec![PixyBlock {
            signature: 1,
            x: 10,
            y: 20,
            width: 5,
            height: 6,
            angle: 0,
        }];
        let mut frame = blocks.clone();
        n.perturb_frame(&mut frame, 1, 2, &mut rng);
        assert_eq!(frame, blocks);
        assert!(n.brightness_grid(1, 3).gains.iter().all(|g| *g == 1.0));
    }

    #[test]
    fn the_brightness_gain_is_drawn_per_episode_at_its_grid_points() {
        let n = RobotNoise::randomised();
        let grid = n.brightness_grid(4, 0);
        assert_ne!(grid, n.brightness_grid(4, 1));
        assert_eq!(grid, n.brightness_grid(4, 0));
        assert_eq!((grid.columns, grid.rows), BRIGHTNESS_GRID);
        assert_eq!(grid.validate(), Ok(()));
    }

    #[test]
    fn jitter_misses_and_spurious_blocks_come_at_their_rates() {
        let n = RobotNoise::randomised().scaled(2.0);
        let mut rng = noise::stream(9, Purpose::Camera, 0, 0);
        let (mut kept, mut spurious, mut moved) = (0, 0, 0);
        let frames = 20_000;
        for _ in 0..frames {
            let mut frame = vec![PixyBlock {
                signature: 1,
                x: 100,
                y: 100,
                width: 10,
                height: 10,
                angle: 0,
            }];
            n.perturb_frame(&mut frame, 1, 2, &mut rng);
            kept += frame
                .iter()
                .filter(|b| b.width < 40 && b.x.abs_diff(100) < 15)
                .count();
            moved += frame.iter().filter(|b| b.x != 100).count();
            spurious +=
                usize::from(frame.len() > 1 || frame.iter().any(|b| b.x.abs_diff(100) >= 15));
        }
        let rate = |n: usize| n as f64 / frames as f64;
        assert!((rate(kept) - 0.9).abs() < 0.01, "kept {}", rate(kept));
        assert!(
            (rate(spurious) - 0.04).abs() < 0.01,
            "spurious {}",
            rate(spurious)
        );
        assert!(rate(moved) > 0.5, "2 pixels of jitter move most blocks");
        assert_eq!(n.scaled(100.0).block_miss, 1.0);
    }

    #[test]
    fn bad_amounts_are_named() {
        let bad = RobotNoise {
            frame_drop: 2.0,
            ..RobotNoise::NONE
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("noise.frame_drop"));
        assert!(RobotNoise::randomised().validate().is_ok());
    }
}
