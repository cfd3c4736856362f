//! How many pucks each shape gets on the TV (`tv75`): the most, up to the
//! arena's 12, for which an arrangement with every puck's centre on the
//! shape reaches the success Eval; never fewer than 6 (issue 31, item 1).
//! Fixed here before any training, the same for orbital construction and
//! every policy. The general table is also searched on our generated T, L
//! and X (the same shapes as the thesis' images, drawn as our I is), whose
//! counts follow the same rule ([`TRAINING_SHAPE_PUCKS`]), and on our T
//! and L turned or mirrored ([`TURNED_SHAPE_PUCKS`]).
//! `sim/tests/shape_pucks.rs` places each count (and one more) and checks
//! it; `docs/policy-search.md` gives the tables.

use crate::fields::source::FieldSource;

/// The shapes of the TV's report and their puck counts, in the report's
/// order: the annulus, the thesis' T, L, V, X and Z (its images), our I.
pub const TV_SHAPE_PUCKS: [(&str, usize); 7] = [
    ("annulus", 12),
    ("thesis:T", 12),
    ("thesis:L", 12),
    ("thesis:V", 12),
    ("thesis:X", 12),
    ("thesis:Z", 12),
    ("letter:I", 11),
];

/// Shapes searched on but not in the report, and their puck counts by the
/// report's rule: our generated T, L and X, which the general table is
/// searched on beside the thesis' images of the same letters.
pub const TRAINING_SHAPE_PUCKS: [(&str, usize); 3] =
    [("letter:T", 10), ("letter:L", 12), ("letter:X", 12)];

/// Shapes searched on for geometry the letters as given lack, and their
/// puck counts by the report's rule: our T and L turned or mirrored
/// (`sim::fields::turn`). None is a turn of the report's held-out I, V or
/// Z, and turning takes no puck count with it (our T takes 10, turned a
/// quarter 9: the placement's grid meets the strokes differently).
pub const TURNED_SHAPE_PUCKS: [(&str, usize); 4] = [
    ("letter:T@rot90", 9),
    ("letter:T@rot180", 10),
    ("letter:L@mirror", 12),
    ("letter:L@rot180", 12),
];

/// The puck count of `field` on the TV, if it is one of the report's
/// shapes ([`TV_SHAPE_PUCKS`]) or searched on ([`TRAINING_SHAPE_PUCKS`],
/// [`TURNED_SHAPE_PUCKS`]).
pub fn tv_pucks(field: &FieldSource) -> Option<usize> {
    tv_shapes()
        .chain(training_shapes())
        .chain(turned_shapes())
        .find(|(shape, _)| shape == field)
        .map(|(_, pucks)| pucks)
}

/// The report's shapes as field sources, with their counts.
pub fn tv_shapes() -> impl Iterator<Item = (FieldSource, usize)> {
    as_sources(&TV_SHAPE_PUCKS)
}

/// The training-only shapes as field sources, with their counts.
pub fn training_shapes() -> impl Iterator<Item = (FieldSource, usize)> {
    as_sources(&TRAINING_SHAPE_PUCKS)
}

/// The turned training shapes as field sources, with their counts.
pub fn turned_shapes() -> impl Iterator<Item = (FieldSource, usize)> {
    as_sources(&TURNED_SHAPE_PUCKS)
}

/// A table of shape names and counts as field sources and counts.
fn as_sources(
    table: &'static [(&'static str, usize)],
) -> impl Iterator<Item = (FieldSource, usize)> {
    table
        .iter()
        .filter_map(|&(name, pucks)| Some((name.parse().ok()?, pucks)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::letters::Letter;

    #[test]
    fn every_shape_of_the_report_and_of_training_has_its_count_and_others_none() {
        assert_eq!(tv_shapes().count(), TV_SHAPE_PUCKS.len());
        assert_eq!(tv_pucks(&FieldSource::Letter(Letter::I)), Some(11));
        assert_eq!(tv_pucks(&FieldSource::Thesis(Letter::T)), Some(12));
        assert_eq!(tv_pucks(&FieldSource::Letter(Letter::T)), Some(10));
        assert_eq!(tv_pucks(&FieldSource::Letter(Letter::V)), None);
        assert_eq!(training_shapes().count(), TRAINING_SHAPE_PUCKS.len());
        assert_eq!(turned_shapes().count(), TURNED_SHAPE_PUCKS.len());
        assert_eq!(tv_pucks(&"letter:T@rot90".parse().unwrap()), Some(9));
        assert!(TV_SHAPE_PUCKS
            .iter()
            .chain(&TRAINING_SHAPE_PUCKS)
            .chain(&TURNED_SHAPE_PUCKS)
            .all(|&(_, n)| (6..=12).contains(&n)));
    }
}
