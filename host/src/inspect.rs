//! Human-readable rendering of a policy blob.

use shared::{PolicyBlob, StateHasher};
use std::fmt::Write;

/// The blob's header, then one line per state with its decoded inputs and action.
pub fn render(blob: &PolicyBlob) -> String {
    let mut out = String::new();
    let p = blob.provenance();
    let a = blob.actions();
    let _ = writeln!(out, "format     QPOL v{}", PolicyBlob::VERSION);
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
    let _ = writeln!(out, "field      {}", p.field);
    let _ = writeln!(out, "name       {}", p.name);
    let _ = writeln!(out, "trained    {} steps, seed {}", p.trainer_steps, p.seed);
    let mut histogram = [0usize; 4];
    for (_, action) in blob.table().entries() {
        histogram[action.index()] += 1;
    }
    let _ = writeln!(
        out,
        "histogram  {:?} states per action",
        &histogram[..a.len()]
    );
    let _ = writeln!(out);
    let obstacle = blob.hasher() == StateHasher::OriginalObstacle;
    let _ = writeln!(
        out,
        "state  puckL puckR  L<M R<M  mid-bin{}  action  omega",
        if obstacle { "  obsL obsR" } else { "" }
    );
    for (state, action) in blob.table().entries() {
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
        let _ = writeln!(
            out,
            "  {:>6}  {:+.3}",
            action.0,
            a.angular(action).unwrap_or(f32::NAN)
        );
    }
    out
}
