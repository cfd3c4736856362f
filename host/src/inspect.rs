//! Human-readable rendering of a policy blob, and the fields a searched
//! table was scored on, from its search log (`<name>.search.json`, the
//! JSON `host search` writes: `world.field`, `search.also_field` and
//! `result`, the packed table).

use shared::{PolicyBlob, StateHasher};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Where the shipped policies' search logs are, from the repository's root.
pub const PUBLISHED_LOGS: &str = "docs/policy-search/runs";

/// The blob's header ([`summary`]), then one line per state with its
/// decoded inputs (the role too, for a hasher that has the role bit) and
/// action, or its best actions (`0|2`) where they tie.
pub fn render(blob: &PolicyBlob) -> String {
    let mut out = summary(blob);
    let a = blob.actions();
    let _ = writeln!(out);
    let obstacle = blob.hasher() == StateHasher::OriginalObstacle;
    let role = blob.hasher().has_role_bit();
    let _ = writeln!(
        out,
        "state  puckL puckR  L<M R<M  mid-bin{}{}  action  omega",
        if obstacle { "  obsL obsR" } else { "" },
        if role { "  role " } else { "" }
    );
    for ((state, action), (_, mask)) in blob.table().entries().zip(blob.sets().masks()) {
        let Some(i) = blob.hasher().unpack(state) else {
            continue;
        };
        let flag = |b: bool| if b { "  x  " } else { "  .  " };
        let _ = write!(
            out,
            "{:>5}  {} {}  {} {}  {:>7}",
            state.0,
            flag(i.puck_left),
            flag(i.puck_right),
            if i.left_below_mid { " x " } else { " . " },
            if i.right_below_mid { " x " } else { " . " },
            i.mid_bin
        );
        if obstacle {
            let _ = write!(
                out,
                "  {} {}",
                flag(i.obstacle_left),
                flag(i.obstacle_right)
            );
        }
        if role {
            let _ = write!(out, "  {}", role_name(i.innie));
        }
        if mask.count_ones() > 1 {
            // a tie: the robot picks one of these uniformly
            let _ = writeln!(out, "  {:>6}  tie", set_text(mask));
        } else {
            let _ = writeln!(
                out,
                "  {:>6}  {:+.3}",
                action.0,
                a.angular(action).unwrap_or(f32::NAN)
            );
        }
    }
    out
}

/// A set of actions as `0|2|3`.
fn set_text(mask: u8) -> String {
    (0..4u8)
        .filter(|a| mask & (1 << a) != 0)
        .map(|a| a.to_string())
        .collect::<Vec<_>>()
        .join("|")
}

/// The blob's header: format, hasher, actions, provenance, what it was
/// trained for, how many states have tied best actions, and how many
/// states choose each action (their lowest best action) (for a hasher with the role bit, also per
/// role): `host policy inspect --summary`.
pub fn summary(blob: &PolicyBlob) -> String {
    let mut out = String::new();
    let p = blob.provenance();
    let a = blob.actions();
    let _ = writeln!(out, "format     QPOL v{}", blob.version());
    let _ = writeln!(
        out,
        "hasher     {} ({} states)",
        blob.hasher(),
        blob.hasher().num_states()
    );
    let _ = writeln!(
        out,
        "actions    {:?} rad/step, forward {} units/step",
        a.angular_speeds(),
        a.forward_speed()
    );
    // the blob's own strings are untrusted: a line break would forge a line
    let _ = writeln!(out, "field      {}", escaped(&p.field));
    let _ = writeln!(out, "name       {}", escaped(&p.name));
    let _ = writeln!(out, "trained    {} steps, seed {}", p.trainer_steps, p.seed);
    match blob.trained_for() {
        Some(t) => {
            let _ = writeln!(
                out,
                "for        sensors {}, arena {}",
                escaped(&t.sensors),
                escaped(&t.arena)
            );
        }
        None => {
            let _ = writeln!(out, "for        not recorded (sensors and arena unknown)");
        }
    }
    let mut by_size = [0usize; 5];
    for (_, mask) in blob.sets().masks() {
        by_size[mask.count_ones() as usize] += 1;
    }
    let _ = writeln!(
        out,
        "ties       {} states with 2 best actions, {} with 3, {} with 4 (the robot picks one uniformly: ChoiceRng)",
        by_size[2], by_size[3], by_size[4]
    );
    // [all, outies, innies]
    let mut histogram = [[0usize; 4]; 3];
    for (state, action) in blob.table().entries() {
        histogram[0][action.index()] += 1;
        if let Some(i) = blob.hasher().unpack(state) {
            histogram[1 + usize::from(i.innie)][action.index()] += 1;
        }
    }
    let _ = writeln!(
        out,
        "histogram  {:?} states per action",
        &histogram[0][..a.len()]
    );
    if blob.hasher().has_role_bit() {
        for innie in [false, true] {
            let _ = writeln!(
                out,
                "  {:<8} {:?}",
                format!("{}s", role_name(innie)),
                &histogram[1 + usize::from(innie)][..a.len()]
            );
        }
    }
    out
}

