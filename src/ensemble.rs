//! The Monte Carlo ensemble: N realizations run in parallel and accumulated as they are produced.
//!
//! Memory does not grow with N: realizations are grouped into chunks of [`CHUNK`] consecutive
//! indices, each chunk is summed into its own [`Accumulator`], and chunk accumulators are merged
//! into the total in chunk order. The chunk boundaries depend on N alone, so the result is
//! bit-for-bit the same on one thread or many.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::filter::{FilterSchedule, Matrix3, Vector3};
use crate::model::Model;
use crate::simulation::{FixState, Observer, run_realization};

/// Realizations summed sequentially into one accumulator before it is merged.
pub const CHUNK: u64 = 64;

/// Memory the chunk accumulators in flight may take together, bytes.
const WINDOW_BYTES: u64 = 256 << 20;

/// Running sums over realizations of one estimate stage (a priori or a posteriori) at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageSums {
    /// Σ e, e = δx − δx̂.
    pub e: Vector3,
    /// Σ e·eᵀ, upper triangle in the order (00, 01, 02, 11, 12, 22).
    pub ee: [f64; 6],
    /// Σ e·δx̂ᵀ.
    pub ex: Matrix3,
    /// Σ δx̂.
    pub x: Vector3,
    /// Σ δx̂_k², the diagonal of Σ δx̂·δx̂ᵀ.
    pub xx: Vector3,
    /// Σ eᵀ·P⁻¹·e (the normalized estimation error squared).
    pub nees: f64,
}

/// Upper-triangle index pairs of a symmetric 3×3 matrix, in [`StageSums::ee`] order.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

impl StageSums {
    #[inline]
    fn add(&mut self, e: &Vector3, x: &Vector3, p_inv: &Matrix3) {
        self.e += e;
        let mut nees = 0.0;
        for (s, &(r, c)) in self.ee.iter_mut().zip(&UPPER) {
            let prod = e[r] * e[c];
            *s += prod;
            // eᵀP⁻¹e over the upper triangle: off-diagonal terms count twice.
            nees += if r == c { 1.0 } else { 2.0 } * p_inv[(r, c)] * prod;
        }
        self.ex += e * x.transpose();
        self.x += x;
        self.xx += x.component_mul(x);
        self.nees += nees;
    }

    /// Σ e·eᵀ as a full matrix.
    pub fn ee_matrix(&self) -> Matrix3 {
        let mut m = Matrix3::zeros();
        for (v, &(r, c)) in self.ee.iter().zip(&UPPER) {
            m[(r, c)] = *v;
            m[(c, r)] = *v;
        }
        m
    }

    fn merge(&mut self, o: &Self) {
        self.e += o.e;
        for (a, b) in self.ee.iter_mut().zip(&o.ee) {
            *a += b;
        }
        self.ex += o.ex;
        self.x += o.x;
        self.xx += o.xx;
        self.nees += o.nees;
    }
}

/// Running sums at one fix.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixSums {
    pub prior: StageSums,
    pub post: StageSums,
    /// Σ rᵀ·S⁻¹·r (the normalized innovation squared).
    pub nis: f64,
}

/// Running sums of an ensemble, or of part of one.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    /// Realizations summed.
    pub count: u64,
    /// One entry per fix.
    pub fixes: Vec<FixSums>,
    /// Σ ρ·ρᵀ over realizations, where ρ = (r(t_0), r(t_1), …) stacks every residual: the lower
    /// triangle, diagonal included, packed row by row (row a holds columns 0..=a).
    pub residual_products: Vec<f64>,
}

/// Index of element (a, b), b ≤ a, in a packed lower triangle.
#[inline]
pub fn packed_index(a: usize, b: usize) -> usize {
    debug_assert!(b <= a);
    a * (a + 1) / 2 + b
}

impl Accumulator {
    /// Empty sums for `fixes` GPS fixes.
    pub fn new(fixes: usize) -> Self {
        let m = 2 * fixes;
        Self {
            count: 0,
            fixes: vec![FixSums::default(); fixes],
            residual_products: vec![0.0; m * (m + 1) / 2],
        }
    }

    /// Adds `other` to these sums.
    pub fn merge(&mut self, other: &Self) {
        self.count += other.count;
        for (a, b) in self.fixes.iter_mut().zip(&other.fixes) {
            a.prior.merge(&b.prior);
            a.post.merge(&b.post);
            a.nis += b.nis;
        }
        for (a, b) in self
            .residual_products
            .iter_mut()
            .zip(&other.residual_products)
        {
            *a += b;
        }
    }

