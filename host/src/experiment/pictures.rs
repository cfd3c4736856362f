//! Pictures of an experiment's arms: the scalar fields they run on (the
//! thesis' Figure 17) and the arena at moments of a re-run trial (Figures
//! 11 and 18), drawn by [`sim::render::draw`].

use super::plan::TrialPlan;
use super::spec::{ExperimentSpec, FigureSpec, Moment};
use super::trial::{Running, TrialResult};
use anyhow::{Context, Result};
use image::{Rgb, RgbImage};
use sim::fields::ScalarField;
use sim::render::{draw, RenderOptions};

/// A field's values as grey pixels, one per cell (0 black, 1 white).
pub fn field_picture(field: &ScalarField) -> RgbImage {
    RgbImage::from_fn(field.width() as u32, field.height() as u32, |x, y| {
        let v = (field.cell(i64::from(x), i64::from(y)) * 255.0).round() as u8;
        Rgb([v, v, v])
    })
}

/// The distinct fields of the figure's arms, in arm order, each captioned
/// with its source (`thesis:T`, `letter:I`, ...).
pub fn fields(spec: &ExperimentSpec, figure: &FigureSpec) -> Result<Vec<(String, RgbImage)>> {
    let mut sources = Vec::new();
    for arm in spec
        .arms
        .iter()
        .filter(|a| figure.arms.is_empty() || figure.arms.contains(&a.name))
    {
        if !sources.contains(&arm.config.world.field) {
            sources.push(arm.config.world.field.clone());
        }
    }
    sources
        .iter()
        .map(|s| Ok((s.to_string(), field_picture(&s.load()?))))
        .collect()
}

/// For each of the figure's arms, its trial with the earliest first
/// formation (the first trial if none formed) run again from its seed, and
/// the arena at each of the figure's moments, in the order they come.
pub fn snapshots(
    figure: &FigureSpec,
    plans: &[TrialPlan],
    results: &[TrialResult],
) -> Result<Vec<(String, RgbImage)>> {
    let mut pictures = Vec::new();
    for arm in &figure.arms {
        let trials: Vec<&TrialResult> = results.iter().filter(|r| &r.arm == arm).collect();
        let Some(trial) = trials.iter().min_by_key(|r| {
            (
                r.formation_steps.first().copied().unwrap_or(u64::MAX),
                r.trial,
            )
        }) else {
            continue;
        };
        let Some(plan) = plans
            .iter()
            .find(|p| &p.arm == arm && p.trial == trial.trial)
        else {
            continue;
        };
        let check = &plan.config.formation_check;
        // the world a check tested: the one after the step before the check's
        // (the episode resets within the check's step), or the previous check's
        let formed = trial
            .formation_steps
            .first()
            .map(|&s| s.saturating_sub(if check.stale { check.every } else { 1 }));
        let end = formed.unwrap_or(plan.config.steps);
        let mut shots: Vec<(u64, String)> = figure
            .moments
            .iter()
            .map(|moment| match (moment, formed) {
                (Moment::Start, _) => (0, format!("{arm}: start")),
                (Moment::Midway, _) => (end / 2, format!("{arm}: step {}", end / 2)),
                (Moment::Formed, Some(s)) => (s, format!("{arm}: formed (step {s})")),
                (Moment::Formed, None) => (end, format!("{arm}: no formation in {end} steps")),
            })
            .collect();
        shots.sort_by_key(|shot| shot.0);
        let mut running =
            Running::start(plan, None).with_context(|| format!("snapshot of arm {arm}"))?;
        let mut at = 0;
        for (step, caption) in shots {
            while at < step {
                running.step();
                at += 1;
            }
            pictures.push((
                caption,
                draw(
                    running.simulation(),
                    RenderOptions {
                        size: 600,
                        ..RenderOptions::default()
                    },
                ),
            ));
        }
    }
    Ok(pictures)
}
