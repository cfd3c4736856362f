//! `host experiment report`: the results pages rendered from published
//! trials. Each [`Document`] is a page group: the built-in experiments
//! whose files name it (`page = "DIR"`), their trials under
//! `<docs>/<dir>/<name>/trials/`. The report writes each experiment's
//! `table.md`, `trials.csv` and figures there, its page
//! `<docs>/<dir>/<name>.md` from its template (`<docs>/<dir>/<name>/template.md`,
//! [`super::template`]; without one, a page of its table and how to
//! reproduce it), and the group's index `<docs>/<dir>.md` from
//! `<docs>/<dir>/template.md` (without one, a list of the experiments'
//! pages); with the trials published before the
//! clamping border (`<docs>/<dir>/wall-segments/trials.tsv`) and the
//! learners' side by side (`<docs>/<dir>/side-by-side/`) where the group
//! has them. Every page of a group sees all of the group's experiments.
//! `check` renders without writing and fails when a committed page
//! differs.
//!
//! Experiment files name their robot sensor configs and policies relative
//! to the repository root: run the report from there.

use super::outputs;
use super::published::{self, Published};
use super::side_by_side::SideBySide;
use super::spec::{ExperimentSpec, BUILT_IN};
use super::template::{self, Source, REPORT_COMMAND};
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A page group rendered from the published trials of its experiments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Document {
    /// Directory under the docs of its templates and trials, and the stem
    /// of its index page.
    pub dir: String,
    /// The experiments it shows, in name order: built-in names, or paths
    /// of files.
    pub experiments: Vec<String>,
}

/// The one key of an experiment file the page groups need.
#[derive(Deserialize)]
struct PageKey {
    page: Option<String>,
}

/// Every page group the experiments name, in name order: the built-in
/// ones, or with `dir` the `*.toml` files in it (by path).
pub fn all_documents(dir: Option<&Path>) -> Result<Vec<Document>> {
    let files: Vec<(String, String)> = match dir {
        None => BUILT_IN
            .iter()
            .map(|(name, text)| (name.to_string(), text.to_string()))
            .collect(),
        Some(dir) => {
            let mut files = Vec::new();
            let entries = std::fs::read_dir(dir)
                .with_context(|| format!("cannot list the experiments in {}", dir.display()))?;
            for entry in entries {
                let path = entry
                    .with_context(|| format!("cannot list the experiments in {}", dir.display()))?
                    .path();
                if path.extension().is_some_and(|e| e == "toml") {
                    let text = std::fs::read_to_string(&path)
                        .with_context(|| format!("cannot read {}", path.display()))?;
                    files.push((path.display().to_string(), text));
                }
            }
            files.sort();
            files
        }
    };
    let mut groups: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (name, text) in files {
        let key: PageKey = toml::from_str(&text).with_context(|| format!("experiment {name}"))?;
        if let Some(page) = key.page {
            groups.entry(page).or_default().push(name);
        }
    }
    Ok(groups
        .into_iter()
        .map(|(dir, experiments)| Document { dir, experiments })
        .collect())
}

impl Document {
    /// The index page.
    pub fn path(&self, docs: &Path) -> PathBuf {
        docs.join(format!("{}.md", self.dir))
    }

    /// Every experiment with its published trials (run at `scale` of the
    /// files' step counts: 1 for the published runs); stale trial files are
    /// reported through `log` and left out.
    pub fn sources(&self, docs: &Path, scale: f64, log: &dyn Fn(&str)) -> Result<Vec<Source>> {
        let mut out = Vec::new();
        for name in &self.experiments {
            let spec = ExperimentSpec::load(name)?;
            let dir = docs.join(&self.dir).join(&spec.name);
            let published: Published = published::load(&spec, &dir, scale, spec.seed)?;
            for stale in &published.stale {
                log(&format!("left out: {stale}"));
            }
            let segments = published::wall_segments(
                &docs.join(&self.dir).join("wall-segments/trials.tsv"),
                &spec.name,
            )?;
            out.push(Source {
                spec,
                published,
                dir,
                segments,
            });
        }
        Ok(out)
    }

