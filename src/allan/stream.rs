//! The overlapping Allan variance at every octave τ of a log read once, in memory independent of
//! its length: the samples arrive in any pieces, none is kept past the window of the longest
//! exact τ.
//!
//! # Formula
//! Up to [`EXACT_MAX_M`] the estimator is [`deviation`]'s (NIST SP 1065, eq. 11), summed in the
//! same stretches and blocks over a window of the phase 2·[`EXACT_MAX_M`] + [`STRETCH`] long: the
//! same bits as [`deviation::overlapping_avars`] on the whole phase. The longer τ of a log with
//! more than 2·[`EXACT_MAX_M`] samples are summed at the end from the phase written to a
//! temporary file as it grows ([`spill`]), again in the same stretches and blocks:
//! every τ has the whole-series form's bits.
//!
//! The phase is the one of [`deviation::phase`] given the log's mean ȳ (found by a first read):
//! x_0 = 0, the running sum of y − ȳ in stretches of [`STRETCH`] samples.

use std::io;
use std::path::Path;

use super::deviation::{self, BLOCK, STRETCH};
use super::noise_id::NoiseId;
use super::noise_stream::StreamingNoiseId;
use super::spill::{self, PhaseSpill};

/// The largest averaging factor computed exactly (every offset): τ up to 655 s at 400 Hz.
pub const EXACT_MAX_M: usize = 1 << 18;

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

/// The Allan variance and noise identification of every octave τ of one channel, fed its
/// samples in order.
#[derive(Debug)]
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
    /// The whole phase on disk, when the log has τ beyond EXACT_MAX_M.
    spill: Option<PhaseSpill>,
    /// Per octave m = 2^j: the block means' identification and the phase at the last boundary.
    noise: Vec<(StreamingNoiseId, f64)>,
}

/// The exact factors.
fn exact_factors() -> impl Iterator<Item = usize> {
    (0..=EXACT_MAX_M.trailing_zeros()).map(|j| 1usize << j)
}

impl AllanStream {
    /// An empty stream for a log of `samples` samples whose mean is `mean_y` (the phase
    /// subtracts it). When that many samples have octave τ beyond [`EXACT_MAX_M`], the phase is
    /// also written to a temporary file in `spill_dir` (8 bytes a sample, removed with the
    /// stream).
    ///
    /// # Errors
    /// The [`io::Error`] of creating the temporary file.
    pub fn new(mean_y: f64, samples: usize, spill_dir: &Path) -> io::Result<Self> {
        let long = deviation::octave_factors(samples)
            .iter()
            .any(|&m| m > EXACT_MAX_M);
        let spill = if long {
            let mut spill = PhaseSpill::create(spill_dir)?;
            spill.push(0.0);
            Some(spill)
        } else {
            None
        };
        Ok(Self {
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
            spill,
            noise: Vec::new(),
        })
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
        if let Some(spill) = &mut self.spill {
            spill.push(x);
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
    /// ([`deviation::octave_factors`]), in order: (m, σ̂², the noise of its block means), each
    /// σ̂² the whole-series estimate's bits.
    ///
    /// # Errors
    /// The [`io::Error`] of the temporary file (writing it, or reading it back), or
    /// [`io::ErrorKind::InvalidInput`] when more samples came than [`AllanStream::new`] was told
    /// and the log has τ it kept no phase for.
    pub fn finish(mut self) -> io::Result<Vec<(usize, f64, Option<NoiseId>)>> {
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
        let long: Vec<usize> = grid.iter().copied().filter(|&m| m > EXACT_MAX_M).collect();
        let long_sums = match (&mut self.spill, long.is_empty()) {
            (_, true) => Vec::new(),
            (Some(spill), false) => spill::second_difference_sums(spill, &long)?,
            (None, false) => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("{n} samples: more than the stream was created for"),
                ));
            }
        };
        Ok(grid
            .iter()
            .enumerate()
            .map(|(j, &m)| {
                let noise = self.noise.get(j).and_then(|(id, _)| id.identify());
                let sum = if m <= EXACT_MAX_M {
                    self.exact_sums[j]
                } else {
                    long_sums[j - factors.len()]
                };
                let terms = (n + 1 - 2 * m) as f64;
                (m, sum / (2.0 * terms * (m * m) as f64), noise)
            })
            .collect())
    }
}
