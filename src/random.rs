//! The random numbers of the crate: one xoshiro256++ generator per realization (or per sampled
//! ensemble), seeded by a SplitMix64 mix of (seed, stream key, index), and standard normal
//! numbers from a 1024-layer ziggurat. [`Stream`] is also a [`rand::Rng`], so the distributions
//! of `rand_distr` draw from the same generators.
//!
//! [`LaneStreams`] runs [`LANES`] such generators side by side in structure-of-arrays form, so that
//! the compiler advances them with vector instructions; lane k draws exactly the numbers the
//! scalar [`Stream`] of its realization draws, in the same order (the rare draws outside the
//! ziggurat's fast path are finished lane by lane with the scalar code).
// Lane loops index several arrays by the lane k; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use std::convert::Infallible;

use crate::lanes::{LANES, Lanes};
use ziggurat::ziggurat;

mod ziggurat;

/// SplitMix64's increment: 2⁶⁴ divided by the golden ratio, rounded to odd (Steele, Lea and
/// Flood, 2014).
const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64: one step of the generator from state `z` (the golden-ratio increment, then the
/// finalizer), a bijective 64-bit mixer. The crate's one seed mixer: every seed, stream key and
/// generator state is derived through it.
#[inline]
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(GOLDEN_GAMMA);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Normal numbers drawn per refill: the fast path of the ziggurat for [`BLOCK`] consecutive
/// outputs of the generator, then, in order, the rest of each draw that fell outside it (with
/// the generator's next numbers). The lanes draw the same way, so the fast path runs as one
/// branch-free loop.
pub const BLOCK: usize = 32;

/// The xoshiro256++ generator of one realization (Blackman and Vigna), period 2²⁵⁶ − 1, with
/// its standard normal numbers drawn [`BLOCK`] at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct Stream {
    core: Core,
    buf: [f64; BLOCK],
    pos: usize,
}

/// The xoshiro256++ state and its uniform numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Core([u64; 4]);

impl Core {
    /// The next 64 random bits.
    #[inline]
    fn next_u64(&mut self) -> u64 {
        let [s0, s1, s2, s3] = self.0;
        let out = s0.wrapping_add(s3).rotate_left(23).wrapping_add(s0);
        let t = s1 << 17;
        let s2 = s2 ^ s0;
        let s3 = s3 ^ s1;
        let s1 = s1 ^ s2;
        let s0 = s0 ^ s3;
        let s2 = s2 ^ t;
        let s3 = s3.rotate_left(45);
        self.0 = [s0, s1, s2, s3];
        out
    }

