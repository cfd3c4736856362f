//! Random draws for the noise models, as pure functions of where they are
//! used: a draw is a function of the world's seed, what it is for, and the
//! episode, step and robot it belongs to. No generator state is carried,
//! so a resumed run draws exactly what an uninterrupted one would, and
//! turning one model's noise on does not change another's draws.
//!
//! Normal draws are the sum of 12 uniforms less 6 (mean 0, variance 1,
//! bounded by +-6), plain arithmetic that rounds the same on every machine.

/// What a draw is for: each use has its own stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u64)]
pub enum Purpose {
    /// A robot's wheel speed factor and turning bias, per episode.
    RobotMotion = 1,
    /// A period's length and whether it is dropped, per step and robot.
    Period = 2,
    /// The screen's brightness over its regions, per episode.
    Brightness = 3,
    /// The discharge times' jitter, per step and robot.
    Discharge = 4,
    /// The camera's frame: drops, missed and spurious blocks, jitter.
    Camera = 5,
}

/// SplitMix64's finaliser: a well-mixed 64-bit function of its input.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A generator for one use at one place: `seed` (the world's), `purpose`,
/// and the two coordinates of the place (episode or step, robot).
pub fn stream(seed: u64, purpose: Purpose, a: u64, b: u64) -> Stream {
    place(seed, purpose, a).stream(b)
}

/// The streams of one use at one first coordinate (a step), for any
/// second (each robot): their hash so far, computed once for all of them.
#[derive(Clone, Copy, Debug)]
pub struct Place(u64);

/// The streams of `purpose` at first coordinate `a` ([`stream`]'s).
pub fn place(seed: u64, purpose: Purpose, a: u64) -> Place {
    Place(mix(mix(seed ^ purpose as u64) ^ a))
}

impl Place {
    /// The generator at second coordinate `b`: `stream(seed, purpose, a, b)`.
    /// Inlined: a noisy robot step seeds three a robot.
    #[inline(always)]
    pub fn stream(self, b: u64) -> Stream {
        Stream::seeded(mix(self.0 ^ b))
    }
}

/// PCG 128/64 (XSL RR): the draws of [`crate::base::rng::SimRng`]
/// (`rand_pcg::Pcg64`) from
/// the same state, with the uniforms' arithmetic in the open so that a
/// normal draw scales its sum once.
#[derive(Clone, Debug)]
pub struct Stream {
    state: u128,
    increment: u128,
}

/// PCG's 128-bit multiplier (`rand_pcg`'s).
const PCG_MULTIPLIER: u128 = 0x2360_ED05_1FC6_5DA4_4385_DF64_9FCC_F645;

/// A uniform draw's 53 random bits are this much of 1.
const UNIT: f64 = 1.0 / (1u64 << 53) as f64;

impl Stream {
    /// `SimRng::seed_from_u64(state)`, in words rather than bytes (the
    /// sensors seed a few generators per robot and step): `rand_core`'s
    /// PCG32 fills the 32-byte seed four bytes at a time, little-endian,
    /// whose first 16 bytes are the state and the last 16 the increment,
    /// made odd; the generator then adds the increment to the state and
    /// steps once.
    fn seeded(mut state: u64) -> Stream {
        const MUL: u64 = 0x5851_F42D_4C95_7F2D;
        const INC: u64 = 0xA176_54E4_6FBE_17F3;
        let mut word = || {
            state = state.wrapping_mul(MUL).wrapping_add(INC);
            let xorshifted = (((state >> 18) ^ state) >> 27) as u32;
            u64::from(xorshifted.rotate_right((state >> 59) as u32))
        };
        let mut half = || {
            let (a, b, c, d) = (word(), word(), word(), word());
            u128::from(a | (b << 32)) | (u128::from(c | (d << 32)) << 64)
        };
        let (start, increment) = (half(), half() | 1);
        let mut stream = Stream {
            state: start.wrapping_add(increment),
            increment,
        };
        stream.step();
        stream
    }

    #[inline(always)]
    fn step(&mut self) {
        self.state = self
            .state
            .wrapping_mul(PCG_MULTIPLIER)
            .wrapping_add(self.increment);
    }

    /// The next 64 random bits (`SimRng::next_u64`).
    #[inline(always)]
    pub fn next_u64(&mut self) -> u64 {
        self.step();
        let (high, low) = ((self.state >> 64) as u64, self.state as u64);
        (high ^ low).rotate_right((high >> 58) as u32)
    }

