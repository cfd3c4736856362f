//! Where a field comes from: the annulus, a generated letter, one of the
//! thesis' own letter images (built in from `experiments/fields/`), either
//! letter turned or mirrored (`letter:L@mirror`, [`Turn`]), a generated
//! shape (`gen:ring:3`, [`GeneratedShape`]), or an image file (one cell per
//! pixel, the mean of R, G and B over 255).

use crate::base::ranges::{self, Range, RangeError};
use crate::fields::generated::{GeneratedShape, UnknownShape};
use crate::fields::letters::Letter;
use crate::fields::turn::{Turn, UnknownTurn};
use crate::fields::ScalarField;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Where a field comes from, by name: `annulus`, `letter:T`, `thesis:T`,
/// `letter:L@mirror`, `gen:ring:3`, or an image file's path.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum FieldSource {
    /// The 64 x 64 annulus (`annulus`).
    Annulus,
    /// A generated letter (`letter:T`).
    Letter(Letter),
    /// The thesis' own image of a letter (`thesis:T`; T, L, V, X and Z, no
    /// I), built into the binary (`experiments/fields/README.md`: source and
    /// licence).
    Thesis(Letter),
    /// A built-in letter, [`FieldSource::Letter`] or [`FieldSource::Thesis`]
    /// (parsing builds no other), turned or mirrored: `letter:L@mirror`,
    /// `thesis:T@rot180`.
    Turned(Box<FieldSource>, Turn),
    /// A generated shape (`gen:ring:3`).
    Generated(GeneratedShape),
    /// A PNG or JPEG image (any other argument: its path).
    Image(PathBuf),
}

/// A field that cannot be loaded, naming the input and the reason.
#[derive(Debug)]
pub enum FieldError {
    /// `letter:` followed by something other than T, I, L, V, X or Z.
    UnknownLetter(String),
    /// The image file cannot be read or decoded.
    Image {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: image::ImageError,
    },
    /// The image decodes to no pixels.
    EmptyImage(PathBuf),
    /// The image file cannot be read, or is too large.
    ImageFile(ImageFileError),
    /// `thesis:` followed by a letter the thesis has no image of.
    NoThesisImage(String),
    /// A built-in letter followed by `@` and no turn's name.
    UnknownTurn(UnknownTurn),
    /// `gen:` followed by no generated shape's name.
    UnknownShape(UnknownShape),
    /// Neither a field's name nor an existing file.
    Unknown(PathBuf),
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FieldError::UnknownLetter(l) => {
                write!(
                    f,
                    "unknown letter {l:?} in the field name: expected one of {}",
                    Letter::NAMES
                )
            }
            FieldError::Image { path, reason } => {
                write!(f, "cannot load field image {}: {reason}", path.display())
            }
            FieldError::EmptyImage(path) => {
                write!(f, "field image {} has no pixels", path.display())
            }
            FieldError::ImageFile(e) => e.fmt(f),
            FieldError::NoThesisImage(l) => {
                write!(
                    f,
                    "the thesis has no letter image {l:?}: expected one of {}",
                    THESIS_LETTERS.join(", ")
                )
            }
            FieldError::UnknownTurn(e) => write!(f, "in the field name: {e}"),
            FieldError::UnknownShape(e) => write!(f, "in the field name: {e}"),
            FieldError::Unknown(path) => write!(
                f,
                "no field is named {:?} and there is no image file of that name: a field is \
                 annulus, letter:X (X one of {}), thesis:X (X one of {}), either letter \
                 turned (letter:L@mirror), a generated shape (gen:ring:3) or the path of a PNG \
                 or JPEG image",
                path.display().to_string(),
                Letter::NAMES,
                THESIS_LETTERS.join(", ")
            ),
        }
    }
}

impl std::error::Error for FieldError {}

impl FromStr for FieldSource {
    type Err = FieldError;

