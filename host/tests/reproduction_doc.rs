//! docs/reproduction.md and docs/robot-sensors.md are what `host
//! experiment report` renders from their templates and the committed
//! trials: every figure they state comes from the trial files, and every
//! claim their templates check still holds. The reproduction page's
//! verdicts follow its one rule (recomputed here), and the author's
//! per-trial figures in the experiment files are those of the checked-in
//! copy of the author's result files.

use host::experiment::metric::Metric;
use host::experiment::published::SegmentTrial;
use host::experiment::report::documents;
use host::experiment::side_by_side::SideBySide;
use host::experiment::spec::ExperimentSpec;
use host::experiment::template::{self, Source};
use host::report::stats::t95;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn the_rendered_pages_are_what_the_committed_trials_give() {
    // as a user runs the report: from the repository root, against which
    // experiment files name their sensor configs and policies
    std::env::set_current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("..")).unwrap();
    let docs = Path::new("docs");
    let stale = std::cell::RefCell::new(Vec::new());
    let log = |line: &str| stale.borrow_mut().push(line.to_string());
    let all = documents(&[], None).unwrap();
    if let Err(e) = host::experiment::report::check(docs, &all, &log) {
        panic!("{e:#}");
    }
    assert!(
        stale.borrow().is_empty(),
        "published trials the experiment files no longer plan: {:?}",
        stale.borrow()
    );
}

/// The page compares the three arms of the Original hash on the annulus
/// (annulus RL, collisions Original, state bits' 8 bits) as one setting
/// drawn with three sets of seeds: their settings must be identical.
#[test]
fn the_arms_the_page_calls_one_setting_have_identical_settings() {
    use host::experiment::spec::ExperimentSpec;
    let arms = [
        ("annulus", "RL"),
        ("collisions", "Original"),
        ("state-bits", "8 bits (Original)"),
        ("obstacle", "8 bits (Original)"),
    ];
    let settings: Vec<String> = arms
        .iter()
        .map(|(experiment, arm)| {
            let spec = ExperimentSpec::load(experiment).unwrap();
            let arm = spec.arm(arm).unwrap();
            assert!(arm.pretrain.is_none() && arm.policy.is_none());
            format!("{:?} {:?}", arm.controller, arm.config)
        })
        .collect();
    for (s, (experiment, arm)) in settings.iter().zip(arms) {
        assert_eq!(
            s, &settings[0],
            "{experiment} {arm:?} differs from annulus RL"
        );
    }
}

/// The summary's first-formation row shows means, the statistic its
/// verdicts test, and gives orbital construction a verdict too.
#[test]
fn the_summary_judges_first_formations_by_the_mean_it_shows_for_every_system() {
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduction.md"),
    )
    .unwrap();
    let row = page
        .lines()
        .find(|l| l.starts_with("| Annulus: first formation"))
        .expect("the summary has a first-formation row");
    assert!(row.contains("(mean over the trials that formed)"), "{row}");
    assert!(!row.contains("median"), "{row}");
    for system in ["OC: ", "RL: ", "RL2: "] {
        assert!(row.contains(system), "no verdict for {system}: {row}");
    }
}

/// Rows 2 and 3 of the collisions table run the code's obstacle discs and
/// test success on Eval: its column does not claim the text's settings
/// without saying which it does not follow.
#[test]
fn the_collisions_table_says_where_its_text_column_follows_the_code() {
    let table = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduction/collisions/table.md"),
    )
    .unwrap();
    assert!(!table.contains("| text: "), "a bare text column");
    assert!(table.contains("| text*: Formations"), "{table}");
    assert!(
        table.contains("Text*: the text's settings but for")
            && table.contains("radius r/4")
            && table.contains("tested on Eval"),
        "the caption explains the asterisk"
    );
}

