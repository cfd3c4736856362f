//! `host render`'s files: a PNG of the world, or an animated GIF of an
//! episode, drawn by [`sim::render::draw`] and written atomically.

use anyhow::{Context, Result};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use sim::control::Controller;
use sim::render::{draw, RenderOptions};
use sim::sensors::SensorModel;
use sim::simulation::Simulation;
use std::path::Path;

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

/// Writes a PNG of the current world atomically.
pub fn write_png<S: SensorModel>(
    sim: &Simulation<S>,
    options: RenderOptions,
    path: &Path,
) -> Result<()> {
    let img = draw(sim, options);
    crate::atomic::write_with(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })
    .with_context(|| format!("cannot write image {}", path.display()))
}
