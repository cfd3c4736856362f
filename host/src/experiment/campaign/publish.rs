//! A campaign's published results and the page they render.
//!
//! A publish stage (`dir = "policy-search"`, under the docs directory)
//! copies every stage's table and search log and each evaluation's JSON
//! lines into `<docs>/<dir>/runs/`, and writes `<docs>/<dir>/results.json`:
//! `shapes` (field -> controller label -> `policy`, `seeds`, `formations`,
//! `steps_per_seed`, `per_million`) from the first of its `evaluations`,
//! `shapes_2x` the same from the second (twice the noise), and `searches`
//! (per search log: `name`, `field` (its fields joined by " + "), `sensors`,
//! `noise` (its levels joined by " + "), `hasher`, `start`, `generations`,
//! `steps`, `validation_worlds`, `validation_steps`, `start_validation`,
//! `result_validation`). The page `<docs>/<dir>.md` has its tables,
//! rendered from `results.json` by [`tables`], between the lines
//! `<!-- results:begin -->` and `<!-- results:end -->`; `host experiment
//! report` renders them (and `--check` fails when they differ).

use super::file::{Campaign, Publication, Stage, Work};
use anyhow::{bail, Context, Result};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// The lines around a page's rendered tables.
const BEGIN: &str = "<!-- results:begin -->";
/// The line after them.
const END: &str = "<!-- results:end -->";
/// How the tables name orbital construction.
const OC: &str = "orbital construction";
/// Where campaign files are, beside the docs directory.
const CAMPAIGNS: &str = "experiments/campaigns";

impl Publication {
    /// Copies the campaign's outputs in `out` into `docs/<dir>/runs/` and
    /// writes `docs/<dir>/results.json` and the page's tables; returns the
    /// files written.
    pub fn publish(&self, campaign: &Campaign, out: &Path) -> Result<Vec<PathBuf>> {
        let docs = Path::new("docs");
        let dir = docs.join(&self.dir);
        let runs = dir.join("runs");
        crate::atomic::check_writable(&runs)?;
        let mut written = Vec::new();
        let copy = |from: PathBuf, written: &mut Vec<PathBuf>| -> Result<()> {
            if let Some(name) = from.file_name().filter(|_| from.exists()) {
                let to = runs.join(name);
                let bytes = std::fs::read(&from)
                    .with_context(|| format!("cannot read {}", from.display()))?;
                crate::atomic::write(&to, &bytes)?;
                written.push(to);
            }
            Ok(())
        };
        for stage in &campaign.stages {
            let file = |suffix: &str| out.join(format!("{}{suffix}", stage.name));
            match stage.work {
                Work::Search { .. } => {
                    copy(file(".policy"), &mut written)?;
                    copy(file(".search.json"), &mut written)?;
                }
                Work::Train { .. } => copy(file(".policy"), &mut written)?,
                Work::Evaluate(_) if self.evaluations.contains(&stage.name) => {
                    copy(file(".jsonl"), &mut written)?
                }
                Work::Evaluate(_) | Work::Publish(_) => {}
            }
        }
        let results = self.results(campaign, out)?;
        let path = dir.join("results.json");
        crate::atomic::write(&path, &json_text(&results)?)?;
        written.push(path);
        written.push(self.write_page(docs, &results)?);
        Ok(written)
    }

    /// The results of the campaign's outputs in `out`.
    fn results(&self, campaign: &Campaign, out: &Path) -> Result<Value> {
        let evaluation = |i: usize| -> Result<Value> {
            match self.evaluations.get(i) {
                Some(e) => evaluation(campaign, &out.join(format!("{e}.jsonl"))),
                None => Ok(json!({})),
            }
        };
        let mut logs: Vec<&Stage> = campaign
            .stages
            .iter()
            .filter(|s| matches!(s.work, Work::Search { .. }))
            .collect();
        logs.sort_by_key(|s| format!("{}.search.json", s.name));
        let mut searches = Vec::new();
        for stage in logs {
            let path = out.join(format!("{}.search.json", stage.name));
            if path.exists() {
                searches.push(search_row(&stage.name, &path)?);
            }
        }
        Ok(json!({
            "command": format!("host experiment {CAMPAIGNS}/{}.toml", campaign.name),
            "shapes": evaluation(0)?,
            "shapes_2x": evaluation(1)?,
            "searches": searches,
        }))
    }

