//! Finding pucks by colour in a top-down picture of the screen.
//!
//! A pixel is a puck's when its hue is near the pucks' and it is saturated
//! and bright enough for its hue to mean something: the field under them
//! is grey, so brightness gradients, glare and the field's own levels do
//! not match. Connected puck pixels form blobs; a blob of about `k` pucks'
//! area (pucks that touch) is split into `k` by k-means on its pixels,
//! started from mutually farthest pixels, so the result is deterministic.
//! Each centre is then refined by fitting a circle of the pucks' radius to
//! the blob's edge against the grey field (least squares, Gauss-Newton),
//! leaving out its edge against other colours: a robot hiding part of a
//! puck does not pull its centre away.

use image::RgbImage;

/// Which colours are a puck's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourMatch {
    hue_deg: f64,
    min_saturation: f64,
}

/// Hues this far from the pucks' match, degrees.
const HUE_TOLERANCE_DEG: f64 = 25.0;

/// Pixels darker than this (of 1) have no reliable hue.
const MIN_VALUE: f64 = 0.12;

/// Blobs smaller than this fraction of a puck's area are noise.
const MIN_AREA_FRACTION: f64 = 0.3;

/// Lloyd iterations at most when splitting a blob.
const KMEANS_ITERATIONS: usize = 50;

/// Gauss-Newton iterations of a circle fit.
const FIT_ITERATIONS: usize = 20;

/// What a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    /// A puck.
    Puck,
    /// The grey field (or anything too grey or dark to have a hue).
    Plain,
    /// Another colour: a robot, say.
    Other,
}

/// Hue (degrees), saturation and value of a colour, HSV.
fn hsv([r, g, b]: [u8; 3]) -> (f64, f64, f64) {
    let (r, g, b) = (
        f64::from(r) / 255.0,
        f64::from(g) / 255.0,
        f64::from(b) / 255.0,
    );
    let (max, min) = (r.max(g).max(b), r.min(g).min(b));
    let chroma = max - min;
    let hue = if chroma == 0.0 {
        0.0
    } else if max == r {
        60.0 * ((g - b) / chroma).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / chroma + 2.0)
    } else {
        60.0 * ((r - g) / chroma + 4.0)
    };
    (hue, if max > 0.0 { chroma / max } else { 0.0 }, max)
}

impl ColourMatch {
    /// Matches the pucks' colour `rgb` (as the camera sees it); `None` if
    /// it is too grey to tell from the field (saturation under 0.3).
    pub fn of(rgb: [u8; 3]) -> Option<ColourMatch> {
        let (hue_deg, saturation, value) = hsv(rgb);
        (saturation >= 0.3 && value >= MIN_VALUE).then_some(ColourMatch {
            hue_deg,
            min_saturation: (saturation / 2.0).clamp(0.2, 0.45),
        })
    }

    /// Whether a pixel is a puck's.
    pub fn matches(&self, rgb: [u8; 3]) -> bool {
        self.class(rgb) == Class::Puck
    }

    fn class(&self, rgb: [u8; 3]) -> Class {
        let (hue, saturation, value) = hsv(rgb);
        if saturation < self.min_saturation || value < MIN_VALUE {
            return Class::Plain;
        }
        let distance = (hue - self.hue_deg).rem_euclid(360.0);
        if distance.min(360.0 - distance) <= HUE_TOLERANCE_DEG {
            Class::Puck
        } else {
            Class::Other
        }
    }
}

/// A blob: its pixels' centres, and the midpoints of its edges against
/// plain pixels.
struct Blob {
    pixels: Vec<[f64; 2]>,
    edges: Vec<[f64; 2]>,
}

/// The centres of the pucks in `image`, pixels (from its top-left corner),
/// for pucks `radius_px` pixels in radius; blob by blob in row order.
pub fn find_pucks(image: &RgbImage, colour: &ColourMatch, radius_px: f64) -> Vec<[f64; 2]> {
    let area = std::f64::consts::PI * radius_px * radius_px;
    let mut centres = Vec::new();
    for blob in blobs(image, colour) {
        if (blob.pixels.len() as f64) < MIN_AREA_FRACTION * area {
            continue;
        }
        let k = ((blob.pixels.len() as f64 / area).round() as usize).max(1);
        let rough = split(&blob.pixels, k);
        centres.extend(rough.iter().enumerate().map(|(i, c)| {
            let own: Vec<[f64; 2]> = blob
                .edges
                .iter()
                .copied()
                .filter(|e| nearest(&rough, *e) == i)
                .collect();
            fit_circle(*c, &own, radius_px)
        }));
    }
    centres
}

