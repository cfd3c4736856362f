//! PNG charts for experiment reports, drawn with `plotters` into memory and
//! written atomically.

use super::stats::{Line, MeanCi};
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const WIDTH: u32 = 960;
const HEIGHT: u32 = 600;
const FONT: &str = "sans-serif";
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Registers the embedded DejaVu Sans once per process.
fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/DejaVuSans.ttf");
        plotters::style::register_font(FONT, FontStyle::Normal, bytes).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(anyhow!("the embedded chart font does not load"))
    }
}

/// One arm of an experiment over time: `trials[t][i]` is trial t's value at `x[i]`.
#[derive(Clone, Debug)]
pub struct Band {
    /// Legend label.
    pub name: String,
    /// Sample points (steps).
    pub x: Vec<f64>,
    /// One series per trial, each as long as `x`.
    pub trials: Vec<Vec<f64>>,
}

/// Points of one arm, summarised by a least-squares line.
#[derive(Clone, Debug)]
pub struct Scatter {
    /// Legend label.
    pub name: String,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
}

/// Axis labels and title of a chart.
#[derive(Clone, Copy, Debug)]
pub struct Labels<'a> {
    /// Title above the chart.
    pub title: &'a str,
    /// X axis label.
    pub x: &'a str,
    /// Y axis label.
    pub y: &'a str,
}

/// What the band around a mean spans.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spread {
    /// The 95 % confidence interval of the mean.
    Ci95,
    /// The least to the greatest trial.
    MinMax,
}

impl Spread {
    /// The legend's entry for the shaded band.
    pub fn legend(self) -> &'static str {
        match self {
            Spread::Ci95 => "shaded: 95 % interval of the mean",
            Spread::MinMax => "shaded: the least to the greatest trial",
        }
    }
}

/// Mean over trials with a band (95 % confidence or min to max), one line
/// per arm (like the thesis' Figure 15).
pub fn mean_with_band(
    path: &Path,
    labels: Labels<'_>,
    bands: &[Band],
    spread: Spread,
) -> Result<()> {
    // (x, mean, low, high) per sample point
    let summaries: Vec<Vec<(f64, f64, f64, f64)>> = bands
        .iter()
        .map(|b| {
            b.x.iter()
                .enumerate()
                .map(|(i, &x)| {
                    let column: Vec<f64> =
                        b.trials.iter().filter_map(|t| t.get(i).copied()).collect();
                    let ci = MeanCi::of(&column);
                    match spread {
                        Spread::Ci95 => (x, ci.mean, ci.low().max(0.0), ci.high()),
                        Spread::MinMax => {
                            let low = column.iter().copied().fold(f64::INFINITY, f64::min);
                            let high = column.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                            (x, ci.mean, low.min(ci.mean), high.max(ci.mean))
                        }
                    }
                })
                .collect()
        })
        .collect();
    let x_max = bands
        .iter()
        .flat_map(|b| b.x.iter().copied())
        .fold(1.0, f64::max);
    let y_max = summaries.iter().flatten().map(|p| p.3).fold(1.0, f64::max) * 1.05;
    render(path, WIDTH, HEIGHT, |root| {
        let mut chart = frame(root, labels, x_max, y_max)?;
        for (k, (band, summary)) in bands.iter().zip(&summaries).enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let mut outline: Vec<(f64, f64)> = summary.iter().map(|p| (p.0, p.3)).collect();
            outline.extend(summary.iter().rev().map(|p| (p.0, p.2)));
            chart.draw_series(std::iter::once(Polygon::new(
                outline,
                color.mix(0.2).filled(),
            )))?;
            chart
                .draw_series(LineSeries::new(
                    summary.iter().map(|p| (p.0, p.1)),
                    color.stroke_width(2),
                ))?
                .label(band.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        let grey = BLACK.mix(0.2);
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
            .label(spread.legend())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], grey.filled()));
        legend(&mut chart)
    })
}

/// Points per arm with each arm's least-squares line (like the thesis'
/// Figure 24).
pub fn points_with_trend(path: &Path, labels: Labels<'_>, series: &[Scatter]) -> Result<()> {
    let x_max = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold(1.0, f64::max);
    let y_max = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(1.0, f64::max)
        * 1.05;
    render(path, WIDTH, HEIGHT, |root| {
        let mut chart = frame(root, labels, x_max, y_max)?;
        for (k, s) in series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            chart.draw_series(
                s.points
                    .iter()
                    .map(|&p| Circle::new(p, 2, color.mix(0.35).filled())),
            )?;
            let label = match Line::fit(&s.points) {
                Some(line) => {
                    chart.draw_series(LineSeries::new(
                        [(0.0, line.at(0.0)), (x_max, line.at(x_max))],
                        color.stroke_width(3),
                    ))?;
                    format!(
                        "{} (fit {:+.3e} x + {:.1})",
                        s.name, line.slope, line.intercept
                    )
                }
                None => s.name.clone(),
            };
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
                });
        }
        legend(&mut chart)
    })
}

/// Side of each picture of [`tiles`], pixels.
pub const TILE: u32 = 360;
const TILE_GAP: u32 = 12;
const TILE_TITLE: u32 = 44;
const TILE_CAPTION: u32 = 28;

