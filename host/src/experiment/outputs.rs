//! An experiment's reports: every trial as CSV and JSON, the markdown
//! table laid out like the thesis' with its numbers beside ours, and the
//! PNG figures. Every file is written atomically.

use super::figures;
use super::metric::Metric;
use super::pictures;
use super::plan::{plans, TrialPlan};
use super::spec::{ArmSpec, BandKind, ExperimentSpec, FigureKind, FigureSpec};
use super::trial::{TrialResult, BLOCK_STEPS};
use crate::report::chart::{self, Band, Labels, Scatter, Spread};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes every report into `dir`: [`write_reports`] and `trials.json`;
/// returns the paths.
pub fn write(
    spec: &ExperimentSpec,
    dir: &Path,
    results: &[TrialResult],
    scale: f64,
    seed: u64,
) -> Result<Vec<PathBuf>> {
    let path = dir.join("trials.json");
    crate::atomic::write(
        &path,
        &serde_json::to_vec_pretty(results).context("cannot encode the trials")?,
    )?;
    let mut written = vec![path];
    written.extend(write_reports(spec, dir, results, scale, seed)?);
    Ok(written)
}

/// Writes `trials.csv`, `table.md` and the figures into `dir` (what the
/// published results hold besides the trial files); returns the paths.
pub fn write_reports(
    spec: &ExperimentSpec,
    dir: &Path,
    results: &[TrialResult],
    scale: f64,
    seed: u64,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let path = dir.join("trials.csv");
    crate::atomic::write(&path, csv(spec, results).as_bytes())?;
    written.push(path);
    let path = dir.join("table.md");
    crate::atomic::write(&path, markdown(spec, results, scale, seed).as_bytes())?;
    written.push(path);
    let trials = results.iter().map(|r| r.trial + 1).max().unwrap_or(0);
    let plans = plans(spec, trials, scale, seed);
    for figure in &spec.figures {
        let path = dir.join(&figure.file);
        draw(spec, figure, results, &plans, &path)?;
        written.push(path);
    }
    Ok(written)
}

/// The trials of one arm.
fn of_arm(results: &[TrialResult], arm: &str) -> Vec<TrialResult> {
    results
        .iter()
        .filter(|r| r.arm == arm)
        .cloned()
        .collect::<Vec<_>>()
}

/// One line per trial.
pub fn csv(spec: &ExperimentSpec, results: &[TrialResult]) -> String {
    let mut out = String::from(
        "experiment,arm,row,column,trial,seed,steps,formations,stuck,first_formation,collisions_per_1000,states_visited,states_total,steps_per_second,seconds\n",
    );
    let opt = |v: Option<String>| v.unwrap_or_default();
    for r in results {
        let arm = spec.arm(&r.arm);
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{:.3},{},{},{:.0},{:.3}",
            field(&r.experiment),
            field(&r.arm),
            field(arm.map_or("", |a| a.row.as_str())),
            field(arm.map_or("", |a| a.column.as_str())),
            r.trial,
            r.seed,
            r.steps,
            r.formations,
            r.stuck,
            opt(r.formation_steps.first().map(u64::to_string)),
            r.collisions_per_1000,
            opt(r.states_visited.map(|v| v.to_string())),
            opt(r.states_total.map(|v| v.to_string())),
            r.steps_per_second,
            r.seconds
        );
    }
    out
}

/// A CSV field, quoted when it holds a comma or a quote.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Distinct values in first-appearance order.
fn distinct<'a>(items: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}

/// One figure of an arm over its trials (ratios over the arm's reference).
fn arm_value(
    spec: &ExperimentSpec,
    results: &[TrialResult],
    arm: &ArmSpec,
    m: Metric,
) -> figures::Value {
    let reference = spec.ratio_reference(arm).map(|r| of_arm(results, &r.name));
    figures::value(m, &of_arm(results, &arm.name), reference.as_deref())
}

