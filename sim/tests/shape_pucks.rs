//! Each shape of the TV's report takes its puck count
//! (`sim::scenario::shape_pucks`): pucks placed with every centre on the
//! shape reach the success Eval, and one more puck (up to the arena's 12)
//! placed the same way does not.
//!
//! The arrangement: the candidate centres of a half-unit grid over the
//! floor, a puck's radius from the walls, in order of their distance from
//! the shape's band (`thresholds`; on a letter `1 - value`, so the
//! brightest first), each kept if it does not overlap a puck kept before.
//! "On the shape": inside the band on the annulus, a field value of at
//! least [`ON_A_LETTER`] on a letter.

use sim::base::vec2::Vec2;
use sim::config::Thresholds;
use sim::episodes::eval::eval;
use sim::fields::source::FieldSource;
use sim::scenario::shape_pucks::{training_shapes, turned_shapes, tv_pucks, tv_shapes};
use sim::scenario::{arena::ArenaSpec, Arena, Scenario};
use sim::world::World;

/// The least field value of a letter's shape (the letters' fields fall off
/// from 1 on the stroke).
const ON_A_LETTER: f32 = 0.8;

/// How far a value lies from the band `[T_o, T_i]`.
fn band_distance(v: f32, t: &Thresholds) -> f64 {
    let v = f64::from(v);
    (t.outie - v).max(v - t.innie).max(0.0)
}

/// `n` pucks placed on `field` on the TV: their Eval, the success Eval,
/// and whether every centre is on the shape.
fn placed(field: &FieldSource, n: usize) -> (f64, f64, bool) {
    let scenario = Scenario {
        field: field.clone(),
        arena: Arena::Screen(Box::new(ArenaSpec::tv75())),
        pucks: Some(n),
        ..Scenario::default()
    };
    let prepared = scenario.prepare().unwrap();
    let c = prepared.config();
    let (layout, shape, t) = (c.world.field_layout(), prepared.field(), &c.thresholds);
    let r = c.world.puck_radius;
    let mut candidates = Vec::new();
    let (mut y, step) = (r, 0.5);
    while y <= c.world.arena_height - r {
        let mut x = r;
        while x <= c.world.arena_width - r {
            let p = Vec2::new(x, y);
            candidates.push((shape.evaluate(p, &layout), p));
            x += step;
        }
        y += step;
    }
    // stable: equal distances keep the grid's order
    candidates.sort_by(|a, b| band_distance(a.0, t).total_cmp(&band_distance(b.0, t)));
    let mut kept: Vec<(f32, Vec2)> = Vec::new();
    for (v, p) in candidates {
        if kept.len() == n {
            break;
        }
        if kept.iter().all(|(_, q)| (p - *q).length() >= 2.0 * r) {
            kept.push((v, p));
        }
    }
    assert_eq!(kept.len(), n, "{field}: room for {} pucks only", kept.len());
    let on_shape = kept.iter().all(|&(v, _)| {
        if *field == FieldSource::Annulus {
            band_distance(v, t) == 0.0
        } else {
            v >= ON_A_LETTER
        }
    });
    let pucks: Vec<Vec2> = kept.iter().map(|&(_, p)| p).collect();
    let world = World::scene(c, &[], &pucks, 1);
    (eval(&world, shape, t), c.episode.success_eval, on_shape)
}

/// `field`'s count reaches success with every puck on the shape; one more
/// does not, unless the count is already the arena's 12.
fn check(field: &str) {
    let field: FieldSource = field.parse().unwrap();
    let n = tv_pucks(&field).unwrap();
    assert!((6..=12).contains(&n), "{field}: {n}");
    let (e, success, on_shape) = placed(&field, n);
    assert!(on_shape, "{field}: a puck's centre is off the shape");
    assert!(e > success, "{field} with {n} pucks: Eval {e} <= {success}");
    if n < 12 {
        let (e, success, _) = placed(&field, n + 1);
        assert!(e <= success, "{field} with {} pucks: Eval {e}", n + 1);
    }
}

#[test]
fn twelve_pucks_on_the_annulus_reach_success() {
    check("annulus");
}

#[test]
fn twelve_pucks_on_the_thesis_t_reach_success() {
    check("thesis:T");
}

#[test]
fn twelve_pucks_on_the_thesis_l_reach_success() {
    check("thesis:L");
}

#[test]
fn twelve_pucks_on_the_thesis_v_reach_success() {
    check("thesis:V");
}

#[test]
fn twelve_pucks_on_the_thesis_x_reach_success() {
    check("thesis:X");
}

#[test]
fn twelve_pucks_on_the_thesis_z_reach_success() {
    check("thesis:Z");
}

#[test]
fn eleven_pucks_on_our_i_reach_success_and_twelve_do_not() {
    check("letter:I");
}

#[test]
fn ten_pucks_on_our_t_reach_success_and_eleven_do_not() {
    check("letter:T");
}

#[test]
fn twelve_pucks_on_our_l_reach_success() {
    check("letter:L");
}

#[test]
fn twelve_pucks_on_our_x_reach_success() {
    check("letter:X");
}

#[test]
fn nine_pucks_on_our_t_turned_a_quarter_reach_success_and_ten_do_not() {
    check("letter:T@rot90");
}

#[test]
fn ten_pucks_on_our_t_upside_down_reach_success_and_eleven_do_not() {
    check("letter:T@rot180");
}

#[test]
fn twelve_pucks_on_our_l_mirrored_reach_success() {
    check("letter:L@mirror");
}

#[test]
fn twelve_pucks_on_our_l_upside_down_reach_success() {
    check("letter:L@rot180");
}

#[test]
fn every_shape_searched_on_but_not_reported_is_checked_above() {
    let names: Vec<String> = training_shapes().map(|(f, _)| f.to_string()).collect();
    assert_eq!(names, ["letter:T", "letter:L", "letter:X"]);
    let names: Vec<String> = turned_shapes().map(|(f, _)| f.to_string()).collect();
    assert_eq!(
        names,
        [
            "letter:T@rot90",
            "letter:T@rot180",
            "letter:L@mirror",
            "letter:L@rot180"
        ]
    );
}

#[test]
fn every_shape_of_the_report_is_checked_above() {
    let names: Vec<String> = tv_shapes().map(|(f, _)| f.to_string()).collect();
    assert_eq!(
        names,
        ["annulus", "thesis:T", "thesis:L", "thesis:V", "thesis:X", "thesis:Z", "letter:I"]
    );
}

#[test]
fn the_policy_search_page_gives_every_count() {
    let page = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/policy-search.md"),
    )
    .unwrap();
    for (field, pucks) in tv_shapes().chain(training_shapes()).chain(turned_shapes()) {
        let row = format!("| {field} | {pucks} |");
        assert!(page.contains(&row), "docs/policy-search.md lacks {row}");
    }
}
