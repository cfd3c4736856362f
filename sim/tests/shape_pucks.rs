//! The puck rule (`sim::scenario::puck_rule`) gives every shape of the
//! published results on the TV (`tv75`) the count those results were run
//! with, places that count on the shape reaching success and one more (up
//! to the arena's 12) not, and refuses a shape too small for six pucks.

use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::puck_rule::{rule_pucks, Placement, LEAST_PUCKS};
use sim::scenario::Arena;
use sim::scenario::ScenarioError;

/// The counts the published trials and tables were run with, by shape: the
/// TV's report (the annulus, the thesis' T, L, V, X and Z, our I), our T,
/// L and X, and our T and L turned or mirrored.
const PUBLISHED: [(&str, usize); 14] = [
    ("annulus", 12),
    ("thesis:T", 12),
    ("thesis:L", 12),
    ("thesis:V", 12),
    ("thesis:X", 12),
    ("thesis:Z", 12),
    ("letter:I", 11),
    ("letter:T", 10),
    ("letter:L", 12),
    ("letter:X", 12),
    ("letter:T@rot90", 9),
    ("letter:T@rot180", 10),
    ("letter:L@mirror", 12),
    ("letter:L@rot180", 12),
];

fn tv() -> Arena {
    Arena::Screen(Box::new(ArenaSpec::tv75()))
}

#[test]
fn every_published_shape_gets_the_count_its_results_were_run_with() {
    let wrong: Vec<String> = PUBLISHED
        .iter()
        .filter_map(|&(name, published)| {
            let field: FieldSource = name.parse().unwrap();
            let n = rule_pucks(&field, &tv()).unwrap();
            (n != published).then(|| format!("{name}: rule {n}, published {published}"))
        })
        .collect();
    assert!(wrong.is_empty(), "{wrong:?}");
}

#[test]
fn the_count_reaches_success_on_the_shape_and_one_more_puck_does_not() {
    for &(name, n) in &PUBLISHED {
        let placement = Placement::new(&name.parse().unwrap(), &tv()).unwrap();
        assert_eq!(placement.cap, 12);
        assert!(placement.reaches_success(n), "{name} with {n} pucks");
        if n < placement.cap {
            assert!(!placement.reaches_success(n + 1), "{name} with {}", n + 1);
        }
    }
}

#[test]
fn an_image_gets_a_count_by_the_same_rule_as_a_letter() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bar.png");
    // a bright horizontal bar across the middle of a dark image
    let img = image::GrayImage::from_fn(64, 64, |_, y| {
        image::Luma([if (24..40).contains(&y) { 255 } else { 0 }])
    });
    img.save(&path).unwrap();
    let field = FieldSource::Image(path);
    let n = rule_pucks(&field, &tv()).unwrap();
    assert!((LEAST_PUCKS..=12).contains(&n), "{n}");
    assert!(Placement::new(&field, &tv()).unwrap().reaches_success(n));
}

#[test]
fn a_shape_too_small_for_six_pucks_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dot.png");
    // one bright pixel: room on the shape for hardly a puck
    let img = image::GrayImage::from_fn(64, 64, |x, y| {
        image::Luma([if (x, y) == (32, 32) { 255 } else { 0 }])
    });
    img.save(&path).unwrap();
    let field = FieldSource::Image(path);
    let e = rule_pucks(&field, &tv()).unwrap_err();
    assert!(matches!(e, ScenarioError::TooFewPucks { most, .. } if most < LEAST_PUCKS));
    assert!(e.to_string().contains("dot.png"), "{e}");
}

#[test]
fn a_field_that_cannot_be_loaded_is_an_error_naming_it() {
    let field = FieldSource::Image("no-such-image.png".into());
    let e = rule_pucks(&field, &tv()).unwrap_err();
    assert!(e.to_string().contains("no-such-image.png"), "{e}");
}
