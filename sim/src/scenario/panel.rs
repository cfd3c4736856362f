//! The panel image: what each pixel of a screen arena shows, the one
//! picture the simulator's arena model assumes (`host field export` writes
//! it, `host display` shows it; `docs/display.md`).
//!
//! Pixel `(i, j)` shows the field value `v` the simulator reads at the
//! pixel's centre (`ArenaSpec::panel_pixel_centre`, [`ScalarField::shown`]
//! with the arena's [`ArenaSpec::field_layout`]: bilinear between the field
//! image's pixel centres, black outside its frame), as the 8-bit level
//! `panel_level`: `round(255 v ^ (LIGHT_GAMMA / display_gamma))`. The
//! display turns level `p` into the light `(p / 255) ^ display_gamma` of
//! its full white, so the light is `v ^ LIGHT_GAMMA` (to the level's
//! rounding), the light curve the robots' calibration inverts
//! ([`shared::calibration`]) and the simulator's photo-transistor model
//! assumes (`field.gamma`, 2.2 by default). With a display gamma equal to
//! `LIGHT_GAMMA` the level is `round(255 v)`.

use crate::base::gain_grid::GainGrid;
use crate::base::vec2::Vec2;
use crate::fields::ScalarField;
use crate::scenario::arena::ArenaSpec;
use crate::scenario::flat_field;
use image::{GrayImage, Luma};
use shared::calibration::LIGHT_GAMMA;

/// The exponent that turns a field value into a panel level's fraction of
/// white on a display of gamma `display_gamma`: `LIGHT_GAMMA /
/// display_gamma`, exactly 1 when the display's gamma is `LIGHT_GAMMA`
/// (equal at `LIGHT_GAMMA`'s f32 precision: the constant is an f32).
pub(crate) fn level_exponent(display_gamma: f64) -> f64 {
    if display_gamma as f32 == LIGHT_GAMMA {
        1.0
    } else {
        f64::from(LIGHT_GAMMA) / display_gamma
    }
}

/// The 8-bit level that shows field value `v` (clamped to [0, 1]) with the
/// light `v ^ LIGHT_GAMMA` on a display of gamma `display_gamma`:
/// `round(255 v ^ level_exponent(display_gamma))`.
#[cfg(test)]
pub(crate) fn panel_level(v: f64, display_gamma: f64) -> u8 {
    level_of(v, level_exponent(display_gamma))
}

fn level_of(v: f64, exponent: f64) -> u8 {
    let v = if v > 0.0 { v.min(1.0) } else { 0.0 };
    let fraction = if exponent == 1.0 { v } else { v.powf(exponent) };
    (255.0 * fraction).round() as u8
}

/// The panel image of `field` on `arena`: `screen_px` pixels, each the
/// `panel_level` of the field value at its centre; with the panel's
/// measured gain `flat`, the value times its [`flat_field::value_scale`]
/// (an evenly lit panel).
pub fn panel_image(arena: &ArenaSpec, field: &ScalarField, flat: Option<&GainGrid>) -> GrayImage {
    let layout = arena.field_layout(field);
    image_of(arena, flat, |p| field.shown(p, &layout))
}

/// Full white on `arena`, evened out for the panel's measured gain `flat`
/// if given: the white screen of the robots' calibration, which must be
/// the field's white.
pub fn white_image(arena: &ArenaSpec, flat: Option<&GainGrid>) -> GrayImage {
    image_of(arena, flat, |_| 1.0)
}

