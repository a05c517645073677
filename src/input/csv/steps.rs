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
    /// Count of each key, and the first step counted under it.
    counts: BTreeMap<u64, (u64, StepAt)>,
    n: u64,
    /// The keys counted last, with counts not yet in `counts`: a log at a fixed rate has a few
    /// distinct steps, so most steps are counted here without a search of the map.
    hot: [(u64, u64); HOT_KEYS],
    /// The entry of `hot` replaced next.
    evict: usize,
}

/// Keys counted without a search of the map.
const HOT_KEYS: usize = 8;

/// A key no step has (the bits of a NaN).
const NO_KEY: u64 = u64::MAX;

/// Where a step was taken: the line and time stamp of the sample it ends at, and the time
/// stamp before.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepAt {
    /// Index of the sample the step ends at (0 = the log's first).
    pub sample: u64,
    /// Its line in the file.
    pub line: u64,
    /// The time stamp before, s.
    pub previous_s: f64,
    /// The time stamp the step ends at, s.
    pub t_s: f64,
}

impl StepAt {
    /// The step, s.
    pub fn step_s(&self) -> f64 {
        self.t_s - self.previous_s
    }
}

impl StepMedian {
    /// An empty histogram.
    pub fn new() -> Self {
        Self {
            hot: [(NO_KEY, 0); HOT_KEYS],
            ..Self::default()
        }
    }

    /// Counts one step, s (positive and finite: time stamps are strictly increasing).
    pub fn add(&mut self, step_s: f64) {
        self.add_at(step_s, StepAt::default());
    }

    /// Counts one step taken `at` (its step is `step_s`), keeping the first step of each key.
    #[inline]
    pub fn add_at(&mut self, step_s: f64, at: StepAt) {
        let key = step_s.to_bits() >> self.shift;
        self.n += 1;
        if let Some(hot) = self.hot.iter_mut().find(|(k, _)| *k == key) {
            hot.1 += 1;
            return;
        }
        self.counts.entry(key).or_insert((0, at)).0 += 1;
        let (old, count) = std::mem::replace(&mut self.hot[self.evict], (key, 0));
        self.evict = (self.evict + 1) % HOT_KEYS;
        if old != NO_KEY {
            self.counts
                .get_mut(&old)
                .expect("a hot key is in the map")
                .0 += count;
        }
        while self.counts.len() > MAX_BUCKETS {
            self.coarsen();
        }
    }

    /// Moves the hot counts into the map.
    fn settle(&mut self) {
        for (key, count) in std::mem::replace(&mut self.hot, [(NO_KEY, 0); HOT_KEYS]) {
            if key != NO_KEY {
                self.counts
                    .get_mut(&key)
                    .expect("a hot key is in the map")
                    .0 += count;
            }
        }
    }

    /// Halves the resolution: keys drop their lowest bit; a bucket keeps its earliest step.
    fn coarsen(&mut self) {
        self.settle();
        self.shift += 1;
        let mut coarser: BTreeMap<u64, (u64, StepAt)> = BTreeMap::new();
        for (k, (c, at)) in std::mem::take(&mut self.counts) {
            let e = coarser.entry(k >> 1).or_insert((0, at));
            e.0 += c;
            if at.sample < e.1.sample {
                e.1 = at;
            }
        }
        self.counts = coarser;
    }

    /// The earliest step outside `[lo_s, hi_s]` among the first steps of the keys: exact while
    /// the histogram is ([`StepMedian::relative_resolution`] 0), else among steps that are.
    pub fn first_outside(&self, lo_s: f64, hi_s: f64) -> Option<StepAt> {
        self.counts
            .values()
            .map(|(_, at)| *at)
            .filter(|at| !(lo_s..=hi_s).contains(&at.step_s()))
            .min_by_key(|at| at.sample)
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
        let mut counts = self.counts.clone();
        for &(key, count) in &self.hot {
            if key != NO_KEY {
                counts.get_mut(&key).expect("a hot key is in the map").0 += count;
            }
        }
        let (mut below, mut at_lo, mut at_hi) = (0u64, None, None);
        for (&k, &(c, _)) in &counts {
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
