//! The docs name only what exists: every `host` command line written in a
//! page (code blocks and inline code of `README.md`, `docs/`, `policies/`
//! and `experiments/`) names subcommands and flags that `host ... --help`
//! lists, and built-in experiments that `experiments/` holds; every
//! repository path a page names in code, and every relative link, exists.
//! And the docs say what is, in pages one can read: every page under
//! `docs/` has at most 600 lines (`docs/guide.md` at most 300), and no
//! heading of any page carries a date (`2026-12-02`) or a "sitting".
//!
//! What counts as a command: the words after `host` (or a path ending in
//! `/host`, or `cargo run ... -p host --`) up to a shell separator (`|`,
//! `;`, `&&`, `||`, `>`, `#`), in inline code or a shell code block
//! (`sh`, `bash`, `shell`, `console`), whose lines are joined where they end
//! in `\`. Placeholders are skipped: a word in angle brackets, or written
//! in capitals (`FILE`, `NAME`, `K/N`). A path is a word that starts with
//! one of the repository's top folders.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

const HOST: &str = env!("CARGO_BIN_EXE_host");

/// Top folders of the repository whose paths a page may name.
const TOP_FOLDERS: [&str; 13] = [
    ".ci/",
    "docs/",
    "experiments/",
    "firmware/",
    "host/",
    "policies/",
    "python/",
    "scripts/",
    "shared/",
    "sim/",
    "tests/",
    "view/",
    "README.md",
];

/// Words that end a command on a line.
const SEPARATORS: [&str; 8] = ["|", "||", "&&", ";", ">", "2>&1", "#", "&"];

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host sits in the repository")
        .to_path_buf()
}

/// The pages checked: every tracked markdown file but the published runs'.
fn pages(root: &Path) -> Vec<PathBuf> {
    let out = Command::new("git")
        .args(["ls-files", "*.md"])
        .current_dir(root)
        .output()
        .expect("git runs");
    String::from_utf8(out.stdout)
        .expect("git prints paths")
        .lines()
        .filter(|p| !p.contains("/runs/") && !p.contains("/trials/"))
        .map(|p| root.join(p))
        .collect()
}

/// What `host PATH --help` lists.
#[derive(Default)]
struct Help {
    flags: BTreeSet<String>,
    subcommands: BTreeSet<String>,
}

/// `host --help` and its subcommands' helps, read once each.
struct Helps(HashMap<Vec<String>, Option<Help>>);

impl Helps {
    /// The help of `path`, or `None` if `host` does not know the path.
    fn of(&mut self, path: &[String]) -> Option<&Help> {
        self.0
            .entry(path.to_vec())
            .or_insert_with(|| {
                let out = Command::new(HOST)
                    .args(path)
                    .arg("--help")
                    .output()
                    .expect("host runs");
                out.status
                    .success()
                    .then(|| parse_help(&String::from_utf8_lossy(&out.stdout)))
            })
            .as_ref()
    }
}

/// The flags (`--name`) and subcommands clap's help lists.
fn parse_help(text: &str) -> Help {
    let mut help = Help::default();
    let mut in_commands = false;
    for line in text.lines() {
        if line.ends_with(':') && !line.starts_with(' ') {
            in_commands = line == "Commands:";
            continue;
        }
        let trimmed = line.trim_start();
        if in_commands && line.starts_with("  ") {
            if let Some(name) = trimmed.split_whitespace().next() {
                help.subcommands.insert(name.to_string());
            }
        }
        if trimmed.starts_with('-') {
            for word in trimmed.split([' ', ',']) {
                if let Some(flag) = word.strip_prefix("--") {
                    let flag = flag.split(['=', '[', '<']).next().unwrap_or(flag);
                    help.flags.insert(flag.to_string());
                }
            }
        }
    }
    help
}

/// A piece of code in a page: a code block's line or an inline span.
struct Code {
    page: PathBuf,
    line: usize,
    text: String,
    /// Whether it may hold commands: inline code, or a shell code block
    /// (not a diagram or a format's layout).
    shell: bool,
}

/// Info strings of the code blocks that hold shell commands.
const SHELL_BLOCKS: [&str; 4] = ["sh", "bash", "shell", "console"];