fn image_of(arena: &ArenaSpec, flat: Option<&GainGrid>, value: impl Fn(Vec2) -> f64) -> GrayImage {
    let exponent = level_exponent(arena.display_gamma);
    let size = arena.size();
    GrayImage::from_fn(arena.screen_px[0], arena.screen_px[1], |i, j| {
        let p = arena.panel_pixel_centre(i, j);
        let scale = flat.map_or(1.0, |grid| flat_field::value_scale(grid, p, size));
        Luma([level_of(value(p) * scale, exponent)])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::arena::FieldFit;

    #[test]
    fn levels_are_identity_at_the_light_gamma_and_pre_compensate_other_displays() {
        for k in 0..=255u8 {
            assert_eq!(panel_level(f64::from(k) / 255.0, 2.2), k);
        }
        assert_eq!(panel_level(-0.5, 1.8), 0);
        assert_eq!(panel_level(1.5, 1.8), 255);
        // A display of gamma 2.4 shows level p as the light (p / 255)^2.4:
        // each value's light v^2.2 lies within half a level of its level's.
        for k in 1..=100 {
            let v = f64::from(k) / 100.0;
            let level = f64::from(panel_level(v, 2.4));
            let light = |p: f64| (p / 255.0).powf(2.4);
            assert!(
                light(level - 0.5) <= v.powf(2.2) && v.powf(2.2) <= light(level + 0.5),
                "{v}: level {level}"
            );
        }
        assert_eq!(panel_level(0.5, 1.1), (255.0 * 0.25f64).round() as u8);
    }

    #[test]
    fn each_panel_pixel_shows_the_field_at_its_centre_and_black_outside_the_frame() {
        // 8 x 4 panel pixels over a 2 x 2 field, kept in aspect: the field
        // covers the middle 4 x 4 pixels; each field pixel spans 2 x 2
        // panel pixels, so panel pixel centres lie a quarter of a field
        // pixel from its centre, interpolating towards the neighbour.
        let arena = ArenaSpec {
            screen_mm: [80.0, 40.0],
            screen_px: [8, 4],
            ..ArenaSpec::tv75()
        };
        let field = ScalarField::new(2, 2, vec![0.0, 1.0, 0.5, 1.0]).unwrap();
        let image = panel_image(&arena, &field, None);
        assert_eq!(image.dimensions(), (8, 4));
        let row = |j| (0..8).map(|i| image.get_pixel(i, j)[0]).collect::<Vec<_>>();
        // Row 0 lies on the field's top row (edge pixels extend to the border).
        assert_eq!(row(0), [0, 0, 0, 64, 191, 255, 0, 0]);
        // Row 1: a quarter of the way down to the bottom row (0.5, 1.0).
        assert_eq!(row(1), [0, 0, 32, 88, 199, 255, 0, 0]);
        let stretched = ArenaSpec {
            fit: FieldFit::Stretch,
            ..arena
        };
        let image = panel_image(&stretched, &field, None);
        assert_eq!(image.get_pixel(0, 0)[0], 0);
        assert_eq!(image.get_pixel(7, 0)[0], 255);
    }

    #[test]
    fn a_measured_gain_dims_each_pixel_to_the_dimmest_points_light_and_white_alike() {
        // 8 x 6 pixels, gain 0.9 at the top-left point, 1 elsewhere: where
        // the panel is brighter, the level shows less, so the light
        // (p / 255)^2.2 times the gain is the dimmest point's
        let arena = ArenaSpec {
            screen_mm: [80.0, 60.0],
            screen_px: [8, 6],
            fit: FieldFit::Stretch,
            ..ArenaSpec::tv75()
        };
        let mut gain = GainGrid::uniform(4, 3, 1.0);
        gain.gains[0] = 0.9;
        let white = white_image(&arena, Some(&gain));
        assert_eq!(white.get_pixel(0, 0)[0], 255);
        let far = f64::from(white.get_pixel(7, 5)[0]);
        assert_eq!(far, (255.0 * 0.9f64.powf(1.0 / 2.2)).round());
        assert!(white_image(&arena, None).pixels().all(|p| p[0] == 255));
        let field = ScalarField::new(2, 2, vec![0.5; 4]).unwrap();
        let grey = panel_image(&arena, &field, Some(&gain));
        let size = arena.size();
        for (i, j, level) in grey.enumerate_pixels() {
            let g = gain.at(arena.panel_pixel_centre(i, j), size);
            let light = (f64::from(level[0]) / 255.0).powf(2.2) * g;
            // within a level's rounding of half grey's light on the dimmest point
            assert!(
                (light / (0.5f64.powf(2.2) * 0.9) - 1.0).abs() < 0.02,
                "{i},{j}"
            );
        }
    }
}
