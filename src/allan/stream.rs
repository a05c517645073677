//! The overlapping Allan variance at every octave τ of a log read once, in memory independent of
//! its length: the samples arrive in any pieces, none is kept past the window of the longest
//! exact τ.
//!
//! # Formula
//! Up to [`EXACT_MAX_M`] the estimator is [`deviation`]'s (NIST SP 1065, eq. 11), summed in the
//! same stretches and blocks over a window of the phase 2·[`EXACT_MAX_M`] + [`STRETCH`] long: the
//! same bits as [`deviation::overlapping_avars`] on the whole phase. Beyond, at τ = mτ₀ with
//! m > [`EXACT_MAX_M`], the second differences are taken at the offsets k that are multiples of
//! the stride s = m / [`OFFSETS_PER_TAU`] only: NIST SP 1065's eq. (11) with a step of s between
//! its terms (s = 1 is eq. (11) itself, s = m the non-overlapping Allan variance of the same
//! handbook):
//!
//! σ̂²(mτ₀) = Σ_{k ∈ sℤ, 0 ≤ k ≤ n − 2m} (x_{k+2m} − 2x_{k+m} + x_k)² / (2 T m²),  T the terms.
//!
//! Each such τ keeps 2·[`OFFSETS_PER_TAU`] + 1 phase values at its stride. Terms s apart share
//! all but a fraction s/m = 1/[`OFFSETS_PER_TAU`] of their samples, so the strided estimate
//! averages nearly the same information as the full one; its departure from the exact value is
//! measured in `tests/allan_imu_stream.rs` and stated in docs/guide/allan.md.
//!
//! The phase is the one of [`deviation::phase`] given the log's mean ȳ (found by a first read):
//! x_0 = 0, the running sum of y − ȳ in stretches of [`STRETCH`] samples.

use super::deviation::{self, BLOCK, STRETCH};
use super::noise_id::NoiseId;
use super::noise_stream::StreamingNoiseId;

/// The largest averaging factor computed exactly (every offset): τ up to 655 s at 400 Hz.
pub const EXACT_MAX_M: usize = 1 << 18;

/// Offsets per τ beyond [`EXACT_MAX_M`]: the stride is m / 4096.
pub const OFFSETS_PER_TAU: usize = 1 << 12;

/// The mean of a log read piece by piece, with the same bits as [`deviation::mean`] of the whole.
#[derive(Clone, Debug)]
pub struct StreamingMean {
    /// The current block of [`BLOCK`] samples.
    block: Vec<f64>,
    /// Σ of the completed blocks' sums, in order.
    total: f64,
    count: u64,
}

impl Default for StreamingMean {
    fn default() -> Self {
        Self {
            block: Vec::with_capacity(BLOCK),
            total: std::iter::empty::<f64>().sum(),
            count: 0,
        }
    }
}

impl StreamingMean {
    /// Counts the next sample.
    #[inline]
    pub fn push(&mut self, y: f64) {
        self.block.push(y);
        self.count += 1;
        if self.block.len() == BLOCK {
            self.total += self.block.iter().sum::<f64>();
            self.block.clear();
        }
    }

    /// Samples counted.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The mean ȳ.
    pub fn mean(&self) -> f64 {
        let mut total = self.total;
        if !self.block.is_empty() {
            total += self.block.iter().sum::<f64>();
        }
        total / self.count as f64
    }
}

/// One τ beyond [`EXACT_MAX_M`]: the phase at its stride over the last 2m, and its sum.
#[derive(Clone, Debug)]
struct StridedTau {
    m: usize,
    stride: usize,
    /// x at indices q·stride, slot q mod (2·OFFSETS_PER_TAU + 1).
    ring: Vec<f64>,
    sum: f64,
    terms: u64,
}

const RING: usize = 2 * OFFSETS_PER_TAU + 1;

impl StridedTau {
    /// The τ whose phase at its stride, indices 0, s, …, 2m, is `history`.
    fn start(m: usize, history: &[f64]) -> Self {
        debug_assert_eq!(history.len(), RING);
        let mut t = Self {
            m,
            stride: m / OFFSETS_PER_TAU,
            ring: history.to_vec(),
            sum: 0.0,
            terms: 0,
        };
        t.term(2 * OFFSETS_PER_TAU);
        t
    }

    /// The term whose newest phase value sits at stride index q (already stored).
    #[inline]
    fn term(&mut self, q: usize) {
        let at = |k: usize| self.ring[k % RING];
        let d = at(q) - 2.0 * at(q - OFFSETS_PER_TAU) + at(q - 2 * OFFSETS_PER_TAU);
        self.sum += d * d;
        self.terms += 1;
    }
}

/// The Allan variance and noise identification of every octave τ of one channel, fed its
/// samples in order.
#[derive(Clone, Debug)]
pub struct AllanStream {
    mean: f64,
    /// Samples n so far; the phase has n + 1 points.
    samples: usize,
    /// The running phase, the current stretch's own running total and its start.
    phase: f64,
    stretch_total: f64,
    stretch_start: f64,
    /// The phase from index `window_base` on.
    window: Vec<f64>,
    window_base: usize,
    /// The first k of the stretch not yet summed.
    next_k: usize,
    /// Per exact factor 1, 2, …, EXACT_MAX_M: Σ over processed stretches, in stretch order.
    exact_sums: Vec<f64>,
    /// τ beyond EXACT_MAX_M that have started, and the phase at the next one's stride.
    strided: Vec<StridedTau>,
    history: Vec<f64>,
    /// Per octave m = 2^j: the block means' identification and the phase at the last boundary.
    noise: Vec<(StreamingNoiseId, f64)>,
}

