//! The panel image of a field on a screen arena as a PNG file
//! (`host field export`) or bytes (`host display` serves them): the
//! picture [`sim::scenario::panel::panel_image`] defines, one 8-bit grey pixel per
//! panel pixel, with no colour profile or gamma chunk (a browser shows the
//! levels as they are).

use anyhow::{Context, Result};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::GrayImage;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use std::path::Path;

/// The panel image of `source` on `arena`, the field loaded as the
/// arena shows it ([`ArenaSpec::load_field`]).
pub fn panel_image(arena: &ArenaSpec, source: &FieldSource) -> Result<GrayImage> {
    let field = arena.load_field(source)?;
    Ok(sim::scenario::panel::panel_image(arena, &field))
}

/// `image` encoded as a PNG.
pub fn encode_png(image: &GrayImage) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    let encoder =
        PngEncoder::new_with_quality(&mut bytes, CompressionType::Fast, FilterType::Adaptive);
    image
        .write_with_encoder(encoder)
        .context("cannot encode the panel image as PNG")?;
    Ok(bytes)
}

/// Writes the panel image of `source` on `arena` to `out` (atomically);
/// returns its size in pixels.
pub fn export(arena: &ArenaSpec, source: &FieldSource, out: &Path) -> Result<(u32, u32)> {
    let image = panel_image(arena, source)?;
    crate::atomic::write(out, &encode_png(&image)?)?;
    Ok(image.dimensions())
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
        assert_eq!(export(&arena, &source, &out).unwrap(), (96, 54));
        let back = image::open(&out).unwrap();
        assert_eq!(back.color(), image::ColorType::L8);
        assert_eq!(
            back.into_luma8(),
            sim::scenario::panel::panel_image(&arena, &arena.load_field(&source).unwrap())
        );
        let missing = FieldSource::Image("/no/such/field.png".into());
        let e = format!("{:#}", export(&arena, &missing, &out).unwrap_err());
        assert!(e.contains("/no/such/field.png"), "{e}");
    }
}
