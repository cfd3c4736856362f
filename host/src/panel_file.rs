//! The panel image of a field on a screen arena as a PNG file
//! (`host field export`) or bytes (`host display` serves them), evened out
//! for the panel's measured gain when one is given
//! ([`sim::scenario::flat_field`]): the
//! picture [`sim::scenario::panel::panel_image`] defines, one 8-bit grey pixel per
//! panel pixel, with no colour profile or gamma chunk (a browser shows the
//! levels as they are).

use anyhow::{Context, Result};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{DynamicImage, GrayImage, ImageBuffer, Pixel, PixelWithColorType, RgbImage};
use sim::base::gain_grid::GainGrid;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use std::path::Path;

/// The panel image of `source` on `arena`, the field loaded as the
/// arena shows it ([`ArenaSpec::load_field`]), evened out for the panel's
/// measured gain `flat` if given.
pub fn panel_image(
    arena: &ArenaSpec,
    source: &FieldSource,
    flat: Option<&GainGrid>,
) -> Result<GrayImage> {
    let field = arena.load_field(source)?;
    Ok(sim::scenario::panel::panel_image(arena, &field, flat))
}

/// The panel image of `source` on `arena` in colour, with the outline of
/// the field's target band ([`sim::scenario::field_thresholds`]) drawn
/// over it in [`sim::render::BAND`]: a picture to look at, not to show the
/// robots (they would read the outline as field).
pub fn panel_image_with_band(
    arena: &ArenaSpec,
    source: &FieldSource,
    flat: Option<&GainGrid>,
) -> Result<RgbImage> {
    let field = arena.load_field(source)?;
    let (layout, thresholds) = (
        arena.field_layout(&field),
        sim::scenario::field_thresholds(source),
    );
    let mut image =
        DynamicImage::ImageLuma8(sim::scenario::panel::panel_image(arena, &field, flat))
            .into_rgb8();
    sim::render::outline_region(&mut image, sim::render::BAND, |i, j| {
        let value = field.shown(arena.panel_pixel_centre(i, j), &layout);
        sim::episodes::eval::in_band(value, &thresholds)
    });
    Ok(image)
}

/// `image` encoded as a PNG.
pub fn encode_png<P>(image: &ImageBuffer<P, Vec<u8>>) -> Result<Vec<u8>>
where
    P: Pixel<Subpixel = u8> + PixelWithColorType,
{
    let mut bytes = Vec::new();
    let encoder =
        PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Adaptive);
    image
        .write_with_encoder(encoder)
        .context("cannot encode the panel image as PNG")?;
    Ok(bytes)
}

/// Which picture `host field export` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    /// The field, as the TV shows it.
    Field,
    /// The field with its target band outlined ([`panel_image_with_band`]).
    Band,
    /// Full white: the calibration's white screen.
    White,
}

/// Writes `picture` of `source` on `arena`, evened out for the panel's
/// measured gain `flat` if given, to `out` (atomically); returns its size
/// in pixels.
pub fn export(
    arena: &ArenaSpec,
    source: &FieldSource,
    picture: Picture,
    flat: Option<&GainGrid>,
    out: &Path,
) -> Result<(u32, u32)> {
    let (png, size) = match picture {
        Picture::Band => {
            let image = panel_image_with_band(arena, source, flat)?;
            (encode_png(&image)?, image.dimensions())
        }
        Picture::Field => {
            let image = panel_image(arena, source, flat)?;
            (encode_png(&image)?, image.dimensions())
        }
        Picture::White => {
            let image = sim::scenario::panel::white_image(arena, flat);
            (encode_png(&image)?, image.dimensions())
        }
    };
    crate::atomic::write(out, &png)?;
    Ok(size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exported_panel_reads_back_as_the_simulators_image() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("panel.png");
        let arena = ArenaSpec {
            screen_px: [96, 54],
            ..ArenaSpec::tv75()
        };
        let source = FieldSource::Letter(sim::fields::letters::Letter::T);
        assert_eq!(
            export(&arena, &source, Picture::Field, None, &out).unwrap(),
            (96, 54)
        );
        let back = image::open(&out).unwrap();
        assert_eq!(back.color(), image::ColorType::L8);
        assert_eq!(
            back.into_luma8(),
            sim::scenario::panel::panel_image(&arena, &arena.load_field(&source).unwrap(), None)
        );
        let missing = FieldSource::Image("/no/such/field.png".into());
        let e = format!(
            "{:#}",
            export(&arena, &missing, Picture::Field, None, &out).unwrap_err()
        );
        assert!(e.contains("/no/such/field.png"), "{e}");
    }

    #[test]
    fn the_band_outline_colours_exactly_the_edge_pixels_of_the_target_band() {
        let arena = ArenaSpec {
            screen_px: [96, 54],
            ..ArenaSpec::tv75()
        };
        let source = FieldSource::Annulus;
        let grey = panel_image(&arena, &source, None).unwrap();
        let outlined = panel_image_with_band(&arena, &source, None).unwrap();
        let field = arena.load_field(&source).unwrap();
        let layout = arena.field_layout(&field);
        let thresholds = sim::scenario::field_thresholds(&source);
        let in_band = |i: u32, j: u32| {
            let v = field.shown(arena.panel_pixel_centre(i, j), &layout);
            sim::episodes::eval::in_band(v, &thresholds)
        };
        let (w, h) = grey.dimensions();
        let mut edges = 0;
        for j in 0..h {
            for i in 0..w {
                let neighbours = [(-1, 0), (1, 0), (0, -1), (0, 1)]
                    .map(|(di, dj)| (i as i64 + di, j as i64 + dj))
                    .into_iter()
                    .filter(|&(x, y)| x >= 0 && y >= 0 && x < i64::from(w) && y < i64::from(h));
                let edge = in_band(i, j)
                    && neighbours
                        .into_iter()
                        .any(|(x, y)| !in_band(x as u32, y as u32));
                let level = grey.get_pixel(i, j)[0];
                let expected = if edge {
                    edges += 1;
                    sim::render::BAND
                } else {
                    image::Rgb([level; 3])
                };
                assert_eq!(*outlined.get_pixel(i, j), expected, "pixel ({i}, {j})");
            }
        }
        // The annulus' band is a ring: an inner and an outer edge.
        assert!(edges > 2 * 40, "{edges} edge pixels");
    }
}
