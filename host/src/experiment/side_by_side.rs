//! The learned tables of the thesis author's program and ours, side by
//! side: what each training run printed at its end, read from
//! `docs/reproduction/side-by-side/{author,ours}/<letter>-<k>.txt` (the
//! directory's README says how the runs were made).
//!
//! The author's program's last lines are
//! `END step S formations F stuck K ...`, `ACTIONS_TOTAL a0 a1 a2 a3` and
//! `QSTATS visited_states N ... states_with_tied_max T ... q50 M ... q90 P ...`;
//! `host train` prints `formations F`, `stuck episodes K`,
//! `states visited N of 256`, `actions taken a0 a1 a2 a3 (...)`,
//! `values, visited ... median M, ... 90 % P, ...` and
//! `tied best actions in T of the visited states`.

use crate::report::stats::permutation_p;
use anyhow::{anyhow, bail, Context, Result};
use std::path::Path;

/// One training run's table at its end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Run {
    /// Formations in the run.
    pub formations: f64,
    /// Stuck episodes.
    pub stuck: f64,
    /// States of the table visited.
    pub states: f64,
    /// Each action's share of the actions taken, by id.
    pub shares: Vec<f64>,
    /// The median value of every action of the visited states.
    pub median: f64,
    /// Their 90th percentile.
    pub p90: f64,
    /// Visited states whose best value two or more actions share.
    pub tied: f64,
}

/// A figure of the side-by-side table.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Figure {
    Formations,
    Stuck,
    States,
    Action(usize),
    Median,
    P90,
    Tied,
}

impl Figure {
    fn parse(s: &str) -> Result<Figure> {
        Ok(match s {
            "formations" => Figure::Formations,
            "stuck" => Figure::Stuck,
            "states" => Figure::States,
            "median" => Figure::Median,
            "p90" => Figure::P90,
            "tied" => Figure::Tied,
            _ => match s.strip_prefix("action ").map(str::parse::<usize>) {
                Some(Ok(a)) if a < 4 => Figure::Action(a),
                _ => bail!("unknown side-by-side figure {s:?}: expected formations, stuck, states, action 0 to action 3, median, p90 or tied"),
            },
        })
    }

    fn of(self, r: &Run) -> f64 {
        match self {
            Figure::Formations => r.formations,
            Figure::Stuck => r.stuck,
            Figure::States => r.states,
            Figure::Action(a) => r.shares.get(a).copied().unwrap_or(f64::NAN),
            Figure::Median => r.median,
            Figure::P90 => r.p90,
            Figure::Tied => r.tied,
        }
    }

    /// The figure over a program's runs: the sum of the tied states, the
    /// mean of the others.
    fn over(self, runs: &[Run]) -> f64 {
        let sum: f64 = runs.iter().map(|r| self.of(r)).sum();
        match self {
            Figure::Tied => sum,
            _ => sum / runs.len() as f64,
        }
    }
}

/// The runs of one letter.
#[derive(Clone, Debug, Default)]
pub struct Letter {
    /// The letter.
    pub letter: String,
    /// The author's program's runs.
    pub author: Vec<Run>,
    /// Ours.
    pub ours: Vec<Run>,
}

/// Every letter's runs; empty where a document has none.
#[derive(Clone, Debug, Default)]
pub struct SideBySide {
    /// By letter, in name order.
    pub letters: Vec<Letter>,
}

/// The number `skip` + 1 tokens after `key`.
fn after(tokens: &[&str], key: &str, skip: usize) -> Result<f64> {
    let at = tokens
        .iter()
        .position(|t| *t == key)
        .ok_or_else(|| anyhow!("no {key:?} in the line"))?;
    let token = tokens
        .get(at + 1 + skip)
        .ok_or_else(|| anyhow!("nothing after {key:?}"))?;
    token
        .trim_end_matches(',')
        .parse()
        .map_err(|_| anyhow!("{token:?} after {key:?} is not a number"))
}

/// Numbers from the start of `tokens` up to the first that is not one.
fn numbers(tokens: &[&str]) -> Vec<f64> {
    tokens.iter().map_while(|t| t.parse().ok()).collect()
}

