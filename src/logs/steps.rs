//! The time steps of a log: their median in bounded memory, and the band of steps accepted
//! around it.

use std::collections::BTreeMap;

/// Accepted steps lie between these multiples of the median step. A longer step is a gap (a
/// sample lost: twice the median), a shorter one an extra sample; jitter of a few per cent passes.
pub const ACCEPTED_STEP_RATIO: (f64, f64) = (0.5, 1.5);

/// Most distinct keys the histogram holds before it halves its resolution.
pub const MAX_BUCKETS: usize = 4096;

/// The median of positive steps, in memory bounded by [`MAX_BUCKETS`] whatever the log's length.
///
/// Steps are counted in a histogram keyed by their bit pattern (which orders positive doubles
/// like their values). While it holds at most 4096 distinct keys the median is exact; beyond, the
/// keys drop their lowest mantissa bit, one at a time, until they fit: the median is then the
/// middle of its bucket, within [`StepMedian::relative_resolution`] of the exact one. Time stamps
/// written at a fixed rate give a handful of distinct steps; jitter of ±10 % needs a resolution
/// of about 10⁻⁴.
#[derive(Clone, Debug, Default)]
pub struct StepMedian {
    shift: u32,
    counts: BTreeMap<u64, u64>,
    n: u64,
}

impl StepMedian {
    /// An empty histogram.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counts one step, s (positive and finite: time stamps are strictly increasing).
    pub fn add(&mut self, step_s: f64) {
        *self
            .counts
            .entry(step_s.to_bits() >> self.shift)
            .or_insert(0) += 1;
        self.n += 1;
        while self.counts.len() > MAX_BUCKETS {
            self.shift += 1;
            let mut coarser = BTreeMap::new();
            for (k, c) in std::mem::take(&mut self.counts) {
                *coarser.entry(k >> 1).or_insert(0) += c;
            }
            self.counts = coarser;
        }
    }

    /// Number of steps counted.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Relative resolution of the median: 0 while exact, else 2^(shift − 52).
    pub fn relative_resolution(&self) -> f64 {
        if self.shift == 0 {
            0.0
        } else {
            2f64.powi(self.shift as i32 - 52)
        }
    }

    /// The value a key stands for: itself while exact, else the middle of its bucket.
    fn value(&self, key: u64) -> f64 {
        if self.shift == 0 {
            f64::from_bits(key)
        } else {
            f64::from_bits((key << self.shift) | (1u64 << (self.shift - 1)))
        }
    }

    /// The median step (the mean of the two middle ones for an even count), s; `None` without
    /// steps.
    pub fn median(&self) -> Option<f64> {
        if self.n == 0 {
            return None;
        }
        // 0-based ranks of the middle steps.
        let (lo, hi) = ((self.n - 1) / 2, self.n / 2);
        let (mut below, mut at_lo, mut at_hi) = (0u64, None, None);
        for (&k, &c) in &self.counts {
            if at_lo.is_none() && lo < below + c {
                at_lo = Some(self.value(k));
            }
            if hi < below + c {
                at_hi = Some(self.value(k));
                break;
            }
            below += c;
        }
        Some(0.5 * (at_lo? + at_hi?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_few_distinct_steps() {
        let mut m = StepMedian::new();
        for s in [0.005, 0.004, 0.006, 0.005, 0.003] {
            m.add(s);
        }
        assert_eq!(m.median(), Some(0.005));
        m.add(0.007);
        assert_eq!(m.median(), Some(0.005));
        m.add(0.007);
        m.add(0.007);
        assert_eq!(m.median(), Some(0.5 * (0.005 + 0.006)));
        assert_eq!(m.relative_resolution(), 0.0);
        assert_eq!(StepMedian::new().median(), None);
    }

    #[test]
    fn bounded_and_close_for_many_distinct_steps() {
        let mut m = StepMedian::new();
        let n = 200_001u64;
        // A permutation of 0..n, so the steps arrive out of order; median at k = 100 000.
        for i in 0..n {
            let k = (i * 7919) % n;
            m.add(0.005 * (1.0 + 0.1 * (k as f64 / n as f64 - 0.5)));
        }
        assert!(m.counts.len() <= MAX_BUCKETS);
        let exact = 0.005 * (1.0 + 0.1 * (100_000.0 / n as f64 - 0.5));
        let got = m.median().unwrap();
        assert!(
            m.relative_resolution() < 1e-4,
            "{}",
            m.relative_resolution()
        );
        assert!(
            (got / exact - 1.0).abs() <= m.relative_resolution(),
            "{got} vs {exact}"
        );
    }
}