    /// `annulus`, `letter:X`, `thesis:X`, either with `@` and a turn, or a
    /// path.
    fn from_str(s: &str) -> Result<FieldSource, FieldError> {
        let built_in = s.starts_with("letter:") || s.starts_with("thesis:");
        if let Some((letter, turn)) = s.split_once('@').filter(|_| built_in) {
            let turn = turn.parse().map_err(FieldError::UnknownTurn)?;
            Ok(FieldSource::Turned(Box::new(letter.parse()?), turn))
        } else if let Some(shape) = s.strip_prefix("gen:") {
            shape
                .parse()
                .map(FieldSource::Generated)
                .map_err(FieldError::UnknownShape)
        } else if s == "annulus" {
            Ok(FieldSource::Annulus)
        } else if let Some(letter) = s.strip_prefix("letter:") {
            letter
                .parse()
                .map(FieldSource::Letter)
                .map_err(|_| FieldError::UnknownLetter(letter.to_string()))
        } else if let Some(letter) = s.strip_prefix("thesis:") {
            match letter.parse::<Letter>() {
                Ok(l) if thesis_image(l).is_some() => Ok(FieldSource::Thesis(l)),
                _ => Err(FieldError::NoThesisImage(letter.to_string())),
            }
        } else {
            Ok(FieldSource::Image(PathBuf::from(s)))
        }
    }
}

crate::text_form!(FieldSource);

impl fmt::Display for FieldSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FieldSource::Annulus => f.write_str("annulus"),
            FieldSource::Letter(l) => write!(f, "letter:{l}"),
            FieldSource::Thesis(l) => write!(f, "thesis:{l}"),
            FieldSource::Turned(letter, turn) => write!(f, "{letter}@{turn}"),
            FieldSource::Generated(shape) => write!(f, "gen:{shape}"),
            FieldSource::Image(p) => write!(f, "{}", p.display()),
        }
    }
}

impl FieldSource {
    /// Builds or loads the field.
    pub fn load(&self) -> Result<ScalarField, FieldError> {
        match self {
            FieldSource::Annulus => Ok(ScalarField::annulus()),
            FieldSource::Letter(l) => Ok(l.field()),
            FieldSource::Thesis(l) => {
                let bytes =
                    thesis_image(*l).ok_or_else(|| FieldError::NoThesisImage(l.to_string()))?;
                let name = PathBuf::from(self.to_string());
                let err = |reason| FieldError::Image {
                    path: name.clone(),
                    reason,
                };
                field_of(image::load_from_memory(bytes).map_err(err)?, &name)
            }
            FieldSource::Turned(letter, turn) => Ok(turn.apply(&letter.load()?)),
            FieldSource::Generated(shape) => Ok(shape.field()),
            FieldSource::Image(path) => load_image(path),
        }
    }

    /// Whether the target shape has a hole in the middle that innies keep
    /// free (only the annulus: the thesis removes innies for letters).
    pub(crate) fn has_cavity(&self) -> bool {
        matches!(self, FieldSource::Annulus)
    }
}

/// The letters the thesis has images of.
const THESIS_LETTERS: [&str; 5] = ["T", "L", "V", "X", "Z"];

/// The PNG of the thesis' image of `letter`, if it has one.
fn thesis_image(letter: Letter) -> Option<&'static [u8]> {
    Some(match letter {
        Letter::T => include_bytes!("../../../experiments/fields/T.png"),
        Letter::L => include_bytes!("../../../experiments/fields/L.png"),
        Letter::V => include_bytes!("../../../experiments/fields/V.png"),
        Letter::X => include_bytes!("../../../experiments/fields/X.png"),
        Letter::Z => include_bytes!("../../../experiments/fields/Z.png"),
        Letter::I => return None,
    })
}

/// An image file that cannot be used, naming what it is for, the file and
/// the problem.
#[derive(Debug)]
pub struct ImageFileError {
    /// What the image is (`field image`, `photo`).
    pub what: &'static str,
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub problem: ImageProblem,
}