    /// Adds Σ_q ρ_q·ρ_qᵀ over the stacked residual vectors of a batch (the first `filled` rows of
    /// `batch`, each of length 2·fixes). Batching reads and writes the large packed triangle once
    /// per [`BATCH`] realizations instead of once per realization.
    fn add_residual_batch(&mut self, batch: &mut [f64], filled: usize) {
        let m = 2 * self.fixes.len();
        debug_assert_eq!(batch.len(), BATCH * m);
        // Unused rows contribute nothing: zero them so the fixed-size inner loop stays exact.
        batch[filled * m..].fill(0.0);
        let rows: [&[f64]; BATCH] = std::array::from_fn(|q| &batch[q * m..(q + 1) * m]);
        let mut start = 0;
        for a in 0..m {
            let coef: [f64; BATCH] = std::array::from_fn(|q| rows[q][a]);
            let dst = &mut self.residual_products[start..start + a + 1];
            let cols: [&[f64]; BATCH] = std::array::from_fn(|q| &rows[q][..=a]);
            // Row a of the packed triangle += Σ_q ρ_q[a] · ρ_q[0..=a].
            for (b, d) in dst.iter_mut().enumerate() {
                let mut s = 0.0;
                for q in 0..BATCH {
                    s += coef[q] * cols[q][b];
                }
                *d += s;
            }
            start += a + 1;
        }
    }
}

/// Realizations whose residual products are accumulated in one pass.
const BATCH: usize = 8;

/// Feeds one realization's fixes into an [`Accumulator`].
struct Summer<'a> {
    acc: &'a mut Accumulator,
    schedule: &'a FilterSchedule,
    /// This realization's residuals, stacked: (r_p(t_0), r_v(t_0), r_p(t_1), …).
    stacked: &'a mut [f64],
}

impl Observer for Summer<'_> {
    #[inline]
    fn fix(&mut self, f: &FixState) {
        let cov = &self.schedule.fixes[f.index];
        let sums = &mut self.acc.fixes[f.index];
        sums.prior
            .add(&(f.delta_x - f.prior), &f.prior, &cov.p_prior_inv);
        sums.post
            .add(&(f.delta_x - f.post), &f.post, &cov.p_post_inv);
        sums.nis += f.residual.dot(&(cov.s_inv * f.residual));
        self.stacked[2 * f.index] = f.residual[0];
        self.stacked[2 * f.index + 1] = f.residual[1];
    }
}

/// Sums realizations `range` of `model` into a fresh accumulator.
pub fn accumulate(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    range: std::ops::Range<u64>,
) -> Accumulator {
    let fixes = model.timeline.fixes();
    let m = 2 * fixes;
    let mut acc = Accumulator::new(fixes);
    let mut batch = vec![0.0; BATCH * m];
    let mut filled = 0;
    for l in range {
        let mut summer = Summer {
            acc: &mut acc,
            schedule,
            stacked: &mut batch[filled * m..(filled + 1) * m],
        };
        run_realization(model, schedule, seed, l, &mut summer);
        acc.count += 1;
        filled += 1;
        if filled == BATCH {
            acc.add_residual_batch(&mut batch, filled);
            filled = 0;
        }
    }
    if filled > 0 {
        acc.add_residual_batch(&mut batch, filled);
    }
    acc
}

/// Runs `n` realizations of `model` under `seed` in parallel and returns their sums.
/// `progress` is called with the number of realizations finished so far.
pub fn run(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    n: u64,
    mut progress: impl FnMut(u64),
) -> Accumulator {
    let chunks = n.div_ceil(CHUNK);
    // A window of chunks in flight at once; only its size depends on the thread count, never the
    // chunk boundaries nor the merge order. At most WINDOW_BYTES of accumulators are alive.
    let acc_bytes = 8 * Accumulator::new(model.timeline.fixes())
        .residual_products
        .len()
        .max(1) as u64;
    let threads = rayon::current_num_threads() as u64;
    let window = (4 * threads)
        .min((WINDOW_BYTES / acc_bytes).max(threads))
        .max(1);
    let mut total = Accumulator::new(model.timeline.fixes());
    let mut first = 0;
    while first < chunks {
        let last = (first + window).min(chunks);
        let parts: Vec<Accumulator> = (first..last)
            .into_par_iter()
            .map(|c| accumulate(model, schedule, seed, c * CHUNK..((c + 1) * CHUNK).min(n)))
            .collect();
        for part in &parts {
            total.merge(part);
        }
        progress(total.count);
        first = last;
    }
    total
}