/// The author's program's last lines.
pub fn author_run(text: &str) -> Result<Run> {
    let mut run = Run::default();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"END") => {
                run.formations = after(&t, "formations", 0)?;
                run.stuck = after(&t, "stuck", 0)?;
            }
            Some(&"ACTIONS_TOTAL") => run.shares = numbers(&t[1..]),
            Some(&"QSTATS") => {
                run.states = after(&t, "visited_states", 0)?;
                run.tied = after(&t, "states_with_tied_max", 0)?;
                run.median = after(&t, "q50", 0)?;
                run.p90 = after(&t, "q90", 0)?;
            }
            _ => {}
        }
    }
    Ok(run)
}

/// `host train`'s report.
pub fn our_run(text: &str) -> Result<Run> {
    let mut run = Run::default();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"formations") => run.formations = after(&t, "formations", 0)?,
            Some(&"stuck") => run.stuck = after(&t, "episodes", 0)?,
            Some(&"states") => run.states = after(&t, "visited", 0)?,
            Some(&"actions") => run.shares = numbers(&t[2..]),
            Some(&"values,") => {
                run.median = after(&t, "median", 0)?;
                run.p90 = after(&t, "90", 1)?; // "90 % -5.629,"
            }
            Some(&"tied") => run.tied = after(&t, "in", 0)?,
            _ => {}
        }
    }
    Ok(run)
}