    /// A uniform number in (0, 1], from the top 53 bits.
    #[inline]
    fn open_closed01(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform number in [0, 1), from the top 53 bits.
    #[inline]
    fn closed_open01(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

impl Stream {
    /// The generator of realization `index` of the streams named by `key` (a mix of the seed and
    /// what is simulated): its four words are SplitMix64 outputs, never all zero in practice.
    pub fn new(key: u64, index: u64) -> Self {
        let base = splitmix64(key) ^ index;
        let mut s = [0; 4];
        let mut z = base;
        for w in &mut s {
            *w = splitmix64(z);
            z = z.wrapping_add(GOLDEN_GAMMA);
        }
        if s == [0; 4] {
            s[0] = 1;
        }
        Self {
            core: Core(s),
            buf: [0.0; BLOCK],
            pos: BLOCK,
        }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.core.next_u64()
    }

    /// The next standard normal number (ziggurat).
    #[inline]
    pub fn normal(&mut self) -> f64 {
        if self.pos == BLOCK {
            self.refill();
        }
        let x = self.buf[self.pos];
        self.pos += 1;
        x
    }

    #[inline(never)]
    fn refill(&mut self) {
        let z = ziggurat();
        let mut bits = [0; BLOCK];
        let mut ok = [true; BLOCK];
        for t in 0..BLOCK {
            bits[t] = self.core.next_u64();
            (self.buf[t], ok[t]) = z.fast(bits[t]);
        }
        for t in 0..BLOCK {
            if !ok[t] {
                self.buf[t] = z.slow(bits[t], self.buf[t], &mut self.core);
            }
        }
        self.pos = 0;
    }
}

/// The generator as a source of `rand`'s distributions: 64 bits per [`Stream::next_u64`], the
/// high half of one for a 32-bit word. The normal numbers buffered for [`Stream::normal`] are
/// not touched: both draw from the one xoshiro256++ sequence, each number of it used once.
impl rand::TryRng for Stream {
    type Error = Infallible;

    #[inline]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.core.next_u64() >> 32) as u32)
    }

    #[inline]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(self.core.next_u64())
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        rand::rand_core::utils::fill_bytes_via_next_word(dst, || self.try_next_u64())
    }
}

/// [`LANES`] generators advanced together, the state of lane k in column k, each drawing its
/// normal numbers exactly as its scalar [`Stream`] does.
#[derive(Clone, Debug)]
pub struct LaneStreams {
    s: [[u64; LANES]; 4],
    buf: [Lanes; BLOCK],
    /// The generators' outputs of the last refill, kept for the draws outside the fast path.
    bits: [[u64; LANES]; BLOCK],
    pos: usize,
}

impl LaneStreams {
    /// The generators of realizations `first`, `first + 1`, … of the streams named by `key`.
    pub fn new(key: u64, first: u64) -> Self {
        let mut s = [[0; LANES]; 4];
        for k in 0..LANES {
            let one = Stream::new(key, first + k as u64);
            for (w, row) in s.iter_mut().enumerate() {
                row[k] = one.core.0[w];
            }
        }
        Self {
            s,
            buf: [Lanes::default(); BLOCK],
            bits: [[0; LANES]; BLOCK],
            pos: BLOCK,
        }
    }

    /// The next normal numbers of every lane, at most `max` of them and at least one: a run of
    /// [`Self::normal`]'s results, handed over at once.
    #[inline(always)]
    pub fn normals(&mut self, max: usize) -> &[Lanes] {
        if self.pos == BLOCK {
            refill(self);
        }
        let start = self.pos;
        let end = (start + max).min(BLOCK);
        self.pos = end;
        &self.buf[start..end]
    }