/// Ensemble statistics of one stage (a priori or a posteriori) at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StageStats {
    /// Ensemble mean error e_ave = (1/N) Σ e.
    pub mean_error: [f64; 3],
    /// Unbiased ensemble covariance P_ave = (1/(N−1)) Σ (e − e_ave)(e − e_ave)ᵀ, row-major.
    pub ensemble_cov: [[f64; 3]; 3],
    /// The filter's covariance P, row-major.
    pub filter_cov: [[f64; 3]; 3],
    /// Orthogonality matrix (1/N) Σ (e − e_ave)·δx̂ᵀ, row-major.
    pub orthogonality: [[f64; 3]; 3],
    /// The same, normalized to a correlation: entry (j, k) divided by σ(e_j)·σ(δx̂_k); NaN where
    /// the estimate does not vary over the ensemble.
    #[serde(serialize_with = "crate::export::nan_as_null_matrix")]
    pub orthogonality_corr: [[f64; 3]; 3],
    /// Average normalized estimation error squared (1/N) Σ eᵀ·P⁻¹·e.
    pub nees_avg: f64,
}

/// Ensemble statistics at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixStats {
    /// Time of the fix, s.
    pub time_s: f64,
    pub prior: StageStats,
    pub post: StageStats,
    /// Average normalized innovation squared (1/N) Σ rᵀ·S⁻¹·r.
    pub nis_avg: f64,
}

/// Everything the ensemble measured, ready for the checks and the report.
#[derive(Clone, Debug, PartialEq)]
pub struct EnsembleStats {
    /// Number of realizations N.
    pub realizations: u64,
    /// One entry per fix.
    pub fixes: Vec<FixStats>,
    /// (1/N) Σ ρ·ρᵀ of the stacked residuals, packed lower triangle (see [`Accumulator`]).
    pub residual_corr: Vec<f64>,
}

impl EnsembleStats {
    /// Turns sums into statistics.
    pub fn from_sums(acc: &Accumulator, schedule: &FilterSchedule) -> Self {
        let n = acc.count as f64;
        let fixes = acc
            .fixes
            .iter()
            .zip(&schedule.fixes)
            .map(|(s, cov)| FixStats {
                time_s: cov.time_s,
                prior: stage_stats(&s.prior, &cov.p_prior, n),
                post: stage_stats(&s.post, &cov.p_post, n),
                nis_avg: s.nis / n,
            })
            .collect();
        Self {
            realizations: acc.count,
            fixes,
            residual_corr: acc.residual_products.iter().map(|x| x / n).collect(),
        }
    }

    /// (1/N) Σ r_a·r_b for stacked residual components a, b (component 2i is position at fix i,
    /// 2i + 1 velocity).
    pub fn residual_moment(&self, a: usize, b: usize) -> f64 {
        let (hi, lo) = if a >= b { (a, b) } else { (b, a) };
        self.residual_corr[packed_index(hi, lo)]
    }
}

fn to_rows(m: &Matrix3) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
}

fn stage_stats(s: &StageSums, p: &Matrix3, n: f64) -> StageStats {
    let mean_e = s.e / n;
    let mean_x = s.x / n;
    let ee = s.ee_matrix();
    let cov = (ee - mean_e * s.e.transpose()) / (n - 1.0);
    // (1/N) Σ (e − ē) x̂ᵀ = (1/N) Σ e x̂ᵀ − ē x̂̄ᵀ.
    let ortho = s.ex / n - mean_e * mean_x.transpose();
    let var_e = (ee / n - mean_e * mean_e.transpose()).diagonal();
    let var_x = s.xx / n - mean_x.component_mul(&mean_x);
    let corr = Matrix3::from_fn(|j, k| {
        let d = var_e[j] * var_x[k];
        // An estimate component that does not vary (e.g. the a priori estimate at a fix at t = 0)
        // has no correlation to speak of; relative tolerance because of rounding in the sums.
        if var_x[k] > 1e-24 * (s.xx[k] / n).max(f64::MIN_POSITIVE) && d > 0.0 {
            ortho[(j, k)] / d.sqrt()
        } else {
            f64::NAN
        }
    });
    StageStats {
        mean_error: mean_e.into(),
        ensemble_cov: to_rows(&cov),
        filter_cov: to_rows(p),
        orthogonality: to_rows(&ortho),
        orthogonality_corr: to_rows(&corr),
        nees_avg: s.nees / n,
    }
}

/// A finished ensemble: its statistics and how fast it ran.
#[derive(Clone, Debug)]
pub struct EnsembleRun {
    pub stats: EnsembleStats,
    /// Wall-clock time of the realizations, s.
    pub elapsed_s: f64,
}

impl EnsembleRun {
    /// Realizations per second.
    pub fn realizations_per_s(&self) -> f64 {
        self.stats.realizations as f64 / self.elapsed_s
    }
}

