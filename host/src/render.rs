//! `host render`'s files: a PNG of the world (after some steps, or at the
//! moment the shape first forms), or an animated GIF of an episode, drawn
//! by [`sim::render::draw`] and written atomically, and the line saying
//! what was drawn.

use anyhow::{Context, Result};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use sim::base::rng::SimRng;
use sim::control::{Controller, Perception};
use sim::episodes::{EpisodeEnd, EpisodeStart, StepOutcome};
use sim::render::{draw, RenderOptions};
use sim::sensors::SensorModel;
use sim::simulation::Simulation;
use sim::world::World;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

/// What a picture shows: the step it was drawn at, its world's Eval and
/// the formations so far (`host render` prints it after the file's name).
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn {
    /// Steps run when it was drawn.
    pub step: u64,
    /// Eval of the world drawn.
    pub eval: f64,
    /// Formations up to then (the one drawn included).
    pub formations: u64,
    /// With `--until-formed`: whether the shape formed in the steps given
    /// (the picture is then the world as it formed).
    pub formed: Option<bool>,
}

impl Drawn {
    /// The simulation's current world.
    pub fn now<S: SensorModel>(sim: &Simulation<S>) -> Drawn {
        Drawn {
            step: sim.totals().steps,
            eval: sim.eval(),
            formations: sim.totals().formations,
            formed: None,
        }
    }
}

impl fmt::Display for Drawn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.formed {
            Some(true) => write!(f, "the shape formed at step {}", self.step)?,
            Some(false) => write!(
                f,
                "no formation in {} steps; the world at the end",
                self.step
            )?,
            None => write!(f, "step {}", self.step)?,
        }
        write!(
            f,
            ", Eval {:.3}, formations so far {}",
            self.eval, self.formations
        )
    }
}

/// Drives a controller and keeps the world as it was when an episode
/// first formed (a formed episode is reset in the same step).
struct UntilFormed<'a, C: ?Sized> {
    inner: &'a mut C,
    formed: Option<World>,
}

impl<C: Controller + ?Sized> Controller for UntilFormed<'_, C> {
    fn decide(&mut self, perception: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        self.inner.decide(perception, turns, rng)
    }

    fn wants_eval_every_step(&self) -> bool {
        self.inner.wants_eval_every_step()
    }

    fn episode_start(&mut self, start: &EpisodeStart<'_>) {
        self.inner.episode_start(start)
    }

    fn observe(&mut self, outcome: &StepOutcome<'_>) {
        if outcome.end == Some(EpisodeEnd::Formed) && self.formed.is_none() {
            self.formed = Some(outcome.world.clone());
        }
        self.inner.observe(outcome)
    }
}

/// Runs at most `steps` steps, stopping when the shape first forms;
/// returns the simulation to draw: the world as it formed (before the
/// episode's reset), or `sim` itself at the end if it never did.
pub fn run_until_formed<S: SensorModel + Clone, C: Controller + ?Sized>(
    sim: &mut Simulation<S>,
    controller: &mut C,
    steps: u64,
) -> (Option<Simulation<S>>, Drawn) {
    let mut watching = UntilFormed {
        inner: controller,
        formed: None,
    };
    for _ in 0..steps {
        sim.step(&mut watching);
        if watching.formed.is_some() {
            break;
        }
    }
    let Some(world) = watching.formed else {
        let drawn = Drawn {
            formed: Some(false),
            ..Drawn::now(sim)
        };
        return (None, drawn);
    };
    let mut state = sim.snapshot();
    state.world = world;
    // sensed again from the formed world
    state.readings.clear();
    let field = Arc::new(sim.field().clone());
    let formed = Simulation::resume(state, field, sim.sensors().clone());
    let drawn = Drawn {
        formed: Some(true),
        ..Drawn::now(&formed)
    };
    (Some(formed), drawn)
}

/// Runs `steps` steps and writes an animated GIF with a frame every
/// `every` steps (the first frame is the starting world).
pub fn animate<S: SensorModel, C: Controller + ?Sized>(
    sim: &mut Simulation<S>,
    controller: &mut C,
    steps: u64,
    every: u64,
    options: RenderOptions,
    path: &Path,
) -> Result<()> {
    anyhow::ensure!(every > 0, "--every must be at least 1");
    crate::atomic::write_with(path, |w| {
        let mut encoder = GifEncoder::new_with_speed(w, 10);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(std::io::Error::other)?;
        let delay = Delay::from_numer_denom_ms(100, 1);
        let frame = |sim: &Simulation<S>| {
            let rgba: RgbaImage = image::DynamicImage::ImageRgb8(draw(sim, options)).into_rgba8();
            Frame::from_parts(rgba, 0, 0, delay)
        };
        encoder
            .encode_frame(frame(sim))
            .map_err(std::io::Error::other)?;
        for step in 1..=steps {
            sim.step(controller);
            if step % every == 0 {
                encoder
                    .encode_frame(frame(sim))
                    .map_err(std::io::Error::other)?;
            }
        }
        Ok(())
    })
    .with_context(|| format!("cannot write animation {}", path.display()))
}

/// Writes a PNG of the current world atomically; returns its width and
/// height.
pub fn write_png<S: SensorModel>(
    sim: &Simulation<S>,
    options: RenderOptions,
    path: &Path,
) -> Result<(u32, u32)> {
    let img = draw(sim, options);
    write_image(&img, path)?;
    Ok(img.dimensions())
}

/// Writes an image as a PNG atomically.
pub fn write_image(img: &image::RgbImage, path: &Path) -> Result<()> {
    crate::atomic::write_with(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })
    .with_context(|| format!("cannot write image {}", path.display()))
}