    /// The page with the tables of `results`.
    fn page(&self, docs: &Path, results: &Value) -> Result<(PathBuf, String)> {
        let path = docs.join(format!("{}.md", self.dir.display()));
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let (head, rest) = text
            .split_once(BEGIN)
            .with_context(|| format!("{}: no line {BEGIN}", path.display()))?;
        let (_, tail) = rest
            .split_once(END)
            .with_context(|| format!("{}: no line {END}", path.display()))?;
        let rendered = format!("{head}{BEGIN}\n{}\n{END}{tail}", tables(self, results)?);
        Ok((path, rendered))
    }

    /// Writes the page's tables from `results`; returns the page.
    fn write_page(&self, docs: &Path, results: &Value) -> Result<PathBuf> {
        let (path, text) = self.page(docs, results)?;
        crate::atomic::write(&path, text.as_bytes())?;
        Ok(path)
    }

    /// The published results.
    fn published(&self, docs: &Path) -> Result<Value> {
        let path = docs.join(&self.dir).join("results.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
    }
}

/// `value` as the results file holds it: one space an indent, keys sorted.
fn json_text(value: &Value) -> Result<Vec<u8>> {
    use serde::Serialize;
    let mut bytes = Vec::new();
    let formatter = serde_json::ser::PrettyFormatter::with_indent(b" ");
    let mut serializer = serde_json::Serializer::with_formatter(&mut bytes, formatter);
    value
        .serialize(&mut serializer)
        .context("cannot encode the results")?;
    bytes.push(b'\n');
    Ok(bytes)
}

/// An evaluation's lines by field and controller label, each with its
/// formations per million steps.
fn evaluation(campaign: &Campaign, path: &Path) -> Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut shapes = Map::new();
    for (i, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let r: Value = serde_json::from_str(line)
            .with_context(|| format!("{} line {}: not JSON", path.display(), i + 1))?;
        let field = r["field"].as_str().unwrap_or_default().to_string();
        let controller = r["controller"].as_str().unwrap_or_default();
        let label = label_of(campaign, controller);
        let shape = shapes
            .entry(field)
            .or_insert_with(|| json!({}))
            .as_object_mut()
            .context("a shape")?;
        let c = shape
            .entry(label)
            .or_insert_with(|| json!({"policy": controller, "seeds": [], "formations": []}));
        push(c, "seeds", r["seed"].clone())?;
        push(c, "formations", r["formations"].clone())?;
        c["steps_per_seed"] = r["steps"].clone();
    }
    for shape in shapes.values_mut() {
        for c in shape.as_object_mut().context("a shape")?.values_mut() {
            let per_million = per_million(c);
            c["per_million"] = json!((per_million * 10.0).round() / 10.0);
        }
    }
    Ok(Value::Object(shapes))
}

/// Appends `v` to the array `c[key]`.
fn push(c: &mut Value, key: &str, v: Value) -> Result<()> {
    c[key].as_array_mut().context(key.to_string())?.push(v);
    Ok(())
}

/// Formations per million steps of an evaluation's controller.
fn per_million(c: &Value) -> f64 {
    let formations: Vec<f64> = c["formations"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default();
    let steps = c["steps_per_seed"].as_f64().unwrap_or(1.0);
    formations.iter().sum::<f64>() * 1e6 / (steps * formations.len().max(1) as f64)
}

/// How the tables name a controller: OC, or its stage's label.
fn label_of(campaign: &Campaign, controller: &str) -> String {
    if controller == "oc" {
        return OC.to_string();
    }
    let run = run_of(controller);
    campaign
        .stage(&run)
        .map_or(run.clone(), |s| s.label.clone())
}

/// The run a controller's table came from (its file's stem).
fn run_of(controller: &str) -> String {
    Path::new(controller)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A search log's row of the searches table.
fn search_row(name: &str, path: &Path) -> Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let log: Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let strings = |v: &Value| -> Vec<String> {
        v.as_array()
            .map(|a| a.iter().map(value_text).collect())
            .unwrap_or_default()
    };
    let mut fields = vec![value_text(&log["world"]["field"])];
    fields.extend(strings(&log["search"]["also_field"]));
    let mut noises = vec![value_text(&log["world"]["noise"])];
    noises.extend(strings(&log["search"]["also_noise"]));
    let formations = |s: &Value| s.get("formations").cloned().unwrap_or_else(|| s.clone());
    Ok(json!({
        "name": name,
        "field": fields.join(" + "),
        "sensors": log["world"]["sensors"],
        "noise": noises.join(" + "),
        "hasher": log["world"]["learn"]["hasher"],
        "start": log["search"]["start"],
        "generations": log["generations"].as_array().map_or(0, Vec::len),
        "steps": log["steps"],
        "validation_worlds": log["validation_seeds"].as_array().map_or(0, Vec::len),
        "validation_steps": log["search"]["validation_steps"],
        "start_validation": formations(&log["start_validation"]),
        "result_validation": formations(&log["result_validation"]),
    }))
}

/// A string as itself, a number as the shortest text that reads back.
fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), |f| f.to_string()),
        other => other.to_string(),
    }
}