/// Runs the ensemble of `model` with its configured size and seed.
pub fn run_model(
    model: &Model,
    schedule: &FilterSchedule,
    progress: impl FnMut(u64),
) -> EnsembleRun {
    let e = &model.config.ensemble;
    let start = Instant::now();
    let acc = run(model, schedule, e.seed, e.realizations, progress);
    let elapsed_s = start.elapsed().as_secs_f64();
    EnsembleRun {
        stats: EnsembleStats::from_sums(&acc, schedule),
        elapsed_s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn small() -> (Model, FilterSchedule) {
        let mut c = Config::default();
        c.profile.duration_s = 2.0;
        let m = Model::new(&c).unwrap();
        let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
        (m, s)
    }

    #[test]
    fn merged_chunks_equal_one_pass_up_to_rounding() {
        let (m, s) = small();
        let whole = accumulate(&m, &s, 5, 0..300);
        let mut parts = accumulate(&m, &s, 5, 0..100);
        parts.merge(&accumulate(&m, &s, 5, 100..300));
        assert_eq!(whole.count, parts.count);
        for (a, b) in whole.residual_products.iter().zip(&parts.residual_products) {
            assert!((a - b).abs() <= 1e-9 * a.abs().max(1.0));
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
        for (a, b) in whole.fixes.iter().zip(&parts.fixes) {
            for (x, y) in [(&a.prior, &b.prior), (&a.post, &b.post)] {
                assert!(x.e.iter().zip(y.e.iter()).all(|(p, q)| close(*p, *q)));
                assert!(x.ee.iter().zip(&y.ee).all(|(p, q)| close(*p, *q)));
                assert!(x.ex.iter().zip(y.ex.iter()).all(|(p, q)| close(*p, *q)));
                assert!(x.xx.iter().zip(y.xx.iter()).all(|(p, q)| close(*p, *q)));
                assert!(close(x.nees, y.nees));
            }
            assert!(close(a.nis, b.nis));
        }
    }

    #[test]
    fn parallel_run_is_independent_of_the_thread_count() {
        let (m, s) = small();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let three = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let a = one.install(|| run(&m, &s, 9, 1000, |_| {}));
        let b = three.install(|| run(&m, &s, 9, 1000, |_| {}));
        assert_eq!(a, b);
    }

    #[test]
    fn streaming_moments_match_a_two_pass_computation() {
        struct Keep(Vec<FixState>);
        impl Observer for Keep {
            fn fix(&mut self, f: &FixState) {
                self.0.push(*f);
            }
        }
        let (m, s) = small();
        let n = 200u64;
        let stats = EnsembleStats::from_sums(&accumulate(&m, &s, 3, 0..n), &s);
        let runs: Vec<Vec<FixState>> = (0..n)
            .map(|l| {
                let mut k = Keep(Vec::new());
                run_realization(&m, &s, 3, l, &mut k);
                k.0
            })
            .collect();
        let i = 4;
        let errs: Vec<Vector3> = runs.iter().map(|r| r[i].delta_x - r[i].post).collect();
        let mean = errs.iter().sum::<Vector3>() / n as f64;
        let var_v = errs.iter().map(|e| (e[1] - mean[1]).powi(2)).sum::<f64>() / (n as f64 - 1.0);
        let got = &stats.fixes[i].post;
        approx::assert_relative_eq!(got.mean_error[1], mean[1], max_relative = 1e-9);
        approx::assert_relative_eq!(got.ensemble_cov[1][1], var_v, max_relative = 1e-9);
        // Orthogonality (1/N) Σ (e − ē) x̂ᵀ, entry (velocity error, bias estimate).
        let xs: Vec<Vector3> = runs.iter().map(|r| r[i].post).collect();
        let ortho = errs
            .iter()
            .zip(&xs)
            .map(|(e, x)| (e[1] - mean[1]) * x[2])
            .sum::<f64>()
            / n as f64;
        approx::assert_relative_eq!(got.orthogonality[1][2], ortho, max_relative = 1e-8);
        // NEES (1/N) Σ eᵀ P⁻¹ e with the filter's a posteriori P.
        let p_inv = s.fixes[i].p_post.try_inverse().unwrap();
        let nees = errs.iter().map(|e| e.dot(&(p_inv * e))).sum::<f64>() / n as f64;
        approx::assert_relative_eq!(got.nees_avg, nees, max_relative = 1e-8);
        let r = |l: usize, a: usize| runs[l][a / 2].residual[a % 2];
        let m12: f64 = (0..n as usize).map(|l| r(l, 7) * r(l, 2)).sum::<f64>() / n as f64;
        approx::assert_relative_eq!(stats.residual_moment(2, 7), m12, max_relative = 1e-9);
    }
}