/// Pictures side by side in a row, each with a caption below, under a
/// title (the thesis' Figures 11, 17 and 18). Pictures are scaled to
/// [`TILE`] pixels square.
pub fn tiles(path: &Path, title: &str, pictures: &[(String, image::RgbImage)]) -> Result<()> {
    let n = pictures.len().max(1) as u32;
    let width = n * TILE + (n + 1) * TILE_GAP;
    let height = TILE_TITLE + TILE + TILE_CAPTION + TILE_GAP;
    render(path, width, height, |root| {
        root.draw(&Text::new(
            title.to_string(),
            (TILE_GAP as i32, 10),
            (FONT, 22).into_font(),
        ))?;
        for (k, (caption, picture)) in pictures.iter().enumerate() {
            let x0 = TILE_GAP + k as u32 * (TILE + TILE_GAP);
            let scaled =
                image::imageops::resize(picture, TILE, TILE, image::imageops::FilterType::Triangle);
            for (x, y, p) in scaled.enumerate_pixels() {
                root.draw_pixel(
                    ((x0 + x) as i32, (TILE_TITLE + y) as i32),
                    &RGBColor(p[0], p[1], p[2]),
                )?;
            }
            let at = (x0 as i32, (TILE_TITLE + TILE + 6) as i32);
            root.draw(&Text::new(caption.clone(), at, (FONT, 16).into_font()))?;
        }
        Ok(())
    })
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn frame<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    labels: Labels<'_>,
    x_max: f64,
    y_max: f64,
) -> Result<Chart<'a, 'b>> {
    let (width, _) = root.dim_in_pixel();
    let mut chart = ChartBuilder::on(root)
        .caption(labels.title, (FONT, title_size(labels.title, width)))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..x_max, 0.0..y_max)?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .label_style((FONT, 14))
        .x_label_formatter(&|x| format_count(*x))
        .y_label_formatter(&|y| format_axis(*y))
        .draw()?;
    Ok(chart)
}

fn legend<'a, 'b>(chart: &mut Chart<'a, 'b>) -> Result<()>
where
    'b: 'a,
{
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// The largest font size, up to 24 pixels, at which `title` fits in
/// `width` pixels (DejaVu Sans' glyphs average under 0.6 of the size).
fn title_size(title: &str, width: u32) -> f64 {
    let chars = title.chars().count().max(1) as f64;
    (f64::from(width) * 0.92 / (0.6 * chars)).clamp(10.0, 24.0)
}

/// A y axis number: whole numbers without decimals, others with two.
fn format_axis(y: f64) -> String {
    if (y - y.round()).abs() < 1e-9 {
        format!("{y:.0}")
    } else {
        format!("{y:.2}")
    }
}

fn format_count(x: f64) -> String {
    if x >= 1e6 {
        format!("{:.1}M", x / 1e6)
    } else if x >= 1e3 {
        format!("{:.0}k", x / 1e3)
    } else {
        format!("{x:.0}")
    }
}

/// Draws into an RGB buffer of `width` x `height`, then encodes a PNG and
/// writes it atomically.
fn render(
    path: &Path,
    width: u32,
    height: u32,
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    ensure_font()?;
    let mut buffer = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root).with_context(|| format!("cannot draw chart {}", path.display()))?;
        root.present()?;
    }
    let image = image::RgbImage::from_raw(width, height, buffer)
        .context("chart buffer has the wrong size")?;
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .with_context(|| format!("cannot encode chart {}", path.display()))?;
    crate::atomic::write(path, &png)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_numbers_have_no_spurious_decimals_and_titles_fit_the_width() {
        assert_eq!(format_axis(1000.0), "1000");
        assert_eq!(format_axis(0.25), "0.25");
        let long = "Transfer, the author's settings: formations over time by swarm size (cf. thesis Figure 16)";
        let size = title_size(long, WIDTH);
        assert!(size < 24.0 && long.chars().count() as f64 * 0.6 * size <= f64::from(WIDTH));
        assert_eq!(title_size("Short", WIDTH), 24.0);
    }

    #[test]
    fn charts_render_to_png_files() {
        let dir = tempfile::tempdir().unwrap();
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 1000.0).collect();
        let bands = vec![
            Band {
                name: "OC".into(),
                x: x.clone(),
                trials: vec![x.iter().map(|v| v / 1000.0).collect(); 3],
            },
            Band {
                name: "RL".into(),
                x: x.clone(),
                trials: (0..3)
                    .map(|t| x.iter().map(|v| v / 2000.0 + t as f64).collect())
                    .collect(),
            },
        ];
        let labels = Labels {
            title: "Formations",
            x: "step",
            y: "formations",
        };
        let path = dir.path().join("f.png");
        mean_with_band(&path, labels, &bands, Spread::Ci95).unwrap();
        let png = image::open(&path).unwrap();
        assert_eq!((png.width(), png.height()), (WIDTH, HEIGHT));
        mean_with_band(&path, labels, &bands, Spread::MinMax).unwrap();
        let scatter = vec![Scatter {
            name: "A".into(),
            points: x.iter().map(|&v| (v, 100.0 + v / 100.0)).collect(),
        }];
        let path = dir.path().join("c.png");
        points_with_trend(&path, labels, &scatter).unwrap();
        assert!(image::open(&path).is_ok());
        let red = image::RgbImage::from_pixel(60, 60, image::Rgb([255, 0, 0]));
        let path = dir.path().join("t.png");
        tiles(
            &path,
            "Two",
            &[("a".into(), red.clone()), ("b".into(), red)],
        )
        .unwrap();
        let png = image::open(&path).unwrap().to_rgb8();
        assert_eq!(png.width(), 2 * TILE + 3 * TILE_GAP);
        assert_eq!(
            png.get_pixel(TILE_GAP + TILE / 2, TILE_TITLE + TILE / 2),
            &image::Rgb([255, 0, 0])
        );
    }
}
