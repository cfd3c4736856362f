//! The image's checks before any search: the field inverted with
//! `--invert` (written as `DIR/NAME.field.png`, the field the run then
//! uses), the dark-on-light check, and the puck count by the puck rule
//! ([`sim::scenario::puck_rule`]).
//!
//! Dark on light: the brightest region, the cells whose value lies in the
//! top fifth of the image's range (as the puck rule's "on the shape" is a
//! value of at least 0.8), covers at least [`MOST_OF_THE_IMAGE`] of the
//! cells or at least [`MOST_OF_THE_BORDER`] of the border's cells. A shape
//! drawn light on dark (as the built-in fields are) touches the border
//! with a stroke's end at most.

use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
use sim::fields::source::FieldSource;
use sim::fields::ScalarField;
use sim::scenario::puck_rule::rule_pucks;
use std::path::Path;

/// Share of the image's cells the brightest region may cover.
pub const MOST_OF_THE_IMAGE: f64 = 0.5;

/// Share of the border's cells the brightest region may cover.
pub const MOST_OF_THE_BORDER: f64 = 0.25;

/// Why a field looks drawn dark on light, if it does.
pub fn dark_on_light(field: &ScalarField) -> Option<String> {
    let values = field.values();
    let (lo, hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let bright = |v: f32| v >= lo + 0.8 * (hi - lo);
    let (w, h) = (field.width() as i64, field.height() as i64);
    let border: Vec<f32> = (0..w)
        .flat_map(|x| [(x, 0), (x, h - 1)])
        .chain((1..h - 1).flat_map(|y| [(0, y), (w - 1, y)]))
        .map(|(x, y)| field.cell(x, y))
        .collect();
    let share = |cells: &[f32]| {
        cells.iter().filter(|&&v| bright(v)).count() as f64 / cells.len().max(1) as f64
    };
    let (area, edge) = (share(values), share(&border));
    if area >= MOST_OF_THE_IMAGE {
        Some(format!(
            "its brightest region covers {:.0} % of it",
            area * 100.0
        ))
    } else if edge >= MOST_OF_THE_BORDER {
        Some(format!(
            "its brightest region covers {:.0} % of its border",
            edge * 100.0
        ))
    } else {
        None
    }
}

/// The field with every value `v` turned into `1 - v`, as an RGB image
/// whose channels' mean is that value to within 1/510.
fn inverted(field: &ScalarField) -> image::RgbImage {
    let (w, h) = (field.width() as u32, field.height() as u32);
    image::RgbImage::from_fn(w, h, |x, y| {
        let v = 1.0 - field.cell(i64::from(x), i64::from(y)).clamp(0.0, 1.0);
        let c = (v * 255.0).round() as u8;
        image::Rgb([c, c, c])
    })
}

/// The field the run uses and its puck count.
#[derive(Clone, Debug, PartialEq)]
pub struct Checked {
    /// The image as given, or with `--invert` the inverted one written.
    pub field: FieldSource,
    /// Pucks: `--pucks`, else the puck rule's count.
    pub pucks: usize,
}

/// Checks `config`'s field: inverted into `inverted_file` first with
/// `invert`; refused when it looks drawn dark on light (offering
/// `--invert`) or when fewer than six pucks placed on it reach success.
pub fn check(config: &TrainConfig, invert: bool, inverted_file: &Path) -> Result<Checked> {
    let given = &config.world.field;
    let loaded = given.load().with_context(|| format!("image {given}"))?;
    let field = if invert {
        crate::render::write_image(&inverted(&loaded), inverted_file)?;
        FieldSource::Image(inverted_file.to_path_buf())
    } else {
        given.clone()
    };
    let checked = field.load().with_context(|| format!("image {field}"))?;
    if let Some(why) = dark_on_light(&checked) {
        if invert {
            bail!(
                "image {given} inverted looks drawn dark on light ({why}): the shape must be the \
                 brightest part; try it without --invert"
            );
        }
        bail!(
            "image {given} looks drawn dark on light ({why}): the shape must be the brightest \
             part of the image; --invert flips it"
        );
    }
    let pucks = match config.world.pucks {
        Some(pucks) => pucks,
        None => {
            let arena = config.arena_choice().arena()?;
            rule_pucks(&field, &arena).with_context(|| format!("image {given} is refused"))?
        }
    };
    Ok(Checked { field, pucks })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 40 x 40 field: 1 on the cells `on` picks, else 0.
    fn drawn(on: impl Fn(usize, usize) -> bool) -> ScalarField {
        let values = (0..40 * 40)
            .map(|k| if on(k % 40, k / 40) { 1.0 } else { 0.0 })
            .collect();
        ScalarField::new(40, 40, values).unwrap()
    }

    #[test]
    fn no_built_in_shape_looks_dark_on_light() {
        for name in [
            "annulus", "thesis:T", "thesis:L", "thesis:V", "thesis:X", "thesis:Z", "letter:I",
            "letter:T",
        ] {
            let field = name.parse::<FieldSource>().unwrap().load().unwrap();
            assert_eq!(dark_on_light(&field), None, "{name}");
        }
    }

    #[test]
    fn a_bar_drawn_dark_on_light_is_named_and_one_touching_the_border_light_on_dark_is_not() {
        let bar = |x: usize, y: usize| (15..25).contains(&x) && y < 30;
        assert_eq!(
            dark_on_light(&drawn(bar)),
            None,
            "a stroke's end on the border"
        );
        let why = dark_on_light(&drawn(|x, y| !bar(x, y))).unwrap();
        assert!(why.contains("% of it"), "{why}");
        // a frame: little of the image, all of its border
        let frame = |x: usize, y: usize| x.min(y) < 2 || x.max(y) > 37;
        let why = dark_on_light(&drawn(frame)).unwrap();
        assert!(why.contains("of its border"), "{why}");
    }

    #[test]
    fn an_inverted_field_is_each_value_flipped() {
        let field = ScalarField::new(2, 1, vec![0.0, 0.75]).unwrap();
        let img = inverted(&field);
        assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(1, 0).0, [64, 64, 64]);
    }
}
