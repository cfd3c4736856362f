//! The report card: the result, orbital construction (OC) and the shipped
//! general table driving the same worlds, each as `host run` builds it
//! (the shape, the same puck count, the report's seed and steps), at the
//! run's noise (`default`) and twice it (`2x`); and the files that say
//! so.
//!
//! `DIR/NAME.report.json`: `pucks`, `hasher`, `seeds` (the report worlds'
//! seeds), `steps` (per world), `minutes` (the budget), `start` (`general`
//! or `oc`), `generations`, and per controller (`result`, `oc`,
//! `general`) the formations per million steps at `default` and `2x`;
//! `worlds` lists every run (`controller`, `noise`, `seed`, `formations`),
//! each of which `host run --controller ... --noise N --seed S --steps
//! STEPS --pucks P` reproduces. `DIR/NAME.report.md` is the same as a
//! table; `DIR/NAME.png` is the shape with its band outlined beside the
//! result's world as it first formed (or at the end of the first report
//! world, if it never did).

use crate::render::run_until_formed;
use crate::train::TrainConfig;
use anyhow::{Context, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use shared::PolicyBlob;
use sim::render::{draw, draw_ground, RenderOptions};
use sim::scenario::ControllerChoice;
use std::path::Path;

/// A controller of the report card.
#[derive(Clone, Debug)]
pub enum Contender {
    /// A policy blob, greedy.
    Table(Box<PolicyBlob>),
    /// Orbital construction.
    Orbital,
}

/// Formations per million steps at the run's noise and twice it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Levels {
    /// At the run's noise.
    pub default: f64,
    /// At twice it.
    #[serde(rename = "2x")]
    pub twice: f64,
}

/// One report world's run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldRun {
    /// `result`, `oc` or `general`.
    pub controller: String,
    /// The noise level.
    pub noise: f64,
    /// The world's seed.
    pub seed: u64,
    /// Formations in `steps` steps.
    pub formations: u64,
}

/// The report card.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Card {
    /// The shape.
    pub field: String,
    /// Pucks, the same for every controller.
    pub pucks: usize,
    /// The result's state hasher.
    pub hasher: String,
    /// The report worlds' seeds.
    pub seeds: Vec<u64>,
    /// Steps per report world.
    pub steps: u64,
    /// The budget, minutes.
    pub minutes: f64,
    /// The start: `general`, `oc` or `oc-role`.
    pub start: String,
    /// The search's generations.
    pub generations: u64,
    /// The result.
    pub result: Levels,
    /// Orbital construction.
    pub oc: Levels,
    /// The shipped general table.
    pub general: Levels,
    /// Every run.
    pub worlds: Vec<WorldRun>,
}

/// The formations of `contender` in the world `host run` builds from
/// `config` at `noise` and `seed`, in `steps` steps.
pub fn formations(
    config: &TrainConfig,
    contender: &Contender,
    noise: f64,
    seed: u64,
    steps: u64,
) -> Result<u64> {
    let mut world = config.clone();
    world.world.noise = noise;
    world.world.seed = seed;
    let mut scenario = world.scenario()?;
    let (mut sim, mut controller) = match contender {
        Contender::Table(blob) => scenario.build_with_policy(blob.as_ref().clone())?,
        Contender::Orbital => {
            scenario.controller = ControllerChoice::Orbital;
            scenario.build()?
        }
    };
    sim.run(controller.as_mut(), steps);
    Ok(sim.totals().formations)
}

/// Runs every contender (named) on every seed at the run's noise and twice
/// it, in parallel; the per-million figures in the order given.
pub fn evaluate(
    config: &TrainConfig,
    contenders: &[(&str, Contender)],
    seeds: &[u64],
    steps: u64,
) -> Result<(Vec<Levels>, Vec<WorldRun>)> {
    let noises = [config.world.noise, 2.0 * config.world.noise];
    let jobs: Vec<(usize, f64, u64)> = (0..contenders.len())
        .flat_map(|c| {
            noises
                .iter()
                .flat_map(move |&n| seeds.iter().map(move |&s| (c, n, s)))
        })
        .collect();
    let runs = jobs
        .par_iter()
        .map(|&(c, noise, seed)| {
            Ok(WorldRun {
                controller: contenders[c].0.to_string(),
                noise,
                seed,
                formations: formations(config, &contenders[c].1, noise, seed, steps)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let per_million = |name: &str, noise: f64| {
        let total: u64 = runs
            .iter()
            .filter(|r| r.controller == name && r.noise == noise)
            .map(|r| r.formations)
            .sum();
        total as f64 * 1e6 / (steps as f64 * seeds.len().max(1) as f64)
    };
    let levels = contenders
        .iter()
        .map(|(name, _)| Levels {
            default: per_million(name, noises[0]),
            twice: per_million(name, noises[1]),
        })
        .collect();
    Ok((levels, runs))
}

impl Card {
    /// The card as markdown.
    pub fn markdown(&self, name: &str) -> String {
        let mut md = format!(
            "# {name}: {field}\n\n{pucks} pucks, hasher {hasher}, started from {start}, {gens} generations \
             (budget {minutes} minutes). Formations per million steps on {n} worlds of {steps} steps \
             (seeds {seeds}), never scored on by the search.\n\n\
             | controller | default noise | 2x noise |\n|---|---:|---:|\n",
            field = self.field,
            pucks = self.pucks,
            hasher = self.hasher,
            start = self.start,
            gens = self.generations,
            minutes = self.minutes,
            n = self.seeds.len(),
            steps = self.steps,
            seeds = self
                .seeds
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
        );
        for (label, l) in [
            ("result", self.result),
            ("orbital construction", self.oc),
            ("general table", self.general),
        ] {
            md.push_str(&format!(
                "| {label} | {:.1} | {:.1} |\n",
                l.default, l.twice
            ));
        }
        md
    }

    /// Writes `DIR/NAME.report.json` and `DIR/NAME.report.md`.
    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let json = serde_json::to_vec_pretty(self).context("cannot encode the report")?;
        crate::atomic::write(&dir.join(format!("{name}.report.json")), &json)?;
        crate::atomic::write(
            &dir.join(format!("{name}.report.md")),
            self.markdown(name).as_bytes(),
        )
    }
}

/// Writes `path`: the shape with its band outlined, beside the result's
/// world of `seed` as it first formed in `steps` steps (or at their end).
pub fn write_picture(
    config: &TrainConfig,
    blob: &PolicyBlob,
    seed: u64,
    steps: u64,
    path: &Path,
) -> Result<()> {
    let mut world = config.clone();
    world.world.seed = seed;
    let (mut sim, mut controller) = world.scenario()?.build_with_policy(blob.clone())?;
    let options = RenderOptions {
        band: true,
        ..RenderOptions::default()
    };
    let shape = draw_ground(&sim, options);
    let (formed, _) = run_until_formed(&mut sim, controller.as_mut(), steps);
    let world = draw(formed.as_ref().unwrap_or(&sim), options);
    let gap = 16;
    let mut both = image::RgbImage::from_pixel(
        shape.width() + gap + world.width(),
        shape.height().max(world.height()),
        image::Rgb([255, 255, 255]),
    );
    image::imageops::replace(&mut both, &shape, 0, 0);
    image::imageops::replace(&mut both, &world, i64::from(shape.width() + gap), 0);
    crate::render::write_image(&both, path)
}