/// The results table like the thesis', then every figure per arm.
pub fn markdown(spec: &ExperimentSpec, results: &[TrialResult], scale: f64, seed: u64) -> String {
    let mut md = format!("# {}\n\n", spec.title);
    if !spec.thesis.is_empty() {
        let _ = writeln!(md, "Reproduces the thesis' {}.\n", spec.thesis);
    }
    let trials = spec
        .arms
        .iter()
        .map(|a| results.iter().filter(|r| r.arm == a.name).count())
        .max()
        .unwrap_or(0);
    let _ = writeln!(
        md,
        "Ours: mean ± 95 % confidence half-width over {trials} trials per arm, scale {scale} of the thesis' step counts, experiment seed {seed}. Thesis: the published figure where there is one, \"–\" where it gives none.{}\n",
        if scale < 1.0 { " **Quick run: not comparable with the thesis' numbers.**" } else { "" }
    );
    md.push_str(&table(spec, results));
    md.push_str("\n## Every figure per arm\n\n");
    md.push_str(&every_figure(spec, results));
    md.push_str("\n## Figures\n\n");
    for f in &spec.figures {
        let _ = writeln!(md, "![{}]({})\n", title(spec, f), f.file);
    }
    md
}

/// The thesis-layout table (one line per row, one group of columns per
/// column, the thesis' figure beside each of ours) and its caption.
pub fn table(spec: &ExperimentSpec, results: &[TrialResult]) -> String {
    let t = &spec.table;
    let value = |arm: &ArmSpec, m: Metric| arm_value(spec, results, arm, m);
    let rows = distinct(spec.arms.iter().map(|a| a.row.as_str()));
    let columns = distinct(spec.arms.iter().map(|a| a.column.as_str()));
    let find = |row: &str, column: &str| {
        spec.arms
            .iter()
            .find(|a| a.row == row && a.column == column)
    };
    let mut md = String::new();

    // header
    let mut header = format!("| {} |", t.row_header);
    let mut rule = String::from("|---|");
    for column in &columns {
        for &m in &t.metrics {
            let label = match m {
                Metric::FormationsRatio if t.ratio_to.is_some() => {
                    format!("Formations / {}", t.ratio_to.as_deref().unwrap_or_default())
                }
                _ => m.label().to_string(),
            };
            let label = if column.is_empty() {
                label
            } else {
                format!("{column}: {label}")
            };
            let _ = write!(header, " {label} |");
            rule.push_str("---:|");
            if spec
                .arms
                .iter()
                .any(|a| a.column == *column && a.thesis.contains_key(&m))
            {
                header.push_str(" thesis |");
                rule.push_str("---:|");
            }
        }
    }
    let _ = writeln!(md, "{header}\n{rule}");
    for row in &rows {
        let _ = write!(md, "| {row} |");
        for column in &columns {
            let arm = find(row, column);
            for &m in &t.metrics {
                let ours = arm.map_or_else(|| "".to_string(), |a| value(a, m).cell());
                let _ = write!(md, " {ours} |");
                if spec
                    .arms
                    .iter()
                    .any(|a| a.column == *column && a.thesis.contains_key(&m))
                {
                    let thesis = arm
                        .and_then(|a| a.thesis.get(&m))
                        .map_or_else(|| "–".to_string(), |&v| figures::number(v));
                    let _ = write!(md, " {thesis} |");
                }
            }
        }
        md.push('\n');
    }
    if !t.caption.is_empty() {
        let _ = writeln!(md, "\n{}", t.caption);
    }
    md
}