    /// The index page the template and the trials give; without a
    /// template, a list of the experiments' pages.
    pub fn render(&self, docs: &Path, sources: &[Source]) -> Result<String> {
        let path = docs.join(&self.dir).join("template.md");
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let mut text = format!("# {}\n\n", self.dir);
                for s in sources {
                    let name = &s.spec.name;
                    text.push_str(&format!("- [{}]({}/{name}.md)\n", s.spec.title, self.dir));
                }
                text
            }
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
        };
        self.render_text(docs, sources, &text, &path)
    }

    /// Every page of the group, each with its path: the index, then each
    /// experiment's.
    pub fn pages(&self, docs: &Path, sources: &[Source]) -> Result<Vec<(PathBuf, String)>> {
        let mut pages = vec![(self.path(docs), self.render(docs, sources)?)];
        for source in sources {
            let name = &source.spec.name;
            let path = docs.join(&self.dir).join(name).join("template.md");
            let text = match std::fs::read_to_string(&path) {
                Ok(text) => text,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    default_template(&source.spec)
                }
                Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
            };
            let page = docs.join(&self.dir).join(format!("{name}.md"));
            pages.push((page, self.render_text(docs, sources, &text, &path)?));
        }
        Ok(pages)
    }

    /// `text`, the template at `path`, rendered.
    fn render_text(
        &self,
        docs: &Path,
        sources: &[Source],
        text: &str,
        path: &Path,
    ) -> Result<String> {
        let side = SideBySide::load(&docs.join(&self.dir).join("side-by-side"))?;
        let body =
            template::render(text, sources, &side).with_context(|| path.display().to_string())?;
        let template = path
            .strip_prefix(docs)
            .map(|p| format!("docs/{}", p.display()))
            .unwrap_or_else(|_| path.display().to_string());
        let dir = &self.dir;
        Ok(format!(
            "<!-- Generated by `host experiment report` from {template} and the trials in docs/{dir}/*/trials/: edit the template, not this file. -->\n{body}"
        ))
    }
}

/// The page of an experiment without a template: its title, table, trials
/// and how to reproduce them.
fn default_template(spec: &ExperimentSpec) -> String {
    let name = &spec.name;
    format!(
        "# {title}\n\n{{{{{name} table}}}}\n\n{{{{{name} trials}}}} trials. Reproduce them with \
         `host experiment {name}` (into `out/experiments/{name}/`).\n",
        title = spec.title
    )
}

/// The documents named (all for none) of the experiments in `dir` (the
/// built-in ones for none); an unknown name is an error that lists the
/// known ones.
pub fn documents(names: &[String], dir: Option<&Path>) -> Result<Vec<Document>> {
    let all = all_documents(dir)?;
    if names.is_empty() {
        return Ok(all);
    }
    names
        .iter()
        .map(|n| {
            all.iter().find(|d| &d.dir == n).cloned().with_context(|| {
                let known: Vec<&str> = all.iter().map(|d| d.dir.as_str()).collect();
                format!(
                    "unknown document {n:?}: expected one of {}",
                    known.join(", ")
                )
            })
        })
        .collect()
}

/// Writes the documents' experiment reports (an experiment without trials
/// gets its empty tables and the figures that need none) and the
/// documents; returns the files written.
pub fn write(
    docs: &Path,
    documents: &[Document],
    scale: f64,
    log: &dyn Fn(&str),
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for document in documents {
        let sources = document.sources(docs, scale, log)?;
        let pages = document.pages(docs, &sources)?;
        for s in &sources {
            written.extend(outputs::write_reports(
                &s.spec,
                &s.dir,
                &s.published.results,
                scale,
                s.spec.seed,
            )?);
        }
        for (path, page) in pages {
            crate::atomic::write(&path, page.as_bytes())?;
            written.push(path);
        }
    }
    written.extend(super::campaign::publish::write_pages(docs)?);
    Ok(written)
}

/// Fails, naming the document, its first differing line and the command,
/// unless each committed document is what the trials give.
pub fn check(docs: &Path, documents: &[Document], log: &dyn Fn(&str)) -> Result<Vec<PathBuf>> {
    let mut checked = Vec::new();
    for document in documents {
        let sources = document.sources(docs, 1.0, log)?;
        for (path, rendered) in document.pages(docs, &sources)? {
            let committed = std::fs::read_to_string(&path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            if committed != rendered {
                let line = committed
                    .lines()
                    .zip(rendered.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or_else(|| committed.lines().count().min(rendered.lines().count()));
                bail!(
                "{} is not what the published trials and its template under docs/{}/ give (first difference at line {}); regenerate it with `{REPORT_COMMAND}`",
                path.display(),
                document.dir,
                line + 1
            );
            }
            checked.push(path);
        }
    }
    checked.extend(super::campaign::publish::check_pages(docs)?);
    Ok(checked)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_built_in_experiment_names_the_results_page_that_shows_it() {
        let documents = all_documents(None).unwrap();
        let listed: Vec<&str> = documents
            .iter()
            .flat_map(|d| d.experiments.iter().map(String::as_str))
            .collect();
        let missing: Vec<&str> = BUILT_IN
            .iter()
            .map(|(n, _)| *n)
            .filter(|n| !listed.contains(n))
            .collect();
        assert!(missing.is_empty(), "no page = \"...\" in {missing:?}");
        let dirs: Vec<&str> = documents.iter().map(|d| d.dir.as_str()).collect();
        assert_eq!(dirs, ["reproduction", "robot-sensors"]);
    }
}