/// `x` with `decimals` decimals and commas between thousands.
fn grouped(x: f64, decimals: usize) -> String {
    let text = format!("{x:.decimals$}");
    let (sign, text) = text
        .strip_prefix('-')
        .map_or(("", text.as_str()), |t| ("-", t));
    let (int, frac) = text.split_once('.').map_or((text, ""), |(i, f)| (i, f));
    let mut out = String::new();
    for (i, ch) in int.chars().enumerate() {
        if i > 0 && (int.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    if frac.is_empty() {
        format!("{sign}{out}")
    } else {
        format!("{sign}{out}.{frac}")
    }
}

/// A controller's figure.
fn pm(c: &Value) -> f64 {
    c["per_million"].as_f64().unwrap_or(0.0)
}

/// The tables of a results page: every controller per field beside OC, the
/// targets, the general tables ranked on the fields they were searched on
/// and then on the report's other fields (and at twice the noise), and the
/// searches.
pub fn tables(publication: &Publication, results: &Value) -> Result<String> {
    let empty = Map::new();
    let shapes = results["shapes"].as_object().unwrap_or(&empty);
    let is_general = |c: &Value| {
        publication
            .general
            .contains(&run_of(c["policy"].as_str().unwrap_or_default()))
    };
    let oc_of = |shape: &Map<String, Value>| shape.get(OC).map(pm);
    let mut lines: Vec<String> = vec![
        "| shape | controller | formations per million steps | / OC |".into(),
        "|---|---|---:|---:|".into(),
    ];
    for (field, shape) in shapes {
        let shape = shape.as_object().unwrap_or(&empty);
        let oc = oc_of(shape).filter(|&oc| oc != 0.0);
        let mut rows: Vec<(&String, &Value)> = shape.iter().collect();
        rows.sort_by_key(|(name, _)| (name.as_str() != OC, name.as_str()));
        for (name, c) in rows {
            let ratio = oc.map_or("-".into(), |oc| format!("{:.2}", pm(c) / oc));
            lines.push(format!(
                "| {field} | {name} | {} | {ratio} |",
                grouped(pm(c), 1)
            ));
        }
    }
    lines.extend([
        String::new(),
        "| target | figure | measured | met |".into(),
        "|---|---|---:|---|".into(),
    ]);
    let t = &publication.targets;
    if let Some(shape) = shapes.get(&t.ratio_field).and_then(Value::as_object) {
        let learned: Vec<(&String, f64)> = shape
            .iter()
            .filter(|(n, _)| n.as_str() != OC)
            .map(|(n, c)| (n, pm(c)))
            .collect();
        let best = learned
            .iter()
            .fold(None, |best: Option<(&String, f64)>, &(n, v)| match best {
                Some((_, b)) if b >= v => best,
                _ => Some((n, v)),
            });
        if let (Some(oc), Some((n, best))) = (oc_of(shape).filter(|&oc| oc != 0.0), best) {
            lines.push(format!(
                "| {}: a learned policy >= {}x OC | best ({n}) / OC | {:.3} | {} |",
                t.ratio_field,
                t.ratio,
                best / oc,
                if best >= t.ratio * oc { "yes" } else { "no" }
            ));
        }
    }
    let own_counts = |shape: &Map<String, Value>| -> Vec<f64> {
        shape
            .iter()
            .filter(|(n, c)| n.as_str() != OC && !is_general(c))
            .map(|(_, c)| pm(c))
            .collect()
    };
    for (field, shape) in shapes {
        if *field == t.ratio_field || !publication.report_fields.contains(field) {
            continue;
        }
        let shape = shape.as_object().unwrap_or(&empty);
        let oc = oc_of(shape).unwrap_or(0.0);
        let learned = own_counts(shape);
        let Some(found) = learned.iter().copied().reduce(f64::max) else {
            continue;
        };
        let mut need = t.least;
        if oc >= t.oc_at_least {
            need = need.max(oc);
        }
        if let Some(times) = t.times_oc.get(field) {
            need = need.max(times * oc);
        }
        lines.push(format!(
            "| {field}: >= {} per million | best learned / million steps | {} | {} |",
            grouped(need, 1),
            grouped(found, 1),
            if found >= need { "yes" } else { "no" }
        ));
    }
    // the fields the general tables were searched on, in order of mention
    let searches = results["searches"].as_array().cloned().unwrap_or_default();
    let mut searched_on: Vec<String> = Vec::new();
    for s in &searches {
        if publication
            .general
            .contains(&s["name"].as_str().unwrap_or_default().to_string())
        {
            for f in s["field"].as_str().unwrap_or_default().split(" + ") {
                if !searched_on.iter().any(|g| g == f) {
                    searched_on.push(f.to_string());
                }
            }
        }
    }
    let ranked = general_ranking(results, &searched_on, "shapes", &is_general);
    if let Some((first, _, _)) = ranked.first() {
        lines.push(String::new());
        lines.push(format!(
            "| general table | {} | sum of ln(1 + per million) |",
            searched_on.join(" | ")
        ));
        lines.push(format!("|---|{}", "---:|".repeat(searched_on.len() + 1)));
        for (run, counts, measure) in &ranked {
            let cells: Vec<String> = counts.iter().map(|&c| grouped(c, 1)).collect();
            lines.push(format!("| {run} | {} | {measure:.2} |", cells.join(" | ")));
        }
        let held_out: Vec<&String> = publication
            .report_fields
            .iter()
            .filter(|f| !searched_on.contains(f) && shapes.contains_key(*f))
            .collect();
        let own: Vec<f64> = held_out
            .iter()
            .map(|f| {
                let shape = shapes[*f].as_object().unwrap_or(&empty);
                own_counts(shape)
                    .into_iter()
                    .reduce(f64::max)
                    .unwrap_or(0.0)
            })
            .collect();
        let heads: Vec<String> = held_out
            .iter()
            .zip(&own)
            .map(|(f, o)| format!("{f} (its own table {})", grouped(*o, 1)))
            .collect();
        lines.push(String::new());
        lines.push(format!(
            "| general table, on shapes no general search saw | {} |",
            heads.join(" | ")
        ));
        lines.push(format!("|---|{}", "---:|".repeat(held_out.len())));
        for (run, _, _) in &ranked {
            let cells: Vec<String> = held_out
                .iter()
                .zip(&own)
                .map(|(f, &o)| match count_of(results, "shapes", f, run) {
                    None => "-".into(),
                    Some(c) if o != 0.0 => format!("{} ({:.2})", grouped(pm(c), 1), pm(c) / o),
                    Some(c) => grouped(pm(c), 1),
                })
                .collect();
            lines.push(format!("| {run} | {} |", cells.join(" | ")));
        }
        let twice = general_ranking(results, &searched_on, "shapes_2x", &is_general);
        if !twice.is_empty() {
            let mut both: Vec<(&String, f64, f64)> = ranked
                .iter()
                .filter_map(|(run, _, m)| {
                    twice
                        .iter()
                        .find(|(r, _, _)| r == run)
                        .map(|(_, _, m2)| (run, *m, *m2))
                })
                .collect();
            both.sort_by(|a, b| (b.1 + b.2).total_cmp(&(a.1 + a.2)));
            let heads: Vec<String> = held_out
                .iter()
                .map(|f| format!("{f}: 2x / default"))
                .collect();
            lines.push(String::new());
            lines.push(format!(
                "| general table | sum at the default noise | sum at twice it | both | {} |",
                heads.join(" | ")
            ));
            lines.push(format!("|---|{}", "---:|".repeat(3 + held_out.len())));
            for (run, default, twice) in &both {
                let cells: Vec<String> = held_out
                    .iter()
                    .map(|f| {
                        match (
                            count_of(results, "shapes", f, run),
                            count_of(results, "shapes_2x", f, run),
                        ) {
                            (Some(c1), Some(c2)) if pm(c1) != 0.0 => {
                                format!("{:.2}", pm(c2) / pm(c1))
                            }
                            _ => "-".into(),
                        }
                    })
                    .collect();
                lines.push(format!(
                    "| {run} | {default:.2} | {twice:.2} | {:.2} | {} |",
                    default + twice,
                    cells.join(" | ")
                ));
            }
            if let Some((best, _, _)) = both.first() {
                lines.push(String::new());
                lines.push(format!("Ranked by the sum at both noise levels, the first is `{best}`; by the default noise alone, `{first}`."));
            }
        }
    }
    lines.extend([
        String::new(),
        "| search | field | senses | noise | hasher | start | generations | steps | validation: start | validation: result | result / start |".into(),
        "|---|---|---|---|---|---|---:|---:|---:|---:|---:|".into(),
    ]);
    for s in &searches {
        let (start, result) = (
            s["start_validation"].as_f64().unwrap_or(0.0),
            s["result_validation"].as_f64().unwrap_or(0.0),
        );
        let ratio = if start != 0.0 {
            format!("{:.2}", result / start)
        } else {
            "-".into()
        };
        lines.push(format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {ratio} |",
            value_text(&s["name"]),
            value_text(&s["field"]),
            value_text(&s["sensors"]),
            value_text(&s["noise"]),
            value_text(&s["hasher"]),
            value_text(&s["start"]),
            value_text(&s["generations"]),
            grouped(s["steps"].as_f64().unwrap_or(0.0), 0),
            value_text(&s["start_validation"]),
            value_text(&s["result_validation"]),
        ));
    }
    Ok(lines.join("\n"))
}

/// A run's controller on `field` in `evaluation` (`shapes` or `shapes_2x`).
fn count_of<'a>(results: &'a Value, evaluation: &str, field: &str, run: &str) -> Option<&'a Value> {
    results[evaluation][field]
        .as_object()?
        .values()
        .find(|c| run_of(c["policy"].as_str().unwrap_or_default()) == run)
}