/// The code of a markdown page: code blocks line by line (continuations
/// joined), inline spans (which may wrap over lines), and link targets.
fn code_of(page: &Path, text: &str) -> (Vec<Code>, Vec<Code>) {
    let (mut code, mut links) = (Vec::new(), Vec::new());
    let (mut fenced, mut shell) = (false, false);
    let mut pending: Option<(usize, String)> = None;
    let mut prose: Vec<(usize, &str)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if let Some(info) = line.trim_start().strip_prefix("```") {
            fenced = !fenced;
            shell = SHELL_BLOCKS.contains(&info.trim());
            continue;
        }
        if !fenced {
            prose.push((i + 1, line));
            continue;
        }
        let (start, mut joined) = pending.take().unwrap_or((i + 1, String::new()));
        joined.push_str(line.trim_end_matches('\\'));
        joined.push(' ');
        if line.ends_with('\\') {
            pending = Some((start, joined));
        } else {
            code.push(Code {
                page: page.to_path_buf(),
                line: start,
                text: joined,
                shell,
            });
        }
    }
    // inline spans: split the prose on backticks, remembering lines
    let mut inside = false;
    let mut span = String::new();
    let mut span_line = 0;
    for (number, line) in prose {
        for (k, piece) in line.split('`').enumerate() {
            if k > 0 {
                if inside {
                    code.push(Code {
                        page: page.to_path_buf(),
                        line: span_line,
                        text: std::mem::take(&mut span),
                        shell: true,
                    });
                } else {
                    span_line = number;
                }
                inside = !inside;
            }
            if inside {
                span.push_str(piece);
            } else {
                links.extend(link_targets(piece).map(|target| Code {
                    page: page.to_path_buf(),
                    line: number,
                    text: target,
                    shell: false,
                }));
            }
        }
        if inside {
            span.push(' ');
        }
    }
    (code, links)
}

/// Targets of `[text](target)` links in a piece of prose.
fn link_targets(prose: &str) -> impl Iterator<Item = String> + '_ {
    prose.match_indices("](").filter_map(|(at, _)| {
        let rest = &prose[at + 2..];
        rest.find(')').map(|end| rest[..end].to_string())
    })
}

/// Whether a word is a placeholder rather than a name.
fn placeholder(word: &str) -> bool {
    word.contains(['<', '>', '*', '{', '$', '[', '…'])
        || word.contains("...")
        || word
            .split(|c: char| !c.is_ascii_alphanumeric())
            .any(|part| part.len() >= 2 && part.chars().all(|c| c.is_ascii_uppercase()))
        || word.contains("-K-")
        || word.ends_with("/N")
}

/// The words of a command after `host`, for each command in `code`.
fn host_commands(code: &str) -> Vec<Vec<&str>> {
    let words: Vec<&str> = code.split_whitespace().collect();
    let mut commands = Vec::new();
    for (i, word) in words.iter().enumerate() {
        let is_host = *word == "host" || word.ends_with("/host");
        let after_cargo = i >= 1 && words[i - 1] == "-p";
        if !is_host || (after_cargo && words.get(i + 1) != Some(&"--")) {
            continue;
        }
        let mut rest = &words[i + 1..];
        if after_cargo {
            rest = &rest[1..];
        }
        let end = rest
            .iter()
            .position(|w| SEPARATORS.contains(w) || w.starts_with('#'))
            .unwrap_or(rest.len());
        commands.push(rest[..end].to_vec());
    }
    commands
}

/// What is wrong with one command's words, if anything.
fn check_command(root: &Path, helps: &mut Helps, words: &[&str]) -> Vec<String> {
    let mut problems = Vec::new();
    let Some(first) = words.first() else {
        return problems;
    };
    let first = first.trim_end_matches([',', '.', ':', ')']);
    if first.starts_with('-') || placeholder(first) {
        return problems;
    }
    let top = helps
        .of(&[])
        .map(|h| h.subcommands.clone())
        .unwrap_or_default();
    if !top.contains(first) {
        // `host` as a word of prose in code ("the host binary") is not a command
        if first.chars().all(|c| c.is_ascii_lowercase() || c == '-') && words.len() > 1 {
            problems.push(format!("`host {first}`: no such subcommand"));
        }
        return problems;
    }
    let mut path = vec![first.to_string()];
    let mut rest = &words[1..];
    while let Some(next) = rest.first() {
        let next = next.trim_end_matches([',', '.', ':', ')']);
        let subs = helps
            .of(&path)
            .map(|h| h.subcommands.clone())
            .unwrap_or_default();
        if subs.contains(next) {
            path.push(next.to_string());
            rest = &rest[1..];
        } else {
            break;
        }
    }
    if path == ["experiment"] {
        if let Some(name) = rest.first().filter(|w| !w.starts_with('-')) {
            let name = name.trim_end_matches([',', '.', ':', ')']);
            for one in name.split('|').filter(|n| !placeholder(n)) {
                let built_in = root.join("experiments").join(format!("{one}.toml"));
                if !built_in.is_file() && !root.join(one).is_file() {
                    problems.push(format!("`host experiment {one}`: no such experiment"));
                }
            }
        }
    }
    let Some(help) = helps.of(&path) else {
        problems.push(format!(
            "`host {}`: host refuses its --help",
            path.join(" ")
        ));
        return problems;
    };
    for word in rest {
        let Some(flag) = word.strip_prefix("--") else {
            continue;
        };
        let flag = flag
            .split('=')
            .next()
            .unwrap_or(flag)
            .trim_end_matches([',', '.', ':', ')', ';']);
        if !flag.is_empty() && !placeholder(flag) && !help.flags.contains(flag) {
            problems.push(format!("`host {}`: no flag --{flag}", path.join(" ")));
        }
    }
    problems
}

