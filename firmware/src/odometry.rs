//! Wheel encoder counting: the quadrature decoding of one Zumo 32U4
//! encoder, as Pololu's `Zumo32U4Encoders` decodes it.
//!
//! Each encoder has two channels, A and B; the board routes A XOR B to an
//! interrupt pin (left: PB4 / PCINT4, right: PE6 / INT6) and B to a plain
//! input (left PE2, right PF0), so every edge of either channel is an edge
//! of the XOR pin. On each such edge the board calls [`Quadrature::edge`]
//! with both pins' levels; A is XOR ^ B. A step forward counts +1 (both
//! wheels count up when their track drives the robot forward), a step back
//! -1, 12 counts per motor revolution (`../shared/docs/hardware.md`
//! section 9). The control loop takes the counts once per period
//! ([`Quadrature::take`]) for the log.

/// One encoder's last channel levels and the counts since the last take.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Quadrature {
    /// Channel A in bit 0, B in bit 1 (one byte: the interrupt handler
    /// stays short).
    levels: u8,
    count: i16,
}

const A: u8 = 1;
const B: u8 = 2;

impl Quadrature {
    /// An encoder whose pins read `xor` and `b`, no counts yet.
    pub const fn new(xor: bool, b: bool) -> Quadrature {
        Quadrature {
            levels: Self::levels(xor, b),
            count: 0,
        }
    }

    const fn levels(xor: bool, b: bool) -> u8 {
        (xor != b) as u8 | (b as u8) << 1
    }

    /// An edge of the XOR pin: the pins now read `xor` and `b`. Counts
    /// +1 when A now differs from the old B, -1 when the old A differs
    /// from B now (Pololu's rule; both or neither: no step).
    #[inline(always)]
    pub fn edge(&mut self, xor: bool, b: bool) {
        let new = Self::levels(xor, b);
        let old = self.levels;
        let up = (new & A) ^ ((old & B) >> 1);
        let down = (old & A) ^ ((new & B) >> 1);
        self.count = self
            .count
            .wrapping_add(i16::from(up))
            .wrapping_sub(i16::from(down));
        self.levels = new;
    }

    /// The counts since the last take; counting restarts from zero.
    pub fn take(&mut self) -> i16 {
        core::mem::take(&mut self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pins' levels at quadrature phase `p` (0..4), forward order
    /// A B = 00, 10, 11, 01: XOR is the phase's low bit, B its high bit.
    fn pins(p: u8) -> (bool, bool) {
        (p & 1 != 0, p & 2 != 0)
    }

    #[test]
    fn forward_steps_count_up_and_backward_steps_down() {
        let mut q = Quadrature::new(false, false);
        for p in 1..=40u8 {
            let (x, b) = pins(p % 4);
            q.edge(x, b);
        }
        assert_eq!(q.take(), 40);
        assert_eq!(q.take(), 0);
        for p in (0..40u8).rev() {
            let (x, b) = pins(p % 4);
            q.edge(x, b);
        }
        assert_eq!(q.take(), -40);
    }

    #[test]
    fn a_spurious_interrupt_without_a_change_counts_nothing() {
        let mut q = Quadrature::new(true, false);
        q.edge(true, false);
        assert_eq!(q.take(), 0);
        // The counter wraps instead of overflowing.
        let mut q = Quadrature {
            count: i16::MAX,
            ..Quadrature::new(false, false)
        };
        q.edge(true, false);
        assert_eq!(q.take(), i16::MIN);
    }
}