/// The general tables on `fields`, best first by the search's own measure:
/// the sum over the fields of ln(1 + formations per million steps); only
/// tables measured on every field, equal measures in order of mention.
fn general_ranking(
    results: &Value,
    fields: &[String],
    evaluation: &str,
    is_general: &dyn Fn(&Value) -> bool,
) -> Vec<(String, Vec<f64>, f64)> {
    let mut runs: Vec<(String, Vec<(String, f64)>)> = Vec::new();
    for field in fields {
        let Some(shape) = results[evaluation][field].as_object() else {
            continue;
        };
        for c in shape.values().filter(|c| is_general(c)) {
            let run = run_of(c["policy"].as_str().unwrap_or_default());
            let i = match runs.iter().position(|(r, _)| *r == run) {
                Some(i) => i,
                None => {
                    runs.push((run, Vec::new()));
                    runs.len() - 1
                }
            };
            let counts = &mut runs[i].1;
            match counts.iter_mut().find(|(f, _)| f == field) {
                Some(slot) => slot.1 = pm(c),
                None => counts.push((field.clone(), pm(c))),
            }
        }
    }
    let mut ranked: Vec<(String, Vec<f64>, f64)> = runs
        .into_iter()
        .filter(|(_, counts)| counts.len() == fields.len())
        .map(|(run, counts)| {
            let row: Vec<f64> = fields
                .iter()
                .map(|f| counts.iter().find(|(g, _)| g == f).map_or(0.0, |c| c.1))
                .collect();
            let measure = row.iter().map(|c| c.ln_1p()).sum();
            (run, row, measure)
        })
        .collect();
    ranked.sort_by(|a, b| b.2.total_cmp(&a.2));
    ranked
}