/// The 4-connected blobs of puck pixels.
fn blobs(image: &RgbImage, colour: &ColourMatch) -> Vec<Blob> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let class: Vec<Class> = image.pixels().map(|p| colour.class(p.0)).collect();
    let mut todo: Vec<bool> = class.iter().map(|c| *c == Class::Puck).collect();
    let mut blobs = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !todo[start] {
            continue;
        }
        todo[start] = false;
        stack.push(start);
        let mut blob = Blob {
            pixels: Vec::new(),
            edges: Vec::new(),
        };
        while let Some(k) = stack.pop() {
            let (x, y) = (k % w, k / w);
            let centre = [x as f64 + 0.5, y as f64 + 0.5];
            blob.pixels.push(centre);
            let neighbours = [
                (x > 0).then(|| (k - 1, [-0.5, 0.0])),
                (x + 1 < w).then(|| (k + 1, [0.5, 0.0])),
                (y > 0).then(|| (k - w, [0.0, -0.5])),
                (y + 1 < h).then(|| (k + w, [0.0, 0.5])),
            ];
            for (n, towards) in neighbours.into_iter().flatten() {
                if todo[n] {
                    todo[n] = false;
                    stack.push(n);
                } else if class[n] == Class::Plain {
                    blob.edges
                        .push([centre[0] + towards[0], centre[1] + towards[1]]);
                }
            }
        }
        blobs.push(blob);
    }
    blobs
}

/// The index of the centre nearest to `p`.
fn nearest(centres: &[[f64; 2]], p: [f64; 2]) -> usize {
    (0..centres.len())
        .min_by(|&a, &b| distance2(p, centres[a]).total_cmp(&distance2(p, centres[b])))
        .unwrap_or(0)
}

/// The centre of the circle of radius `r` through `edges` (least squares,
/// from `start`; edge points more than 1.5 pixels off the first fit are
/// left out of the second), or `start` when the edges cannot place it: too
/// few, too short an arc, or a centre farther than `r` from `start`.
fn fit_circle(start: [f64; 2], edges: &[[f64; 2]], r: f64) -> [f64; 2] {
    let mut kept: Vec<[f64; 2]> = edges.to_vec();
    let mut centre = start;
    for round in 0..2 {
        if kept.len() < 8 {
            return start;
        }
        for _ in 0..FIT_ITERATIONS {
            // Normal equations of the residuals |e - c| - r in the centre.
            let (mut a, mut b, mut d, mut gx, mut gy) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for e in &kept {
                let (dx, dy) = (e[0] - centre[0], e[1] - centre[1]);
                let length = dx.hypot(dy).max(1e-9);
                let (ux, uy) = (dx / length, dy / length);
                let residual = length - r;
                (a, b, d) = (a + ux * ux, b + ux * uy, d + uy * uy);
                (gx, gy) = (gx + ux * residual, gy + uy * residual);
            }
            let det = a * d - b * b;
            // An arc too short to fix both directions.
            if det < 0.05 * ((a + d) / 2.0).powi(2) {
                return start;
            }
            let step = [(d * gx - b * gy) / det, (a * gy - b * gx) / det];
            centre = [centre[0] + step[0], centre[1] + step[1]];
            if step[0].hypot(step[1]) < 1e-4 {
                break;
            }
        }
        if round == 0 {
            kept.retain(|e| (distance2(*e, centre).sqrt() - r).abs() <= 1.5);
        }
    }
    if distance2(centre, start) <= r * r {
        centre
    } else {
        start
    }
}

fn distance2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

