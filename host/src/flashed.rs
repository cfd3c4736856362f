//! What is flashed against what learned (`docs/flashed.md`): formations of
//! a learned table acting three ways, (a) learning on, (b) frozen with the
//! learner's own tie-breaking ([`FrozenLearner`]) and (c) as the exported
//! blob drives the robot ([`GreedyPolicy`]: each state's best actions,
//! picked by the robot's [`shared::ChoiceRng`]); and (c) of the blob as
//! exported before format version 2 (ties broken towards action 0), for
//! comparison. `host policy gap` measures and writes the JSON,
//! `host policy gap-table` renders the docs' table from it.

use crate::learn::FrozenLearner;
use crate::train::{TrainConfig, Trainer};
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use shared::PolicyBlob;
use sim::control::greedy::GreedyPolicy;
use sim::control::Controller;
use std::fmt::Write;
use std::path::Path;

/// One measured window: a learner's final window of training and its
/// exported table, or a shipped policy (then only (c)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapRow {
    /// What was measured (`annulus`, `L`, a policy file's name).
    pub label: String,
    /// The seed of the training run and of the worlds (b) and (c) ran in.
    pub seed: u64,
    /// Training steps in all (the window is their last ones); 0 for a
    /// shipped policy.
    pub trained_steps: u64,
    /// Steps of the window, and of each of (b) and (c).
    pub window: u64,
    /// (a) formations of the learner in the window; `None` for a policy.
    pub learning: Option<u64>,
    /// (b) formations of the final table frozen with the learner's
    /// tie-breaking; `None` for a policy (a blob holds no Q-values).
    pub frozen: Option<u64>,
    /// (c) formations of the exported blob as the robot acts on it.
    pub flashed: u64,
    /// (c) of the blob as exported before format version 2 (each tie
    /// broken towards action 0); `None` for a policy.
    pub flashed_lowest: Option<u64>,
    /// States of the exported blob with two or more best actions.
    pub tied_states: usize,
    /// The exported blob's states.
    pub states: usize,
}

/// Every row measured, with the commands that measured them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GapReport {
    /// The `host policy gap` command of each label.
    pub commands: Vec<(String, String)>,
    /// The rows, by label then seed.
    pub rows: Vec<GapRow>,
}

impl GapReport {
    /// Reads a report, or an empty one if `path` does not exist.
    pub fn load(path: &Path) -> Result<GapReport> {
        if !path.exists() {
            return Ok(GapReport::default());
        }
        let text = sim::base::ranges::read_text(path, &sim::base::ranges::SETTINGS_FILE)
            .with_context(|| format!("cannot read {}", path.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("{} is not a gap report", path.display()))
    }

    /// Replaces `label`'s rows and command with these.
    pub fn replace(&mut self, label: &str, command: String, rows: Vec<GapRow>) {
        self.rows.retain(|r| r.label != label);
        self.rows.extend(rows);
        self.commands.retain(|(l, _)| l != label);
        self.commands.push((label.to_string(), command));
    }

    /// Writes the report atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).context("cannot encode the report")?;
        crate::atomic::write(path, format!("{text}\n").as_bytes())
    }
}

/// Trains `config` for its steps and measures (a) over the last `window`
/// steps, then (b), (c) and (c) as before version 2 over `window` steps
/// each in a fresh world of the run's settings and seed.
pub fn measure_learner(label: &str, config: &TrainConfig, window: u64) -> Result<GapRow> {
    if window == 0 || window > config.steps {
        bail!(
            "--window {window} must be 1 to the training's --steps {}",
            config.steps
        );
    }
    let mut trainer = Trainer::start(config.clone(), None)?;
    trainer.run(config.steps - window);
    let before = trainer.totals().formations;
    trainer.run(window);
    let learning = trainer.totals().formations - before;
    let q = trainer.learner().table().clone();
    let frozen = FrozenLearner::new(q, config.learn.actions.clone(), config.learn.tie_tolerance);
    let frozen = formations(config, None, Box::new(frozen), window)?;
    let blob = trainer.policy()?;
    let lowest = trainer.greedy_policy()?;
    let flashed = formations(
        config,
        Some(&blob),
        Box::new(GreedyPolicy::new(blob.clone())),
        window,
    )?;
    let flashed_lowest = formations(
        config,
        Some(&lowest),
        Box::new(GreedyPolicy::new(lowest.clone())),
        window,
    )?;
    Ok(GapRow {
        label: label.to_string(),
        seed: config.world.seed,
        trained_steps: config.steps,
        window,
        learning: Some(learning),
        frozen: Some(frozen),
        flashed,
        flashed_lowest: Some(flashed_lowest),
        tied_states: tied_states(&blob),
        states: blob.hasher().num_states(),
    })
}

/// (c) of a policy blob over `window` steps in the world of `config`.
pub fn measure_policy(
    label: &str,
    blob: &PolicyBlob,
    config: &TrainConfig,
    window: u64,
) -> Result<GapRow> {
    let flashed = formations(
        config,
        Some(blob),
        Box::new(GreedyPolicy::new(blob.clone())),
        window,
    )?;
    Ok(GapRow {
        label: label.to_string(),
        seed: config.world.seed,
        trained_steps: 0,
        window,
        learning: None,
        frozen: None,
        flashed,
        flashed_lowest: None,
        tied_states: tied_states(blob),
        states: blob.hasher().num_states(),
    })
}

fn tied_states(blob: &PolicyBlob) -> usize {
    blob.sets()
        .masks()
        .filter(|(_, m)| m.count_ones() > 1)
        .count()
}