/// A role as the table shows it.
fn role_name(innie: bool) -> &'static str {
    if innie {
        "innie"
    } else {
        "outie"
    }
}

/// `s` as it is safe to print on a terminal: control characters (line
/// breaks, terminal escape sequences) and the invisible direction marks
/// and overrides written as Rust escapes (`\n`, `\u{1b}`, `\u{202e}`),
/// a backslash doubled so that an escape cannot be forged; the rest as is.
pub fn escaped(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        let bidi = matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
        if c == '\\' || c.is_control() {
            out.extend(c.escape_default());
        } else if bidi {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

/// `text` (a [`summary`] or [`render`] of `blob`, read from `file`) with,
/// after its field line, every field a searched table was scored on, when
/// its search log is found: `<name>.search.json` beside `file` (where
/// `host search` writes it) or in [`PUBLISHED_LOGS`], and the log's result
/// is this blob's table. The blob itself records only the first field.
pub fn with_search_log(text: &str, blob: &PolicyBlob, file: &Path) -> String {
    let Some((fields, log)) = search_log(blob, file) else {
        return text.to_string();
    };
    let line = format!(
        "searched   on {} fields: {} (its log {})",
        fields.len(),
        fields
            .iter()
            .map(|f| escaped(f))
            .collect::<Vec<_>>()
            .join(", "),
        log.display()
    );
    let mut out = String::new();
    for l in text.lines() {
        out.push_str(l);
        out.push('\n');
        if l.starts_with("field      ") {
            out.push_str(&line);
            out.push('\n');
        }
    }
    out
}

/// The fields of the search log of `blob` and the log's path, if one is
/// found whose result is the blob's table.
fn search_log(blob: &PolicyBlob, file: &Path) -> Option<(Vec<String>, PathBuf)> {
    let name = format!("{}.search.json", blob.provenance().name);
    let beside = file.parent().map(|d| d.join(&name));
    let published = Path::new(PUBLISHED_LOGS).join(&name);
    beside.into_iter().chain([published]).find_map(|path| {
        let log: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).ok()?).ok()?;
        let result: Vec<u8> = serde_json::from_value(log["result"].clone()).ok()?;
        if result != blob.table().packed() {
            return None;
        }
        let first = log["world"]["field"].as_str()?.to_string();
        let also: Vec<String> =
            serde_json::from_value(log["search"]["also_field"].clone()).unwrap_or_default();
        Some((std::iter::once(first).chain(also).collect(), path))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::{ActionTable, PolicyTable, Provenance};

    #[test]
    fn a_blobs_strings_are_printed_escaped_and_cannot_forge_a_line() {
        let provenance = Provenance::new(
            "annulus\nhasher     FAKE",
            "\u{1b}[2J\u{202e}evil\\n",
            10,
            1,
        )
        .unwrap();
        let table = PolicyTable::new(StateHasher::Original);
        let blob = PolicyBlob::new(ActionTable::default(), table, provenance).unwrap();
        let text = render(&blob);
        assert_eq!(
            text.lines().filter(|l| l.starts_with("hasher")).count(),
            1,
            "{text}"
        );
        assert!(!text.contains(['\u{1b}', '\u{202e}']), "{text}");
        assert!(
            text.contains("field      annulus\\nhasher     FAKE\n"),
            "{text}"
        );
        assert!(
            text.contains("name       \\u{1b}[2J\\u{202e}evil\\\\n\n"),
            "{text}"
        );
    }

    #[test]
    fn the_summary_is_the_header_and_a_role_table_shows_each_states_role() {
        let provenance = Provenance::new("annulus", "role", 10, 1).unwrap();
        let mut table = PolicyTable::new(StateHasher::OriginalRole);
        // an innie's state: bit 8 set
        table.set(shared::State(256), shared::ActionId(2));
        let blob = PolicyBlob::new(ActionTable::default(), table, provenance).unwrap();
        let short = summary(&blob);
        let full = render(&blob);
        assert!(full.starts_with(&short), "{full}");
        assert!(!short.contains("state  puckL"), "{short}");
        assert!(
            short.contains("histogram  [511, 0, 1, 0]")
                && short.contains("  outies   [256, 0, 0, 0]")
                && short.contains("  innies   [255, 0, 1, 0]"),
            "{short}"
        );
        assert!(full.contains("  role   action  omega"), "{full}");
        let rows: Vec<&str> = full.lines().filter(|l| l.starts_with("  256 ")).collect();
        assert_eq!(rows.len(), 1, "{full}");
        assert!(
            rows[0].contains("innie") && rows[0].contains("-0.150"),
            "{full}"
        );
        assert!(full
            .lines()
            .any(|l| l.starts_with("  255 ") && l.contains("outie")));
    }
}