/// Why an image file cannot be used.
#[derive(Debug)]
pub enum ImageProblem {
    /// It cannot be read or decoded (or is larger than
    /// [`ranges::IMAGE_FILE`]).
    Read(image::ImageError),
    /// Its width or height is outside its range.
    Size(RangeError),
}

impl fmt::Display for ImageFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (what, path) = (self.what, self.path.display());
        match &self.problem {
            ImageProblem::Read(reason) => write!(f, "cannot load {what} {path}: {reason}"),
            ImageProblem::Size(error) => write!(f, "{what} {path}: {error}"),
        }
    }
}

impl std::error::Error for ImageFileError {}

/// Reads and decodes the image file at `path`: no further than
/// [`ranges::IMAGE_FILE`]'s size, its width and height checked against
/// `sides` (keys `<what> width`, `<what> height`) before its pixels are
/// decoded, so that a small file of huge dimensions costs nothing.
pub fn read_image(
    path: &Path,
    what: &'static str,
    sides: &'static Range,
) -> Result<image::DynamicImage, ImageFileError> {
    let fail = |problem| ImageFileError {
        what,
        path: path.to_path_buf(),
        problem,
    };
    let unreadable = |e| fail(ImageProblem::Read(image::ImageError::IoError(e)));
    let bytes = ranges::read_file(path, &ranges::IMAGE_FILE).map_err(unreadable)?;
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(&bytes))
            .with_guessed_format()
            .map_err(unreadable)
    };
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| fail(ImageProblem::Read(e)))?;
    for (side, value) in [("width", width), ("height", height)] {
        sides
            .check_count(&format!("{what} {side}"), u64::from(value))
            .map_err(|e| fail(ImageProblem::Size(e)))?;
    }
    reader()?.decode().map_err(|e| fail(ImageProblem::Read(e)))
}

/// An image file's field ([`read_image`] with
/// [`ranges::FIELD_IMAGE_SIDE`]).
fn load_image(path: &Path) -> Result<ScalarField, FieldError> {
    if !path.exists() {
        return Err(FieldError::Unknown(path.to_path_buf()));
    }
    let img = read_image(path, "field image", &ranges::FIELD_IMAGE_SIDE)
        .map_err(FieldError::ImageFile)?;
    field_of(img, path)
}

