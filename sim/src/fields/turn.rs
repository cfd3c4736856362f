//! A letter turned or mirrored on the screen: the eight symmetries of a
//! square grid, named `rot90`, `rot180`, `rot270` (quarter turns clockwise
//! as the screen shows the field, row 0 at the top), `mirror` (left and
//! right swapped) and `mirror-rot90`, `mirror-rot180`, `mirror-rot270`
//! (mirrored, then turned). Training shapes whose geometry the letters as
//! given lack: an L whose foot points left, a T standing on its bar. Exact
//! on the grid: cells move, no value is resampled.

use crate::fields::ScalarField;
use std::fmt;
use std::str::FromStr;

/// One of the square's symmetries other than leaving it be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Turn {
    /// Left and right swapped first.
    mirrored: bool,
    /// Then this many quarter turns clockwise, 0 to 3.
    quarters: u8,
}

/// A turn's name that is not one of [`Turn::NAMES`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownTurn(pub String);

impl fmt::Display for UnknownTurn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown turn {:?}: expected one of {}",
            self.0,
            Turn::NAMES.join(", ")
        )
    }
}

impl std::error::Error for UnknownTurn {}

impl Turn {
    /// Every turn's name, in the order of [`Turn::all`].
    pub const NAMES: [&'static str; 7] = [
        "rot90",
        "rot180",
        "rot270",
        "mirror",
        "mirror-rot90",
        "mirror-rot180",
        "mirror-rot270",
    ];

    /// Every turn, in the order of [`Turn::NAMES`].
    pub fn all() -> impl Iterator<Item = Turn> {
        (1..8u8).map(|i| Turn {
            mirrored: i >= 4,
            quarters: i % 4,
        })
    }

    /// `field` turned: a `w x h` grid becomes `h x w` after an odd number
    /// of quarter turns.
    pub fn apply(self, field: &ScalarField) -> ScalarField {
        let (w, h) = (field.width(), field.height());
        let (mut out_w, mut out_h) = (w, h);
        if self.quarters % 2 == 1 {
            (out_w, out_h) = (h, w);
        }
        let mut values = vec![0.0; w * h];
        for (i, &v) in field.values().iter().enumerate() {
            let (mut x, mut y, mut cols, mut rows) = (i % w, i / w, w, h);
            if self.mirrored {
                x = cols - 1 - x;
            }
            for _ in 0..self.quarters {
                // clockwise with row 0 at the top: the top-left corner goes
                // to the top-right
                (x, y) = (rows - 1 - y, x);
                (cols, rows) = (rows, cols);
            }
            values[y * out_w + x] = v;
        }
        ScalarField::new(out_w, out_h, values).expect("a turned grid has the field's cells")
    }
}

impl FromStr for Turn {
    type Err = UnknownTurn;

    fn from_str(s: &str) -> Result<Turn, UnknownTurn> {
        Turn::NAMES
            .iter()
            .zip(Turn::all())
            .find(|(name, _)| **name == s)
            .map(|(_, turn)| turn)
            .ok_or_else(|| UnknownTurn(s.to_string()))
    }
}

impl fmt::Display for Turn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let index = usize::from(self.quarters) + if self.mirrored { 4 } else { 0 } - 1;
        f.write_str(Turn::NAMES[index])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 x 2 grid with every cell different: 0.1 to 0.6 row by row.
    fn grid() -> ScalarField {
        ScalarField::new(3, 2, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]).unwrap()
    }

    fn turned(name: &str) -> ScalarField {
        name.parse::<Turn>().unwrap().apply(&grid())
    }

    #[test]
    fn each_turn_moves_the_cells_as_drawn_by_hand() {
        // 0.1 0.2 0.3        0.4 0.1
        // 0.4 0.5 0.6  rot90 0.5 0.2
        //                    0.6 0.3
        let rot90 = turned("rot90");
        assert_eq!((rot90.width(), rot90.height()), (2, 3));
        assert_eq!(rot90.values(), [0.4, 0.1, 0.5, 0.2, 0.6, 0.3]);
        assert_eq!(turned("rot180").values(), [0.6, 0.5, 0.4, 0.3, 0.2, 0.1]);
        assert_eq!(turned("rot270").values(), [0.3, 0.6, 0.2, 0.5, 0.1, 0.4]);
        assert_eq!(turned("mirror").values(), [0.3, 0.2, 0.1, 0.6, 0.5, 0.4]);
        // mirrored first: 0.3 0.2 0.1 / 0.6 0.5 0.4, then a quarter turn
        assert_eq!(
            turned("mirror-rot90").values(),
            [0.6, 0.3, 0.5, 0.2, 0.4, 0.1]
        );
        assert_eq!(
            turned("mirror-rot180").values(),
            [0.4, 0.5, 0.6, 0.1, 0.2, 0.3]
        );
    }

    #[test]
    fn the_eight_symmetries_are_distinct_and_four_quarter_turns_are_none() {
        let mut seen = vec![grid().values().to_vec()];
        for turn in Turn::all() {
            let values = turn.apply(&grid()).values().to_vec();
            assert!(!seen.contains(&values), "{turn} repeats a symmetry");
            seen.push(values);
        }
        let quarter: Turn = "rot90".parse().unwrap();
        let mut f = grid();
        for _ in 0..4 {
            f = quarter.apply(&f);
        }
        assert_eq!(f, grid());
        let mirror: Turn = "mirror".parse().unwrap();
        assert_eq!(mirror.apply(&mirror.apply(&grid())), grid());
    }

    #[test]
    fn names_round_trip_and_an_unknown_one_is_named_with_the_choices() {
        for (turn, name) in Turn::all().zip(Turn::NAMES) {
            assert_eq!(turn.to_string(), name);
            assert_eq!(name.parse::<Turn>(), Ok(turn));
        }
        let e = "rot45".parse::<Turn>().unwrap_err().to_string();
        assert!(
            e.contains("\"rot45\"") && e.contains("rot90, rot180"),
            "{e}"
        );
    }
}