    /// The next uniform draw's 53 bits as a whole number: the draw is this
    /// times [`UNIT`] (`rng.random::<f64>()`).
    #[inline(always)]
    fn next_whole(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64
    }

    /// A uniform draw in `[0, 1)`, as `rng.random::<f64>()` draws it.
    #[inline(always)]
    pub fn uniform(&mut self) -> f64 {
        self.next_whole() * UNIT
    }
}

/// A standard normal draw (Irwin-Hall: 12 uniforms less 6). The uniforms
/// are whole multiples of [`UNIT`], a power of two, so their sum rounds
/// at the same places as the sum of the whole numbers scaled once: the
/// same value as summing the uniforms themselves. Inlined into its few
/// callers: most of a noisy step's draws were calls.
#[inline(always)]
pub fn normal(rng: &mut Stream) -> f64 {
    let mut sum = rng.next_whole();
    for _ in 1..12 {
        sum += rng.next_whole();
    }
    sum * UNIT - 6.0
}

/// A uniform draw in `[-half, half]`.
pub(crate) fn symmetric(rng: &mut Stream, half: f64) -> f64 {
    (rng.uniform() * 2.0 - 1.0) * half
}

/// Whether an event of probability `p` happens.
pub(crate) fn chance(rng: &mut Stream, p: f64) -> bool {
    p > 0.0 && rng.uniform() < p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::SimRng;
    use rand::{Rng, RngExt, SeedableRng};

    #[test]
    fn a_stream_is_the_generator_seeded_from_its_place_s_hash() {
        for (seed, a, b) in [(0, 0, 0), (1, 5, 2), (u64::MAX, 1 << 40, 7), (3, 22_000, 4)] {
            let hash = mix(mix(mix(seed ^ Purpose::Camera as u64) ^ a) ^ b);
            let mut ours = stream(seed, Purpose::Camera, a, b);
            let mut theirs = SimRng::seed_from_u64(hash);
            for _ in 0..4 {
                assert_eq!(ours.next_u64(), theirs.next_u64());
            }
        }
    }

    #[test]
    fn draws_are_bit_for_bit_those_of_the_uniforms_rand_draws() {
        for k in 0..2_000u64 {
            let hash = mix(k);
            let mut ours = Stream::seeded(hash);
            let mut theirs = SimRng::seed_from_u64(hash);
            let plain = (0..12).map(|_| theirs.random::<f64>()).sum::<f64>() - 6.0;
            assert_eq!(normal(&mut ours).to_bits(), plain.to_bits(), "stream {k}");
            assert_eq!(
                symmetric(&mut ours, 0.3).to_bits(),
                ((theirs.random::<f64>() * 2.0 - 1.0) * 0.3).to_bits()
            );
            let u = theirs.random::<f64>();
            assert_eq!(chance(&mut ours, 0.5), u < 0.5);
            assert_eq!(ours.uniform().to_bits(), theirs.random::<f64>().to_bits());
        }
    }

    #[test]
    fn the_same_place_draws_the_same_and_other_places_draw_otherwise() {
        let draw = |seed, purpose, a, b| normal(&mut stream(seed, purpose, a, b));
        assert_eq!(
            draw(1, Purpose::Period, 5, 2),
            draw(1, Purpose::Period, 5, 2)
        );
        let here = draw(1, Purpose::Period, 5, 2);
        for other in [
            draw(2, Purpose::Period, 5, 2),
            draw(1, Purpose::Camera, 5, 2),
            draw(1, Purpose::Period, 6, 2),
            draw(1, Purpose::Period, 5, 3),
        ] {
            assert_ne!(here, other);
        }
    }

    #[test]
    fn normal_draws_have_mean_0_and_variance_1_and_chances_their_rate() {
        let mut rng = stream(7, Purpose::Discharge, 0, 0);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
        assert!(
            mean.abs() < 0.01 && (var - 1.0).abs() < 0.02,
            "mean {mean}, variance {var}"
        );
        assert!(xs.iter().all(|x| x.abs() <= 6.0));
        let hits = (0..n).filter(|_| chance(&mut rng, 0.1)).count() as f64 / n as f64;
        assert!((hits - 0.1).abs() < 0.005, "{hits}");
        assert!(!chance(&mut rng, 0.0));
        let u: Vec<f64> = (0..1000).map(|_| symmetric(&mut rng, 0.5)).collect();
        assert!(
            u.iter().all(|x| x.abs() <= 0.5)
                && u.iter().any(|x| *x < -0.4)
                && u.iter().any(|x| *x > 0.4)
        );
    }
}