/// The exact factors.
fn exact_factors() -> impl Iterator<Item = usize> {
    (0..=EXACT_MAX_M.trailing_zeros()).map(|j| 1usize << j)
}

impl AllanStream {
    /// An empty stream whose samples have the mean `mean_y` (the phase subtracts it).
    pub fn new(mean_y: f64) -> Self {
        Self {
            mean: mean_y,
            samples: 0,
            phase: 0.0,
            stretch_total: std::iter::empty::<f64>().sum(),
            stretch_start: 0.0,
            window: vec![0.0],
            window_base: 0,
            next_k: 0,
            exact_sums: exact_factors()
                .map(|_| std::iter::empty::<f64>().sum())
                .collect(),
            strided: Vec::new(),
            history: vec![0.0],
            noise: Vec::new(),
        }
    }

    /// The next factor beyond the exact ones that has not started, and its stride.
    fn next_strided(&self) -> (usize, usize) {
        let m = EXACT_MAX_M << (self.strided.len() + 1);
        (m, m / OFFSETS_PER_TAU)
    }

    /// Counts the next samples.
    pub fn extend(&mut self, y: &[f64]) {
        for piece in y.chunks(STRETCH) {
            for &v in piece {
                self.push(v);
            }
            self.process_stretches();
        }
    }

    #[inline]
    fn push(&mut self, v: f64) {
        let i = self.samples;
        if i.is_multiple_of(STRETCH) && i > 0 {
            // deviation::phase: each stretch starts from the sum of the stretch totals before.
            self.stretch_start += self.stretch_total;
            self.stretch_total = std::iter::empty::<f64>().sum();
            self.phase = self.stretch_start;
        }
        let d = v - self.mean;
        self.stretch_total += d;
        self.phase += d;
        self.samples += 1;
        let (i, x) = (i + 1, self.phase);
        self.window.push(x);
        // Block means of every octave m dividing i.
        let mut j = 0;
        while j <= i.trailing_zeros() as usize && (1usize << j) <= i {
            let m = 1usize << j;
            if j == self.noise.len() {
                self.noise.push((StreamingNoiseId::default(), 0.0));
            }
            let (id, last) = &mut self.noise[j];
            id.push((x - *last) / m as f64);
            *last = x;
            j += 1;
        }
        // Strides are powers of two: a mask, not a division, per sample.
        for t in &mut self.strided {
            if i & (t.stride - 1) == 0 {
                let q = i / t.stride;
                t.ring[q % RING] = x;
                t.term(q);
            }
        }
        let (next_m, next_stride) = self.next_strided();
        if i & (next_stride - 1) == 0 {
            self.history.push(x);
            if i == 2 * next_m {
                self.strided.push(StridedTau::start(next_m, &self.history));
                // The next factor's stride is twice this one's: every other value so far.
                self.history = self.history.iter().step_by(2).copied().collect();
            }
        }
    }

    /// Sums every stretch of k whose terms at every exact factor are in the window, and drops
    /// the phase no later term needs.
    fn process_stretches(&mut self) {
        let factors: Vec<usize> = exact_factors().collect();
        let points = self.samples + 1;
        let mut from = self.next_k;
        let unbounded = vec![usize::MAX; factors.len()];
        while from + STRETCH + 2 * EXACT_MAX_M <= points {
            self.add_stretch(&factors, from, from + STRETCH, &unbounded);
            from += STRETCH;
        }
        self.next_k = from;
        // The phase before `from` is dropped once it is EXACT_MAX_M long: a copy of the window
        // per EXACT_MAX_M samples, and a window of at most 3·EXACT_MAX_M + STRETCH points.
        if from >= self.window_base + EXACT_MAX_M {
            self.window.drain(..from - self.window_base);
            self.window_base = from;
        }
    }

    /// Adds the sums over k in [from, to) at `factors`, k < `terms` of each.
    fn add_stretch(&mut self, factors: &[usize], from: usize, to: usize, terms: &[usize]) {
        let base = self.window_base;
        let relative: Vec<usize> = terms.iter().map(|t| t.saturating_sub(base)).collect();
        let sums =
            deviation::stretch_sums(&self.window, factors, &relative, from - base, to - base);
        for (total, s) in self.exact_sums.iter_mut().zip(sums) {
            *total += s;
        }
    }

    /// Samples counted.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The variance and noise at every factor of the octave grid of the samples counted
    /// ([`deviation::octave_factors`]), in order: (m, σ̂², the noise of its block means). The
    /// estimate is the exact one for m ≤ [`EXACT_MAX_M`], the strided one beyond.
    pub fn finish(mut self) -> Vec<(usize, f64, Option<NoiseId>)> {
        let n = self.samples;
        let grid = deviation::octave_factors(n);
        let factors: Vec<usize> = exact_factors().collect();
        let terms: Vec<usize> = factors
            .iter()
            .map(|&m| (n + 1).saturating_sub(2 * m))
            .collect();
        let longest = terms[0];
        let mut from = self.next_k;
        while from < longest {
            let to = (from + STRETCH).min(longest);
            self.add_stretch(&factors, from, to, &terms);
            from += STRETCH;
        }
        grid.iter()
            .enumerate()
            .map(|(j, &m)| {
                let noise = self.noise.get(j).and_then(|(id, _)| id.identify());
                if m <= EXACT_MAX_M {
                    let avar = self.exact_sums[j] / (2.0 * terms[j] as f64 * (m * m) as f64);
                    (m, avar, noise)
                } else {
                    let t = self
                        .strided
                        .iter()
                        .find(|t| t.m == m)
                        .expect("started at 2m ≤ n");
                    (m, t.sum / (2.0 * t.terms as f64 * (m * m) as f64), noise)
                }
            })
            .collect()
    }
}