    /// The next standard normal number of every lane, each the number its scalar stream draws.
    #[inline(always)]
    pub fn normal(&mut self) -> Lanes {
        if self.pos == BLOCK {
            refill(self);
        }
        let x = self.buf[self.pos];
        self.pos += 1;
        x
    }
}

#[inline(always)]
fn refill_lanes(r: &mut LaneStreams) {
    let z = ziggurat();
    let [mut s0, mut s1, mut s2, mut s3] = r.s;
    // Bit t of fail[k]: lane k's draw t fell outside the fast path.
    let mut fail = [0u64; LANES];
    for t in 0..BLOCK {
        for k in 0..LANES {
            let out = (s0[k].wrapping_add(s3[k]))
                .rotate_left(23)
                .wrapping_add(s0[k]);
            let u = s1[k] << 17;
            s2[k] ^= s0[k];
            s3[k] ^= s1[k];
            s1[k] ^= s2[k];
            s0[k] ^= s3[k];
            s2[k] ^= u;
            s3[k] = s3[k].rotate_left(45);
            r.bits[t][k] = out;
            let (x, ok) = z.fast(out);
            r.buf[t].0[k] = x;
            fail[k] |= u64::from(!ok) << t;
        }
    }
    r.s = [s0, s1, s2, s3];
    r.pos = 0;
    if fail.iter().fold(0, |a, &f| a | f) != 0 {
        finish(r, &fail);
    }
}

crate::lanes::vectorized! {
    fn refill(r: &mut LaneStreams) -> () => refill_lanes
}

/// Finishes, lane by lane and in draw order, the draws that fell outside the fast path, with the
/// scalar code.
#[cold]
#[inline(never)]
fn finish(r: &mut LaneStreams, fail: &[u64; LANES]) {
    let z = ziggurat();
    for k in 0..LANES {
        let mut left = fail[k];
        if left == 0 {
            continue;
        }
        let mut one = Core(std::array::from_fn(|w| r.s[w][k]));
        while left != 0 {
            let t = left.trailing_zeros() as usize;
            left &= left - 1;
            r.buf[t].0[k] = z.slow(r.bits[t][k], r.buf[t].0[k], &mut one);
        }
        for w in 0..4 {
            r.s[w][k] = one.0[w];
        }
    }
}

#[inline(always)]
fn normals_sum_lanes(key: u64, first: u64, draws: usize) -> f64 {
    let mut r = LaneStreams::new(key, first);
    let mut acc = Lanes::default();
    for _ in 0..draws {
        acc += r.normal();
    }
    acc.sum()
}

crate::lanes::vectorized! {
    /// The random-number bound for benchmarks: `draws` normal numbers in each lane of the group
    /// of realizations `first..first + LANES`, summed.
    pub fn normals_sum(key: u64, first: u64, draws: usize) -> f64 => normals_sum_lanes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xoshiro_matches_the_reference_output() {
        // xoshiro256++ from state (1, 2, 3, 4): the reference implementation's first outputs.
        let mut r = Stream::new(0, 0);
        r.core = Core([1, 2, 3, 4]);
        let first: Vec<u64> = (0..3).map(|_| r.next_u64()).collect();
        assert_eq!(first, [41943041, 58720359, 3588806011781223]);
    }

    #[test]
    fn rand_draws_the_streams_own_bits() {
        // Through rand's trait a stream hands out its xoshiro256++ words: a u64 whole, a u32 as
        // the high half, bytes little-endian; the buffered normal numbers are left alone.
        let mut ours = Stream::new(3, 7);
        let mut theirs = ours.clone();
        assert_eq!(ours.normal().to_bits(), theirs.normal().to_bits());
        assert_eq!(rand::Rng::next_u64(&mut theirs), ours.next_u64());
        assert_eq!(
            u64::from(rand::Rng::next_u32(&mut theirs)),
            ours.next_u64() >> 32
        );
        let mut bytes = [0u8; 8];
        rand::Rng::fill_bytes(&mut theirs, &mut bytes);
        assert_eq!(u64::from_le_bytes(bytes), ours.next_u64());
        assert_eq!(ours.normal().to_bits(), theirs.normal().to_bits());
    }

    #[test]
    fn lanes_draw_what_scalar_streams_draw() {
        let mut lanes = LaneStreams::new(99, 1000);
        let mut scalar: Vec<Stream> = (0..LANES as u64)
            .map(|k| Stream::new(99, 1000 + k))
            .collect();
        for _ in 0..20_000 {
            let v = lanes.normal();
            for k in 0..LANES {
                assert_eq!(v.0[k].to_bits(), scalar[k].normal().to_bits());
            }
        }
    }

    #[test]
    fn normals_have_the_standard_moments_and_tails() {
        // 4·10⁶ draws: the mean within 5σ (σ = 1/√n = 5·10⁻⁴), the variance within 5σ
        // (σ = √(2/n) ≈ 7.1·10⁻⁴), and P(|x| > 3) = 0.0026998 within 5σ of a binomial count; a
        // false alarm has probability below 10⁻⁵.
        let n = 4_000_000;
        let mut r = Stream::new(5, 0);
        let (mut s1, mut s2, mut tail) = (0.0, 0.0, 0u64);
        for _ in 0..n {
            let x = r.normal();
            s1 += x;
            s2 += x * x;
            tail += u64::from(x.abs() > 3.0);
        }
        let n_f = n as f64;
        assert!((s1 / n_f).abs() < 5.0 / n_f.sqrt());
        assert!((s2 / n_f - 1.0).abs() < 5.0 * (2.0 / n_f).sqrt());
        let p = 0.002_699_796_063_260_2;
        let sd = (n_f * p * (1.0 - p)).sqrt();
        assert!((tail as f64 - n_f * p).abs() < 5.0 * sd, "tail {tail}");
    }
}