impl SideBySide {
    /// Reads `dir/author/*.txt` and `dir/ours/*.txt` (`<letter>-<k>.txt`);
    /// a missing `dir` has no runs.
    pub fn load(dir: &Path) -> Result<SideBySide> {
        let mut out = SideBySide::default();
        if !dir.exists() {
            return Ok(out);
        }
        for (program, read) in [
            ("author", author_run as fn(&str) -> Result<Run>),
            ("ours", our_run),
        ] {
            let sub = dir.join(program);
            let mut files: Vec<_> = std::fs::read_dir(&sub)
                .with_context(|| format!("cannot read {}", sub.display()))?
                .map(|e| e.map(|e| e.path()))
                .collect::<std::io::Result<_>>()
                .with_context(|| format!("cannot read {}", sub.display()))?;
            files.sort();
            for path in files {
                let name = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let Some((letter, _)) = name.split_once('-') else {
                    bail!("{}: expected <letter>-<k>.txt", path.display());
                };
                let text = std::fs::read_to_string(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                let run = read(&text).with_context(|| path.display().to_string())?;
                if run.shares.len() != 4 {
                    bail!("{}: no share for each of 4 actions", path.display());
                }
                let at = match out.letters.iter().position(|l| l.letter == letter) {
                    Some(at) => at,
                    None => {
                        out.letters.push(Letter {
                            letter: letter.to_string(),
                            ..Letter::default()
                        });
                        out.letters.len() - 1
                    }
                };
                let l = &mut out.letters[at];
                if program == "author" {
                    l.author.push(run);
                } else {
                    l.ours.push(run);
                }
            }
        }
        out.letters.sort_by(|a, b| a.letter.cmp(&b.letter));
        Ok(out)
    }

    /// The table's rows: for each letter the author's program, then ours.
    pub fn table(&self) -> String {
        let mut out = String::from("| Letter | Program | Runs | Formations | Stuck | States visited (of 256) | Actions taken (0, 1, 2, 3) | Median value | 90 % value | Tied |\n|---|---|---:|---:|---:|---:|---|---:|---:|---:|\n");
        for l in &self.letters {
            for (program, runs) in [("the author's", &l.author), ("ours", &l.ours)] {
                let shares: Vec<String> = (0..4)
                    .map(|a| format!("{:.3}", Figure::Action(a).over(runs)))
                    .collect();
                out.push_str(&format!(
                    "| {} | {program} | {} | {:.1} | {:.1} | {:.1} | {} | {:.2} | {:.2} | {:.0} |\n",
                    l.letter,
                    runs.len(),
                    Figure::Formations.over(runs),
                    Figure::Stuck.over(runs),
                    Figure::States.over(runs),
                    shares.join(", "),
                    Figure::Median.over(runs),
                    Figure::P90.over(runs),
                    Figure::Tied.over(runs),
                ));
            }
        }
        out.trim_end().to_string()
    }

    fn letter(&self, letter: &str) -> Result<&Letter> {
        self.letters
            .iter()
            .find(|l| l.letter == letter)
            .ok_or_else(|| anyhow!("the side-by-side runs have no letter {letter:?}"))
    }

    /// `side-by-side | ...` of the template: `LETTER | PROGRAM | FIGURE`
    /// (PROGRAM `author`, `ours` or `ours - author`), `LETTER | p` (the
    /// permutation test of the two programs' formations), `runs` (runs of
    /// each program per letter), or `difference | FIGURE` and
    /// `largest | FIGURE` (over the letters, the largest difference of the
    /// programs' figures, and the largest figure).
    pub fn figure(&self, parts: &[&str]) -> Result<f64> {
        let all = || self.letters.iter();
        match parts {
            ["runs"] => all()
                .flat_map(|l| [l.author.len(), l.ours.len()])
                .max()
                .map(|n| n as f64)
                .ok_or_else(|| anyhow!("no side-by-side runs")),
            ["difference", figure] => {
                let f = Figure::parse(figure)?;
                Ok(all()
                    .map(|l| (f.over(&l.ours) - f.over(&l.author)).abs())
                    .fold(0.0, f64::max))
            }
            ["largest", figure] => {
                let f = Figure::parse(figure)?;
                Ok(all()
                    .flat_map(|l| [f.over(&l.ours), f.over(&l.author)])
                    .fold(f64::NEG_INFINITY, f64::max))
            }
            [letter, "p"] => {
                let l = self.letter(letter)?;
                let formations = |runs: &[Run]| runs.iter().map(|r| r.formations).collect::<Vec<_>>();
                permutation_p(&formations(&l.ours), &formations(&l.author))
                    .ok_or_else(|| anyhow!("too many runs for an exact permutation test"))
            }
            [letter, program, figure] => {
                let (l, f) = (self.letter(letter)?, Figure::parse(figure)?);
                match *program {
                    "author" => Ok(f.over(&l.author)),
                    "ours" => Ok(f.over(&l.ours)),
                    "ours - author" => Ok(f.over(&l.ours) - f.over(&l.author)),
                    _ => bail!("unknown program {program:?}: expected author, ours or ours - author"),
                }
            }
            _ => bail!("expected side-by-side | LETTER | PROGRAM | FIGURE, | LETTER | p, | difference | FIGURE or | largest | FIGURE"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const AUTHOR: &str = "END step 2001000 formations 9 stuck 35 win_form 0 states 254\nACTIONS_TOTAL 0.2425 0.2140 0.2347 0.3089\nQSTATS visited_states 254 states_with_tied_max 1 q50 -8.7040 q75 -7.1 q90 -5.7759\n";
    const OURS: &str = "formations           50\nstuck episodes       17\nstates visited       253 of 256\nactions taken        0.299 0.231 0.192 0.278 (share of each action id)\nvalues, visited      min -9.985, median -8.742, 75 % -7.097, 90 % -5.629, max -2.331\ntied best actions    in 0 of the visited states\n";

    #[test]
    fn both_programs_reports_are_read() {
        let a = author_run(AUTHOR).unwrap();
        assert_eq!(
            (a.formations, a.stuck, a.states, a.tied, a.median, a.p90),
            (9.0, 35.0, 254.0, 1.0, -8.704, -5.7759)
        );
        assert_eq!(a.shares, [0.2425, 0.2140, 0.2347, 0.3089]);
        let o = our_run(OURS).unwrap();
        assert_eq!(
            (o.formations, o.stuck, o.states, o.tied, o.median, o.p90),
            (50.0, 17.0, 253.0, 0.0, -8.742, -5.629)
        );
        assert_eq!(o.shares, [0.299, 0.231, 0.192, 0.278]);
        assert!(
            format!("{:#}", author_run("END step 1 formations x").unwrap_err())
                .contains("\"x\" after \"formations\" is not a number")
        );
    }

    #[test]
    fn figures_compare_the_programs_letter_by_letter() {
        let s = SideBySide {
            letters: vec![Letter {
                letter: "T".into(),
                author: vec![author_run(AUTHOR).unwrap()],
                ours: vec![our_run(OURS).unwrap()],
            }],
        };
        let f = |p: &[&str]| s.figure(p).unwrap();
        assert_eq!(f(&["T", "ours", "formations"]), 50.0);
        assert_eq!(f(&["T", "ours - author", "states"]), -1.0);
        assert_eq!(f(&["difference", "stuck"]), 18.0);
        assert_eq!(f(&["largest", "tied"]), 1.0);
        assert_eq!(f(&["runs"]), 1.0);
        assert_eq!(f(&["T", "p"]), 1.0);
        assert!(s.figure(&["V", "p"]).is_err());
        assert!(s.table().contains(
            "| T | ours | 1 | 50.0 | 17.0 | 253.0 | 0.299, 0.231, 0.192, 0.278 | -8.74 | -5.63 | 0 |"
        ));
    }
}