/// Every figure of every arm, one line per arm.
pub fn every_figure(spec: &ExperimentSpec, results: &[TrialResult]) -> String {
    let mut md = String::new();
    let all = [
        Metric::Formations,
        Metric::FirstFormation,
        Metric::Stuck,
        Metric::StepsPerFormation,
        Metric::CollisionsPer1000,
        Metric::StatesVisited,
        Metric::StepsPerSecond,
    ];
    let _ = write!(md, "| Arm | Controller | Trials | Steps |");
    for m in all {
        let _ = write!(md, " {} |", m.label());
    }
    let _ = writeln!(md, "\n|---|---|---:|---:|{}", "---:|".repeat(all.len()));
    for arm in &spec.arms {
        let trials = of_arm(results, &arm.name);
        let steps = trials.first().map_or(0, |t| t.steps);
        let _ = write!(
            md,
            "| {} | {} | {} | {} |",
            arm.name,
            arm.controller.name(),
            trials.len(),
            steps
        );
        for m in all {
            let _ = write!(md, " {} |", arm_value(spec, results, arm, m).cell());
        }
        md.push('\n');
    }
    md
}

fn title(spec: &ExperimentSpec, f: &FigureSpec) -> String {
    f.title.clone().unwrap_or_else(|| match f.kind {
        FigureKind::Formations => format!("{}: formations over time", spec.title),
        FigureKind::Collisions => "Robot-robot collisions per 1000 steps".to_string(),
        FigureKind::Fields => "The scalar fields".to_string(),
        FigureKind::Snapshots => "The arena during a trial".to_string(),
    })
}

/// Draws one figure.
fn draw(
    spec: &ExperimentSpec,
    f: &FigureSpec,
    results: &[TrialResult],
    plans: &[TrialPlan],
    path: &Path,
) -> Result<()> {
    let arms: Vec<&ArmSpec> = if f.arms.is_empty() {
        spec.arms.iter().collect()
    } else {
        f.arms.iter().filter_map(|n| spec.arm(n)).collect()
    };
    let title = title(spec, f);
    match f.kind {
        FigureKind::Formations => {
            let bands: Vec<Band> = arms
                .iter()
                .map(|arm| {
                    let trials = of_arm(results, &arm.name);
                    let steps = trials.iter().map(|t| t.steps).max().unwrap_or(0);
                    let n = spec.sample_points;
                    let x: Vec<f64> = (0..n)
                        .map(|i| steps as f64 * i as f64 / (n - 1) as f64)
                        .collect();
                    let series = trials
                        .iter()
                        .map(|t| {
                            x.iter()
                                .map(|&x| {
                                    t.formation_steps.partition_point(|&s| s as f64 <= x) as f64
                                })
                                .collect()
                        })
                        .collect();
                    Band {
                        name: arm.name.clone(),
                        x,
                        trials: series,
                    }
                })
                .collect();
            let spread = match f.band {
                BandKind::Ci95 => Spread::Ci95,
                BandKind::MinMax => Spread::MinMax,
            };
            chart::mean_with_band(
                path,
                Labels {
                    title: &title,
                    x: "step",
                    y: "formations",
                },
                &bands,
                spread,
            )
        }
        FigureKind::Collisions => {
            let series: Vec<Scatter> = arms
                .iter()
                .map(|arm| {
                    let trials = of_arm(results, &arm.name);
                    let blocks = trials
                        .iter()
                        .map(|t| t.collisions_per_block.len())
                        .min()
                        .unwrap_or(0);
                    let points = (0..blocks)
                        .map(|b| {
                            let mean = trials
                                .iter()
                                .map(|t| t.collisions_per_block[b] as f64)
                                .sum::<f64>()
                                / trials.len() as f64;
                            (((b as u64 + 1) * BLOCK_STEPS) as f64, mean)
                        })
                        .collect();
                    Scatter {
                        name: arm.name.clone(),
                        points,
                    }
                })
                .collect();
            chart::points_with_trend(
                path,
                Labels {
                    title: &title,
                    x: "step",
                    y: "collisions per 1000 steps (mean over trials)",
                },
                &series,
            )
        }
        FigureKind::Fields => chart::tiles(path, &title, &pictures::fields(spec, f)?),
        FigureKind::Snapshots => {
            chart::tiles(path, &title, &pictures::snapshots(f, plans, results)?)
        }
    }
}