/// An image's field: mean of R, G, B over 255, one cell per pixel.
fn field_of(img: image::DynamicImage, path: &Path) -> Result<ScalarField, FieldError> {
    let img = img.to_rgb8();
    let values = img
        .pixels()
        .map(|p| (f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2])) / (3.0 * 255.0))
        .collect();
    ScalarField::new(img.width() as usize, img.height() as usize, values)
        .ok_or_else(|| FieldError::EmptyImage(path.to_path_buf()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sources_parse_and_errors_name_the_input() {
        assert_eq!(
            "annulus".parse::<FieldSource>().unwrap(),
            FieldSource::Annulus
        );
        assert_eq!(
            "letter:T".parse::<FieldSource>().unwrap(),
            FieldSource::Letter(Letter::T)
        );
        let e = "letter:Q".parse::<FieldSource>().unwrap_err().to_string();
        assert!(e.contains("\"Q\""), "{e}");
        assert_eq!(
            "thesis:X".parse::<FieldSource>().unwrap(),
            FieldSource::Thesis(Letter::X)
        );
        let e = "thesis:I".parse::<FieldSource>().unwrap_err().to_string();
        assert!(e.contains("\"I\"") && e.contains("T, L, V, X, Z"), "{e}");
        let missing = FieldSource::Image(PathBuf::from("/no/such/field.png"));
        let e = missing.load().unwrap_err().to_string();
        assert!(e.contains("/no/such/field.png"), "{e}");
        // a misspelt name lists the names there are
        let e = "square"
            .parse::<FieldSource>()
            .unwrap()
            .load()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("\"square\"") && e.contains("annulus, letter:X"),
            "{e}"
        );
    }

    #[test]
    fn a_turned_letter_parses_prints_and_loads_as_its_letter_turned() {
        for name in [
            "letter:L@mirror",
            "thesis:T@rot180",
            "letter:T@mirror-rot90",
        ] {
            let source: FieldSource = name.parse().unwrap();
            assert_eq!(source.to_string(), name);
            let FieldSource::Turned(letter, turn) = &source else {
                panic!("{name} parsed as {source:?}");
            };
            assert_eq!(source.load().unwrap(), turn.apply(&letter.load().unwrap()));
        }
        // our L's stem is on the left, so its bottom-left quarter is the
        // brighter; mirrored, the bottom-right
        let bottom_left_minus_right = |name: &str| -> f32 {
            let f = name.parse::<FieldSource>().unwrap().load().unwrap();
            let (w, h) = (f.width(), f.height());
            let sign = |x: usize| if x < w / 2 { 1.0 } else { -1.0 };
            (h / 2..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| sign(x) * f.values()[y * w + x])
                .sum()
        };
        assert!(bottom_left_minus_right("letter:L") > 0.0);
        assert!(bottom_left_minus_right("letter:L@mirror") < 0.0);
        let e = "letter:L@rot45"
            .parse::<FieldSource>()
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"rot45\"") && e.contains("mirror"), "{e}");
        let e = "thesis:I@mirror"
            .parse::<FieldSource>()
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"I\""), "{e}");
        // only built-in letters turn: anything else is a path
        assert_eq!(
            "annulus@mirror".parse::<FieldSource>().unwrap(),
            FieldSource::Image(PathBuf::from("annulus@mirror"))
        );
    }

    #[test]
    fn the_thesis_images_are_built_in_and_read_like_their_files() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments/fields");
        for l in THESIS_LETTERS {
            let built_in = format!("thesis:{l}")
                .parse::<FieldSource>()
                .unwrap()
                .load()
                .unwrap();
            let file = FieldSource::Image(dir.join(format!("{l}.png")))
                .load()
                .unwrap();
            assert_eq!((built_in.width(), built_in.height()), (600, 600));
            assert!(built_in == file, "{l}");
        }
    }

    #[test]
    fn images_read_as_mean_rgb() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.png");
        let mut img = image::RgbImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgb([255, 255, 255]));
        img.put_pixel(1, 0, image::Rgb([255, 0, 0]));
        img.save(&path).unwrap();
        let f = FieldSource::Image(path).load().unwrap();
        assert_eq!((f.width(), f.height()), (2, 1));
        assert_eq!(f.cell(0, 0), 1.0);
        assert!((f.cell(1, 0) - 1.0 / 3.0).abs() < 1e-6);
    }

    /// CRC-32 of a PNG chunk (type and data).
    fn png_crc(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for b in bytes {
            crc ^= u32::from(*b);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    #[test]
    fn a_field_image_of_huge_dimensions_is_refused_before_its_pixels_are_decoded() {
        // A 1 x 1 PNG whose header says 20,000 x 20,000: decoding it would
        // take 1.2 GB before finding its data short.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        image::GrayImage::new(1, 1).save(&path).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        // signature (8), IHDR length (4), "IHDR" (4), width, height, ...
        bytes[16..20].copy_from_slice(&20_000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&20_000u32.to_be_bytes());
        let crc = png_crc(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let e = FieldSource::Image(path).load().unwrap_err();
        assert!(
            matches!(
                e,
                FieldError::ImageFile(ImageFileError {
                    problem: ImageProblem::Size(_),
                    ..
                })
            ),
            "{e}"
        );
        let e = e.to_string();
        assert!(
            e.contains("huge.png")
                && e.contains("field image width = 20000")
                && e.contains("[1, 4096]"),
            "{e}"
        );
    }
}