/// Every campaign page under `docs` with its publication: the campaign
/// files beside the docs (`experiments/campaigns/`) with a publish stage.
fn publications(docs: &Path) -> Result<Vec<Publication>> {
    let dir = docs
        .parent()
        .unwrap_or_else(|| Path::new(""))
        .join(CAMPAIGNS);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    let mut out = Vec::new();
    for file in files {
        let campaign = Campaign::load(&file)?;
        for stage in campaign.stages {
            if let Work::Publish(p) = stage.work {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// Renders every campaign page's tables from its published results;
/// returns the pages written.
pub fn write_pages(docs: &Path) -> Result<Vec<PathBuf>> {
    publications(docs)?
        .iter()
        .map(|p| p.write_page(docs, &p.published(docs)?))
        .collect()
}

/// Fails, naming the page and its first differing line, unless every
/// campaign page's tables are what its published results give.
pub fn check_pages(docs: &Path) -> Result<Vec<PathBuf>> {
    let mut checked = Vec::new();
    for p in publications(docs)? {
        let (path, rendered) = p.page(docs, &p.published(docs)?)?;
        let committed = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        if let Some(line) = committed
            .lines()
            .zip(rendered.lines())
            .position(|(a, b)| a != b)
            .or_else(|| (committed != rendered).then(|| committed.lines().count()))
        {
            bail!(
                "{} is not what {}/results.json gives (first difference at line {}); regenerate it with `{}`",
                path.display(),
                docs.join(&p.dir).display(),
                line + 1,
                super::super::template::REPORT_COMMAND
            );
        }
        checked.push(path);
    }
    Ok(checked)
}