/// The experiment files' `author` lists are, trial by trial, the last
/// counts of the author's result files (the checked-in copy under
/// docs/reproduction/author/), and their means are Table 5's figures.
#[test]
fn the_authors_lists_are_the_counts_of_the_authors_result_files() {
    let text =
        std::fs::read_to_string(root().join("docs/reproduction/author/letters.tsv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split('\t').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut files: std::collections::BTreeMap<String, Vec<(usize, f64, f64)>> = Default::default();
    for line in lines {
        let c: Vec<&str> = line.split('\t').collect();
        let formations: f64 = c[col("formations")].parse().unwrap();
        // the copy keeps every rise of the count: as many as the last count
        let rises = c[col("formation_steps")].split_whitespace().count();
        assert_eq!(rises as f64, formations, "{line}");
        files
            .entry(format!("{} {}", c[col("letter")], c[col("system")]))
            .or_default()
            .push((
                c[col("trial")].parse().unwrap(),
                formations,
                c[col("stuck")].parse().unwrap(),
            ));
    }
    let spec = ExperimentSpec::load("letters").unwrap();
    for arm in &spec.arms {
        let listed = arm.author.get(&Metric::Formations);
        let Some(trials) = files.get_mut(&arm.name) else {
            assert!(
                listed.is_none(),
                "{}: an author list without files",
                arm.name
            );
            continue;
        };
        trials.sort_by_key(|t| t.0);
        let counts: Vec<f64> = trials.iter().map(|t| t.1).collect();
        assert_eq!(listed, Some(&counts), "{}", arm.name);
        for (metric, i) in [(Metric::Formations, 1), (Metric::Stuck, 2)] {
            let mean = trials.iter().map(|t| [t.1, t.2][i - 1]).sum::<f64>() / trials.len() as f64;
            assert_eq!(
                format!("{mean:.1}"),
                format!("{:.1}", arm.thesis[&metric]),
                "{}: Table 5's {metric:?}",
                arm.name
            );
        }
    }
    assert_eq!(files.len(), 8, "T, V, X and Z, RL and OC");
}

/// The verdict rule, recomputed: ours over theirs with its 95 % interval
/// (a mean's t interval over a single figure, or a ratio of two means
/// with the delta method's interval and Welch's degrees of freedom), inside
/// 0.75 to 4/3 reproduced, outside it not reproduced, else inconclusive.
fn expected_verdict(ours: &[f64], theirs: &[f64], figure: f64) -> String {
    let stats = |v: &[f64]| {
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = if v.len() > 1 {
            v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        (n, m, var)
    };
    let (na, ma, va) = stats(ours);
    let (nb, mb, vb) = stats(theirs);
    let r = ma / mb;
    let (ua, ub) = (va / (na * ma * ma), vb / (nb * mb * mb));
    let df = if nb == 1.0 {
        na - 1.0
    } else {
        (ua + ub).powi(2) / (ua * ua / (na - 1.0) + ub * ub / (nb - 1.0))
    };
    let half = t95(df) * r * (ua + ub).sqrt();
    let (low, high) = ((r - half) / figure, (r + half) / figure);
    let show = |v: f64| format!("{:.2}", if v.abs() < 0.005 { 0.0 } else { v });
    let bounds = format!("{} to {}", show(low), show(high));
    if low >= 0.75 && high <= 4.0 / 3.0 {
        format!("reproduced ({bounds})")
    } else if low > 4.0 / 3.0 {
        format!("not reproduced (ours higher: {bounds})")
    } else if high < 0.75 {
        format!("not reproduced (ours lower: {bounds})")
    } else {
        format!("inconclusive ({bounds})")
    }
}

/// An arm's per-trial values of a quantity the summary judges.
fn arm_values(source: &Source, arm: &str, quantity: &str, segments: bool) -> Vec<f64> {
    if segments {
        let of = |r: &SegmentTrial| match quantity {
            "formations" => Some(r.formations as f64),
            "first_formation" => r.first_formation.map(|s| s as f64),
            "collisions_per_1000" => Some(r.collisions_per_1000),
            q => panic!("no verdict on {q}"),
        };
        return source
            .segments
            .iter()
            .filter(|r| r.arm == arm)
            .filter_map(of)
            .collect();
    }
    source
        .published
        .results
        .iter()
        .filter(|r| r.arm == arm)
        .filter_map(|r| match quantity {
            "formations" => Some(r.formations as f64),
            "first_formation" => r.formation_steps.first().map(|&s| s as f64),
            "collisions_per_1000" => Some(r.collisions_per_1000),
            q => panic!("no verdict on {q}"),
        })
        .collect()
}

/// A verdict expression's verdict, recomputed from the trials; `None` for
/// an expression that is not a verdict.
fn recompute(expr: &str, sources: &[Source]) -> Option<String> {
    let parts: Vec<&str> = expr.split('|').map(str::trim).collect();
    let [experiment, arms, quantity, stat] = parts[..] else {
        return None;
    };
    let (segments, stat) = match stat.strip_prefix("segments ") {
        Some(stat) => (true, stat),
        None => (false, stat),
    };
    if !(stat.starts_with("verdict") || stat == "author_verdict") {
        return None;
    }
    let source = sources.iter().find(|s| s.spec.name == experiment).unwrap();
    let metric = match quantity {
        "formations" => Metric::Formations,
        "first_formation" => Metric::FirstFormation,
        "collisions_per_1000" => Metric::CollisionsPer1000,
        q => panic!("no verdict on {q}"),
    };
    let figure = |arm: &str, m: Metric| source.spec.arm(arm).unwrap().thesis[&m];
    Some(match arms.split_once(" / ") {
        None if stat == "author_verdict" => {
            let author = &source.spec.arm(arms).unwrap().author[&metric];
            expected_verdict(&arm_values(source, arms, quantity, segments), author, 1.0)
        }
        None => expected_verdict(
            &arm_values(source, arms, quantity, segments),
            &[figure(arms, metric)],
            1.0,
        ),
        Some((a, b)) => {
            let thesis_ratio = || match source
                .spec
                .arm(a)
                .unwrap()
                .thesis
                .get(&Metric::FormationsRatio)
            {
                Some(&r) if metric == Metric::Formations => r,
                _ => figure(a, metric) / figure(b, metric),
            };
            let against = match stat.strip_prefix("verdict").unwrap().trim() {
                "" => thesis_ratio(),
                x => x.parse().unwrap(),
            };
            expected_verdict(
                &arm_values(source, a, quantity, segments),
                &arm_values(source, b, quantity, segments),
                against,
            )
        }
    })
}

/// Every verdict on docs/reproduction.md is the one rule's, recomputed
/// here from the published trials (and the wall-segment trials and the
/// author's trials) without the renderer's code for it: each template line
/// with a verdict, its verdicts recomputed and its other expressions
/// rendered, is a line of the page.
#[test]
fn every_verdict_on_the_page_follows_the_one_rule() {
    std::env::set_current_dir(root()).unwrap();
    let docs = Path::new("docs");
    let document = documents(&["reproduction".to_string()], None)
        .unwrap()
        .remove(0);
    let sources = document.sources(docs, 1.0, &|_| {}).unwrap();
    let side = SideBySide::load(&docs.join("reproduction/side-by-side")).unwrap();
    // each page's template and the page: the index, then each experiment's
    let mut pairs = vec![(
        docs.join("reproduction/template.md"),
        docs.join("reproduction.md"),
    )];
    for name in &document.experiments {
        let dir = docs.join("reproduction").join(name);
        pairs.push((dir.join("template.md"), dir.with_extension("md")));
    }
    let (mut verdicts, mut missing) = (0, Vec::new());
    for (template_path, page_path) in pairs {
        let Ok(template_text) = std::fs::read_to_string(&template_path) else {
            continue;
        };
        let page = std::fs::read_to_string(&page_path).unwrap();
        let page_lines: std::collections::HashSet<&str> = page.lines().collect();
        for line in template_text.lines() {
            let mut expected = String::new();
            let mut rest = line;
            let mut judged = false;
            while let Some(open) = rest.find("{{") {
                expected.push_str(&rest[..open]);
                let close = rest[open..].find("}}").unwrap() + open;
                let expr = rest[open + 2..close].trim();
                match recompute(expr, &sources) {
                    Some(v) => {
                        expected.push_str(&v);
                        judged = true;
                        verdicts += 1;
                    }
                    None => expected.push_str(
                        &template::render(&format!("{{{{{expr}}}}}"), &sources, &side).unwrap(),
                    ),
                }
                rest = &rest[close + 2..];
            }
            expected.push_str(rest);
            if judged && !page_lines.contains(expected.as_str()) {
                missing.push(expected);
            }
        }
    }
    assert!(verdicts > 100, "only {verdicts} verdicts found");
    assert!(
        missing.is_empty(),
        "lines whose verdicts are not the rule's:\n{}",
        missing.join("\n")
    );
}

/// The pages type none of the figures the trials or the runs give: the
/// learners' side-by-side table and its comparisons, and the figures with
/// wall segments, are rendered.
#[test]
fn the_template_types_no_figure_of_the_runs() {
    // the index's template and every experiment page's
    let dir = root().join("docs/reproduction");
    let mut template = std::fs::read_to_string(dir.join("template.md")).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        if let Ok(text) = std::fs::read_to_string(entry.unwrap().path().join("template.md")) {
            template.push_str(&text);
        }
    }
    let mut prose = String::new();
    let mut rest = template.as_str();
    while let Some(open) = rest.find("{{") {
        prose.push_str(&rest[..open]);
        rest = &rest[open + rest[open..].find("}}").unwrap() + 2..];
    }
    prose.push_str(rest);
    let prose = prose.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(template.contains("{{side-by-side table}}"));
    for typed in [
        "254",
        "442",
        "0.02",
        "p 0.09",
        "p 0.69",
        "within 1.1",
        "a tenth",
        "| 31.0 |",
    ] {
        assert!(!prose.contains(typed), "typed into the template: {typed:?}");
    }
    assert!(
        !prose.contains("forms as many shapes as the author"),
        "equality read from a test that found no difference"
    );
}