/// Formations of `controller` in `window` steps of a fresh world of
/// `config` (its seed), driven as `blob` says when there is one.
fn formations(
    config: &TrainConfig,
    blob: Option<&PolicyBlob>,
    mut controller: Box<dyn Controller>,
    window: u64,
) -> Result<u64> {
    let mut prepared = config.prepare()?;
    if let Some(blob) = blob {
        sim::scenario::drive_with(prepared.config_mut(), blob);
    }
    let mut sim = prepared.simulation(config.world.seed)?;
    sim.run(controller.as_mut(), window);
    Ok(sim.totals().formations)
}

/// Mean and sample standard deviation.
fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = if xs.len() > 1 {
        xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (mean, var.sqrt())
}

/// Windows of (b) with at least this many formations count towards the
/// ratio target (issue 29).
pub const MIN_FROZEN_FORMATIONS: u64 = 20;

/// The docs' tables: every row, then per label the means and the targets.
pub fn render(report: &GapReport) -> String {
    let per_m = |f: u64, w: u64| f as f64 * 1e6 / w as f64;
    let opt = |f: Option<u64>, w: u64| f.map_or("-".to_string(), |f| format!("{:.0}", per_m(f, w)));
    let mut out = String::new();
    let _ = writeln!(out, "Formations per million steps; (a) learning on, (b) the final table frozen with the learner's tie-breaking, (c) the exported blob as the robot acts on it (format version 2: ties sampled), (c, v1) the blob as exported before version 2 (ties broken towards action 0).\n");
    let _ = writeln!(
        out,
        "| what | seed | trained steps | window | (a) | (b) | (c) | (c, v1) | tied states |"
    );
    let _ = writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in &report.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {:.0} | {} | {} of {} |",
            r.label,
            r.seed,
            r.trained_steps,
            r.window,
            opt(r.learning, r.window),
            opt(r.frozen, r.window),
            per_m(r.flashed, r.window),
            opt(r.flashed_lowest, r.window),
            r.tied_states,
            r.states
        );
    }
    let _ = writeln!(out, "\nPer learner, over its seeds: means (sample standard deviation); (c)/(b) over the windows where (b) formed at least {MIN_FROZEN_FORMATIONS}; target (c)/(b) >= 0.9 and (b) >= (a) - sd(a).\n");
    let _ = writeln!(
        out,
        "| what | seeds | (a) | (b) | (c) | (c, v1) | (c)/(b) | (c, v1)/(b) | (b) >= (a) - sd(a) |"
    );
    let _ = writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut labels: Vec<&str> = Vec::new();
    for r in &report.rows {
        if r.learning.is_some() && !labels.contains(&r.label.as_str()) {
            labels.push(&r.label);
        }
    }
    for label in labels {
        let rows: Vec<&GapRow> = report
            .rows
            .iter()
            .filter(|r| r.label == label && r.learning.is_some())
            .collect();
        let series = |f: &dyn Fn(&GapRow) -> u64| -> Vec<f64> {
            rows.iter().map(|r| per_m(f(r), r.window)).collect()
        };
        let a = mean_sd(&series(&|r| r.learning.unwrap_or(0)));
        let b = mean_sd(&series(&|r| r.frozen.unwrap_or(0)));
        let c = mean_sd(&series(&|r| r.flashed));
        let c1 = mean_sd(&series(&|r| r.flashed_lowest.unwrap_or(0)));
        let eligible: Vec<&&GapRow> = rows
            .iter()
            .filter(|r| r.frozen.unwrap_or(0) >= MIN_FROZEN_FORMATIONS)
            .collect();
        let sum = |f: &dyn Fn(&GapRow) -> u64| eligible.iter().map(|r| f(r) as f64).sum::<f64>();
        let ratio = |num: f64| {
            let den = sum(&|r| r.frozen.unwrap_or(0));
            if den > 0.0 {
                format!("{:.2} ({} windows)", num / den, eligible.len())
            } else {
                "no window".into()
            }
        };
        let seeds: Vec<String> = rows.iter().map(|r| r.seed.to_string()).collect();
        let cell = |(m, s): (f64, f64)| format!("{m:.0} ({s:.0})");
        let _ = writeln!(
            out,
            "| {label} | {} | {} | {} | {} | {} | {} | {} | {} |",
            seeds.join(", "),
            cell(a),
            cell(b),
            cell(c),
            cell(c1),
            ratio(sum(&|r| r.flashed)),
            ratio(sum(&|r| r.flashed_lowest.unwrap_or(0))),
            if b.0 >= a.0 - a.1 { "yes" } else { "no" }
        );
    }
    let _ = writeln!(out, "\nCommands:\n");
    for (label, command) in &report.commands {
        let _ = writeln!(out, "- {label}: `{command}`");
    }
    out
}

/// The markers around the generated table in a doc.
const BEGIN: &str = "<!-- flashed:gap begin: generated by `host policy gap-table`; do not edit -->";
const END: &str = "<!-- flashed:gap end -->";

/// `doc` with the text between its markers replaced by `table`.
pub fn splice(doc: &str, table: &str) -> Result<String> {
    let (Some(b), Some(e)) = (doc.find(BEGIN), doc.find(END)) else {
        bail!("the doc has no {BEGIN} ... {END} markers");
    };
    if e < b {
        bail!("the doc's end marker comes before its begin marker");
    }
    Ok(format!("{}{BEGIN}\n{table}{}", &doc[..b], &doc[e..]))
}

/// The generated part of `doc`, between its markers.
pub fn generated_part(doc: &str) -> Option<&str> {
    let b = doc.find(BEGIN)? + BEGIN.len() + 1;
    let e = doc.find(END)?;
    doc.get(b..e)
}
