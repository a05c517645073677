//! The memory a run is predicted to need: the running sums of its blocks of realizations and
//! what each command keeps per accelerometer sample and per fix.

use super::{ALL_PAIRS_MAX_FIXES, DEFAULT_MAX_LAG, RESIDUAL_WIDTH, SUM_FLOATS_PER_FIX};
use crate::config::Config;

/// The bytes of the running sums of one block of realizations over `fixes` fixes: the fix-level
/// sums ([`SUM_FLOATS_PER_FIX`] per fix) and the kept residual products (every pair, or a band
/// of lags).
pub(super) fn sums_bytes(c: &Config, fixes: u64) -> f64 {
    let f = fixes as f64;
    let lag = match c.checks.residual_max_lag {
        Some(l) => Some(f64::from(l)),
        None if fixes as usize <= ALL_PAIRS_MAX_FIXES => None,
        None => Some(DEFAULT_MAX_LAG as f64),
    };
    // The residual stacks M components per fix: M·f rows, of which a band of lags up to l keeps
    // M·(l + 1) columns each, every pair the M·f·(M·f + 1)/2 of the lower triangle.
    let m = RESIDUAL_WIDTH as f64;
    let products = match lag {
        Some(l) if l + 1.0 < f => m * f * (m * l + m),
        _ => m * f * (m * f + 1.0) / 2.0,
    };
    std::mem::size_of::<f64>() as f64 * (SUM_FLOATS_PER_FIX as f64 * f + products)
}

/// The work of a command, for its memory estimate ([`super::Model::peak_memory`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// One ensemble (or one shard of it) and its JSON.
    Ensemble,
    /// The sensitivity study.
    Sensitivity,
    /// The report: every case's ensemble, the sensitivity study, the page and its data.
    Report,
    /// One realization written at every accelerometer sample.
    Simulate,
}

impl Work {
    /// Bytes held whatever the size, per accelerometer sample and per fix at the peak, measured
    /// (maximum resident set of runs from 5·10³ to 4·10⁵ fixes and 10⁷ samples, docs/SPEED.md)
    /// and rounded up: the filter schedule and the per-fix statistics an ensemble (its JSON is
    /// written as it is made, never held whole); the sensitivity study's filters and ensembles;
    /// every case's statistics, the data and the page a report, which also simulates and
    /// analyses 100 static logs of fixed size; the CSV text, built whole, a simulation.
    fn bytes_fixed_per_sample_and_fix(self) -> (f64, f64, f64) {
        match self {
            Work::Ensemble => (0.0, 24.0, 2048.0),
            Work::Sensitivity => (0.0, 24.0, 6144.0),
            Work::Report => (144.0 * 1048576.0, 24.0, 13312.0),
            Work::Simulate => (0.0, 640.0, 1024.0),
        }
    }
}

/// A run's predicted peak memory and the configuration key that sizes it most.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// Predicted peak resident memory, bytes: an upper bound within a factor 2 of the measured
    /// peak at the sizes measured (tests/work_size.rs).
    pub bytes: f64,
    /// The key whose share is the largest: `profile.duration_s` (samples), `gps.sample_rate_hz`
    /// (fixes: the per-fix bytes and the fix-level running sums) or `checks.residual_max_lag`
    /// (the residual products of the running sums).
    pub key: &'static str,
    /// The terms in words.
    pub terms: String,
}

/// Realizations of the smallest block of an ensemble: one chunk, `ensemble::CHUNK` (named here,
/// not imported: the ensemble depends on the model; tests/work_size.rs checks that they agree).
const CHUNK_REALIZATIONS: u64 = 64;

/// Resident memory of the program itself, bytes.
const BASE_BYTES: f64 = 8.0 * 1048576.0;

impl super::Model {
    /// The predicted peak memory of `work` on `threads` threads.
    ///
    /// # Formula
    /// bytes = 8 MiB + c + samples·s + fixes·f + blocks·B + workers·(P + R), where c, s and f
    /// are the work's fixed bytes and bytes per sample and per fix, B the bytes of one block's
    /// running sums and P those of its residual products alone; blocks =
    /// min(2·threads, ⌈N/64⌉) + 1 for the ensembles (each thread sums a block while another
    /// waits for its turn, a block holds at least a chunk of 64 of the N realizations, and the
    /// total) and 0 for a simulation; workers = threads for the ensembles and 0 for a
    /// simulation. Each worker keeps the tiles it sums the products in, about as large as the
    /// products (P: every pair of a run of 1 000 fixes makes them 16 MB), and the residuals of
    /// a pass of up to 128 realizations in single precision, R = 4 bytes · 2·fixes · min(N, 128).
    pub fn peak_memory(&self, work: Work, threads: usize) -> MemoryEstimate {
        let (fixed, per_sample, per_fix) = work.bytes_fixed_per_sample_and_fix();
        let samples = self.timeline.steps as f64 + 1.0;
        let fixes = self.timeline.fixes() as f64;
        let (blocks, workers) = match work {
            Work::Simulate => (0.0, 0.0),
            _ => {
                let least = self
                    .config
                    .ensemble
                    .realizations
                    .div_ceil(CHUNK_REALIZATIONS);
                let threads = threads.max(1) as u64;
                ((2 * threads).min(least) as f64 + 1.0, threads as f64)
            }
        };
        let block = sums_bytes(&self.config, self.timeline.fixes() as u64);
        let fix_sum = fixes * (std::mem::size_of::<f64>() * SUM_FLOATS_PER_FIX) as f64;
        let pass = self
            .config
            .ensemble
            .realizations
            .min(2 * CHUNK_REALIZATIONS) as f64;
        let residuals = (std::mem::size_of::<f32>() * RESIDUAL_WIDTH) as f64 * fixes * pass;
        let sums = blocks * block + workers * (block - fix_sum + residuals);
        let terms = [
            (samples * per_sample, "profile.duration_s"),
            (fixes * per_fix, "gps.sample_rate_hz"),
            (sums, "checks.residual_max_lag"),
        ];
        // The fix-level sums and the residuals grow with the fixes alone, only the residual
        // products with the lags too: the key names what lowers the larger share.
        let products = (blocks + workers) * (block - fix_sum);
        let shares = [terms[0].0, terms[1].0 + sums - products, products];
        let key = shares
            .iter()
            .zip(&terms)
            .max_by(|a, b| a.0.total_cmp(b.0))
            .map_or("profile.duration_s", |(_, t)| t.1);
        let mb = |b: f64| b / 1e6;
        MemoryEstimate {
            bytes: BASE_BYTES + fixed + terms.iter().map(|t| t.0).sum::<f64>(),
            key,
            terms: format!(
                "{samples} samples × {per_sample} B = {:.0} MB, {fixes} fixes × {per_fix} B = \
                 {:.0} MB, {blocks} blocks of running sums, {workers} workers' tiles and residuals = {:.0} MB",
                mb(terms[0].0),
                mb(terms[1].0),
                mb(sums)
            ),
        }
    }
}