fn mean(points: impl Iterator<Item = [f64; 2]>) -> Option<[f64; 2]> {
    let (mut sum, mut n) = ([0.0, 0.0], 0.0);
    for p in points {
        sum = [sum[0] + p[0], sum[1] + p[1]];
        n += 1.0;
    }
    (n > 0.0).then(|| [sum[0] / n, sum[1] / n])
}

/// `k` centres of the blob's pixels: its centroid for one, else k-means.
fn split(blob: &[[f64; 2]], k: usize) -> Vec<[f64; 2]> {
    let Some(centroid) = mean(blob.iter().copied()) else {
        return Vec::new();
    };
    if k == 1 {
        return vec![centroid];
    }
    // Farthest-point start: the pixel farthest from the centroid, then the
    // one farthest from every centre so far.
    let mut centres: Vec<[f64; 2]> = Vec::with_capacity(k);
    let mut nearest: Vec<f64> = blob.iter().map(|p| distance2(*p, centroid)).collect();
    while centres.len() < k {
        let far = (0..blob.len())
            .max_by(|&a, &b| nearest[a].total_cmp(&nearest[b]))
            .unwrap_or(0);
        let c = blob[far];
        centres.push(c);
        for (d, p) in nearest.iter_mut().zip(blob) {
            *d = d.min(distance2(*p, c));
        }
    }
    let mut owner = vec![0usize; blob.len()];
    for _ in 0..KMEANS_ITERATIONS {
        let mut changed = false;
        for (o, p) in owner.iter_mut().zip(blob) {
            let best = (0..k)
                .min_by(|&a, &b| distance2(*p, centres[a]).total_cmp(&distance2(*p, centres[b])))
                .unwrap_or(0);
            changed |= best != *o;
            *o = best;
        }
        for (c, centre) in centres.iter_mut().enumerate() {
            if let Some(m) = mean(
                blob.iter()
                    .zip(&owner)
                    .filter(|(_, o)| **o == c)
                    .map(|(p, _)| *p),
            ) {
                *centre = m;
            }
        }
        if !changed {
            break;
        }
    }
    centres
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn disc(img: &mut RgbImage, c: [f64; 2], r: f64, colour: [u8; 3]) {
        for (x, y, p) in img.enumerate_pixels_mut() {
            if distance2([f64::from(x) + 0.5, f64::from(y) + 0.5], c) <= r * r {
                *p = Rgb(colour);
            }
        }
    }

    #[test]
    fn red_on_any_grey_matches_and_grey_blue_or_dark_red_do_not() {
        let red = ColourMatch::of([200, 44, 44]).unwrap();
        assert!(
            red.matches([200, 44, 44])
                && red.matches([120, 30, 40])
                && red.matches([255, 120, 110])
        );
        for grey in [0u8, 60, 128, 200, 255] {
            assert!(!red.matches([grey, grey, grey]), "{grey}");
        }
        assert!(
            !red.matches([0, 100, 200]) && !red.matches([20, 5, 5]) && !red.matches([200, 160, 40])
        );
        assert_eq!(ColourMatch::of([128, 120, 120]), None);
    }

    #[test]
    fn touching_pucks_are_split_and_specks_ignored() {
        let mut img = RgbImage::from_pixel(200, 100, Rgb([128, 128, 128]));
        disc(&mut img, [30.0, 30.0], 10.0, [200, 44, 44]);
        // Three in a row, touching.
        for x in [100.0, 120.0, 140.0] {
            disc(&mut img, [x, 60.0], 10.0, [200, 44, 44]);
        }
        disc(&mut img, [180.0, 20.0], 2.0, [200, 44, 44]);
        let found = find_pucks(&img, &ColourMatch::of([200, 44, 44]).unwrap(), 10.0);
        assert_eq!(found.len(), 4, "{found:?}");
        assert!(distance2(found[0], [30.0, 30.0]) < 0.01);
        let mut row: Vec<[f64; 2]> = found[1..4].to_vec();
        row.sort_by(|a, b| a[0].total_cmp(&b[0]));
        for (c, x) in row.iter().zip([100.0, 120.0, 140.0]) {
            assert!(distance2(*c, [x, 60.0]) < 1.5 * 1.5, "{c:?} vs {x}");
        }
    }
}