/// The repository paths named in a piece of code that do not exist.
fn missing_paths(root: &Path, code: &str) -> Vec<String> {
    code.split_whitespace()
        .map(|w| w.trim_matches(|c: char| "\"'(),.:;=".contains(c)))
        .map(|w| w.split_once('=').map_or(w, |(_, value)| value))
        .filter(|w| TOP_FOLDERS.iter().any(|top| w.starts_with(top)))
        .filter(|w| !placeholder(w))
        .filter(|w| !root.join(w.split(':').next().unwrap_or(w)).exists())
        .map(|w| format!("`{w}`: no such file in the repository"))
        .collect()
}

#[test]
fn every_page_names_only_subcommands_flags_experiments_and_files_that_exist() {
    let root = repository();
    let mut helps = Helps(HashMap::new());
    let mut problems = Vec::new();
    let mut commands = 0;
    for page in pages(&root) {
        let text = std::fs::read_to_string(&page).expect("a tracked page reads");
        let (code, links) = code_of(&page, &text);
        for piece in &code {
            let at = |p: String| {
                format!(
                    "{}:{}: {p}",
                    piece
                        .page
                        .strip_prefix(&root)
                        .unwrap_or(&piece.page)
                        .display(),
                    piece.line
                )
            };
            for words in host_commands(&piece.text)
                .into_iter()
                .filter(|_| piece.shell)
            {
                commands += 1;
                problems.extend(check_command(&root, &mut helps, &words).into_iter().map(at));
            }
            problems.extend(missing_paths(&root, &piece.text).into_iter().map(at));
        }
        for link in links {
            let target = link.text.split('#').next().unwrap_or_default();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            // a template's links are its rendered page's: one folder up
            let mut dir = link.page.parent().expect("a page sits in a folder");
            if link.page.file_name().is_some_and(|n| n == "template.md") {
                dir = dir.parent().expect("a template sits in its page's folder");
            }
            if !dir.join(target).exists() {
                problems.push(format!(
                    "{}:{}: link to `{target}`: no such file",
                    link.page
                        .strip_prefix(&root)
                        .unwrap_or(&link.page)
                        .display(),
                    link.line
                ));
            }
        }
    }
    assert!(
        commands > 50,
        "the pages name {commands} host commands: the reader broke"
    );
    assert!(
        problems.is_empty(),
        "{} references to what does not exist:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// What a page must not say: our tracker's issue numbers (`issue 31`; an
/// upstream project's `issue #40` is a citation), one machine's paths, the
/// thesis by a path outside the repository (it is cited by title).
fn outside_references(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let lower = line.to_lowercase();
        for (at, _) in lower.match_indices("issue") {
            let rest = lower[at + 5..].trim_start_matches(['s', ' ']);
            if rest.starts_with(|c: char| c.is_ascii_digit()) {
                found.push((i + 1, "names an issue number".to_string()));
            }
        }
        for outside in ["/work/", "/root/", "../shared/seed"] {
            if line.contains(outside) {
                found.push((
                    i + 1,
                    format!("names a path outside the repository ({outside})"),
                ));
            }
        }
    }
    found
}

#[test]
fn no_page_names_an_issue_number_or_a_path_outside_the_repository() {
    let root = repository();
    let problems: Vec<String> = pages(&root)
        .iter()
        .flat_map(|page| {
            let text = std::fs::read_to_string(page).expect("a tracked page reads");
            let name = page
                .strip_prefix(&root)
                .unwrap_or(page)
                .display()
                .to_string();
            outside_references(&text)
                .into_iter()
                .map(move |(line, what)| format!("{name}:{line}: {what}"))
        })
        .collect();
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert_eq!(
        outside_references(
            "as issue 31 asks\nsee ../shared/seed/thesis.txt\nthe issues of the day, avr-hal issue #40"
        ),
        [
            (1, "names an issue number".to_string()),
            (
                2,
                "names a path outside the repository (../shared/seed)".to_string()
            )
        ]
    );
}

#[test]
fn the_check_finds_a_subcommand_a_flag_an_experiment_and_a_file_that_do_not_exist() {
    let root = repository();
    let mut helps = Helps(HashMap::new());
    let page = "Run `host run --no-such-flag 3` or\n\n```sh\nhost render --steps 10 \\\n    --bogus\nhost experiment no-such-experiment\nhost frobnicate now\n```\n\nas `scripts/no-such-script` says; [see](no-such-page.md).\n";
    let (code, links) = code_of(Path::new("page.md"), page);
    let mut problems = Vec::new();
    for piece in &code {
        for words in host_commands(&piece.text) {
            problems.extend(check_command(&root, &mut helps, &words));
        }
        problems.extend(missing_paths(&root, &piece.text));
    }
    assert_eq!(
        problems,
        [
            "`host render`: no flag --bogus",
            "`host experiment no-such-experiment`: no such experiment",
            "`host frobnicate`: no such subcommand",
            "`host run`: no flag --no-such-flag",
            "`scripts/no-such-script`: no such file in the repository",
        ]
    );
    assert_eq!(links.len(), 1);
    assert_eq!(links[0].text, "no-such-page.md");
    // what exists passes
    let fine = "```sh\ncargo run --release -p host -- train --steps 2000\nhost policy inspect policies/robot-general.policy\nhost experiment annulus --scale 0.05 --trials 3\n```\n";
    let (code, _) = code_of(Path::new("page.md"), fine);
    for piece in &code {
        for words in host_commands(&piece.text) {
            assert_eq!(
                check_command(&root, &mut helps, &words),
                Vec::<String>::new()
            );
        }
        assert_eq!(missing_paths(&root, &piece.text), Vec::<String>::new());
    }
}

/// The most lines a page under `docs/` may have, and the guide.
const PAGE_LINES: usize = 600;
const GUIDE_LINES: usize = 300;

/// The pages under `docs/` longer than they may be, as `page: N lines`.
fn long_pages(root: &Path) -> Vec<String> {
    pages(root)
        .iter()
        .filter(|page| page.starts_with(root.join("docs")))
        .filter_map(|page| {
            let lines = std::fs::read_to_string(page)
                .expect("a tracked page reads")
                .lines()
                .count();
            let name = page.strip_prefix(root).unwrap_or(page);
            let most = if name == Path::new("docs/guide.md") {
                GUIDE_LINES
            } else {
                PAGE_LINES
            };
            (lines > most).then(|| format!("{}: {lines} lines (at most {most})", name.display()))
        })
        .collect()
}

#[test]
fn every_page_under_docs_has_at_most_600_lines_and_the_guide_at_most_300() {
    let root = repository();
    assert!(
        root.join("docs/guide.md").is_file(),
        "docs/guide.md, the user guide, is missing"
    );
    let long = long_pages(&root);
    assert!(
        long.is_empty(),
        "pages too long (split them by purpose; history belongs in git):\n{}",
        long.join("\n")
    );
}

/// Whether a heading names a date (`2026-12-02`, `2026/12/02`) or a
/// sitting: a page says what is, and git keeps when it was done.
fn dated_heading(heading: &str) -> bool {
    let bytes = heading.as_bytes();
    let date = (0..bytes.len()).any(|at| {
        let digits = |from: usize, n: usize| {
            bytes
                .get(from..from + n)
                .is_some_and(|d| d.iter().all(u8::is_ascii_digit))
        };
        let dash = |i: usize| matches!(bytes.get(i), Some(b'-' | b'/'));
        digits(at, 4) && dash(at + 4) && digits(at + 5, 2) && dash(at + 7) && digits(at + 8, 2)
    });
    let sitting = heading
        .to_lowercase()
        .split(|c: char| !c.is_alphanumeric())
        .any(|word| word == "sitting" || word == "sittings");
    date || sitting
}

/// The headings of a markdown page (outside code blocks), with their lines.
fn headings(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let hashes = line.len() - line.trim_start_matches('#').len();
        if !fenced && (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            found.push((i + 1, line));
        }
    }
    found
}

#[test]
fn no_heading_carries_a_date_or_a_sitting() {
    let root = repository();
    let mut problems = Vec::new();
    for page in pages(&root) {
        let text = std::fs::read_to_string(&page).expect("a tracked page reads");
        let name = page
            .strip_prefix(&root)
            .unwrap_or(&page)
            .display()
            .to_string();
        for (line, heading) in headings(&text) {
            if dated_heading(heading) {
                problems.push(format!("{name}:{line}: {heading}"));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "headings that date their section (say what is; git keeps when):\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_heading_check_finds_a_date_and_a_sitting_but_not_a_comment_in_code() {
    let page = "# Speed\n\n## 2026-12-02, evening: the camera\n\n### The camera (2026/12/01)\n\n## Earlier sittings\n\n```sh\n# a comment, 2026-12-02, one sitting\n```\n\n## The standard step, 24,828 instructions\n#not a heading 2026-12-02\n";
    let dated: Vec<usize> = headings(page)
        .into_iter()
        .filter(|(_, heading)| dated_heading(heading))
        .map(|(line, _)| line)
        .collect();
    assert_eq!(dated, [3, 5, 7]);
    assert_eq!(headings(page).len(), 5);
}
