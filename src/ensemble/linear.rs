//! The model-exact engine: realizations of any [`StateModel`] drawn from its own linear Gaussian
//! system, accelerometer step by step, and filtered by a [`FilterSchedule`] of the same sizes.
//!
//! The truth is the model itself: x(0) ~ N(0, P(0)), x(t_{j+1}) = Φ(t_j, Δt)·x(t_j) + w_j with
//! w_j ~ N(0, Q(t_j, Δt)), and a fix measures δz = H·x + η, η ~ N(0, R), all with the truth's
//! statistics. A filter whose model is the truth's is then exactly consistent, so every check must
//! pass; that makes this engine the test bed of a new state before it has a physical truth, and
//! the reference the accelerometer's own engines are compared with in law.
//!
//! The realizations are summed in blocks of [`BLOCK`] consecutive indices, each from its own
//! random stream, and the blocks are added in index order: the sums do not depend on the thread
//! count.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use super::layout::ResidualLayout;
use super::sums::Accumulator;
use crate::filter::FilterSchedule;
use crate::model::Timeline;
use crate::random::{Stream, splitmix64};
use crate::state::StateModel;

/// Realizations summed sequentially before their block is added to the total.
pub const BLOCK: u64 = 256;

/// What to run: the ensemble's size and random streams, and which residual products to keep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinearRun {
    /// Realizations N.
    pub realizations: u64,
    /// Seed of the random streams: realization l draws from stream l of the seed's key.
    pub seed: u64,
    /// Largest lag of the residual products kept (`None`: every pair).
    pub max_lag: Option<usize>,
    /// The fix indices [m, i], m < i, of the single residual pair kept whatever the lag.
    pub pair: [usize; 2],
}

/// One accelerometer step of the truth: x ← Φ·x + L·n, L·Lᵀ = Q, n standard normal.
#[derive(Clone, Copy, Debug)]
struct Step<const N: usize> {
    phi: SMatrix<f64, N, N>,
    noise_root: SMatrix<f64, N, N>,
}

/// The truth's steps and roots, computed once for every realization.
struct Truth<const N: usize, const M: usize> {
    /// One step per sample, or a single one when the model does not depend on time.
    steps: Vec<Step<N>>,
    p0_root: SMatrix<f64, N, N>,
    r_root: SMatrix<f64, M, M>,
    h: SMatrix<f64, M, N>,
}

impl<const N: usize, const M: usize> Truth<N, M> {
    fn new<S: StateModel<N, M>>(truth: &S, timeline: &Timeline) -> Self {
        let step = |j: usize| {
            let t = timeline.time_s(j);
            Step {
                phi: truth.transition(t, timeline.dt_s),
                noise_root: psd_root(&truth.process_noise(t, timeline.dt_s)),
            }
        };
        let count = if S::TIME_INVARIANT { 1 } else { timeline.steps };
        Self {
            steps: (0..count).map(step).collect(),
            p0_root: psd_root(&truth.initial_covariance()),
            r_root: psd_root(&truth.measurement_noise()),
            h: truth.observation(),
        }
    }

    fn step(&self, j: usize) -> &Step<N> {
        &self.steps[j.min(self.steps.len() - 1)]
    }
}

/// Runs `run.realizations` realizations of the truth `truth` on `timeline`, filtered by
/// `schedule`, and returns their sums.
pub fn run<S: StateModel<N, M> + Sync, const N: usize, const M: usize>(
    truth: &S,
    schedule: &FilterSchedule<N, M>,
    timeline: &Timeline,
    run: &LinearRun,
) -> Accumulator<N, M> {
    let layout = ResidualLayout::with_width(timeline.fixes(), M, run.max_lag);
    let world = Truth::new(truth, timeline);
    let key = splitmix64(run.seed ^ 0x11AE_A5E7_0F5E_ED00);
    let blocks = run.realizations.div_ceil(BLOCK);
    let sums: Vec<Accumulator<N, M>> = (0..blocks)
        .into_par_iter()
        .map(|b| {
            let mut acc = Accumulator::new(&layout, run.pair);
            let end = ((b + 1) * BLOCK).min(run.realizations);
            let mut rho = vec![0.0; M * timeline.fixes()];
            for l in b * BLOCK..end {
                realization(
                    &world,
                    schedule,
                    timeline,
                    Stream::new(key, l),
                    &mut acc,
                    &mut rho,
                );
            }
            acc
        })
        .collect();
    let mut total = Accumulator::new(&layout, run.pair);
    for s in &sums {
        total.merge(s);
    }
    total
}

/// One realization added to `acc`; `rho` receives its stacked residuals.
fn realization<const N: usize, const M: usize>(
    world: &Truth<N, M>,
    schedule: &FilterSchedule<N, M>,
    timeline: &Timeline,
    mut stream: Stream,
    acc: &mut Accumulator<N, M>,
    rho: &mut [f64],
) {
    let mut x = world.p0_root * normals::<N>(&mut stream);
    let mut estimate = SVector::<f64, N>::zeros();
    let mut j = 0;
    for (i, fix) in schedule.fixes.iter().enumerate() {
        while j < timeline.fix_steps[i] {
            let step = world.step(j);
            x = step.phi * x + step.noise_root * normals::<N>(&mut stream);
            j += 1;
        }
        let dz = world.h * x + world.r_root * normals::<M>(&mut stream);
        let prior = fix.phi_from_previous * estimate;
        let (post, residual) = schedule.model.update_estimate(fix, &prior, &dz);
        let sums = &mut acc.fixes[i];
        sums.prior.add(&(x - prior), &prior, &fix.p_prior_inv);
        sums.post.add(&(x - post), &post, &fix.p_post_inv);
        sums.nis += (residual.transpose() * fix.s_inv * residual)[0];
        rho[M * i..M * (i + 1)].copy_from_slice(residual.as_slice());
        estimate = post;
    }
    add_products(acc, rho);
    acc.count += 1;
}

/// A vector of independent standard normal numbers.
fn normals<const D: usize>(stream: &mut Stream) -> SVector<f64, D> {
    SVector::from_fn(|_, _| stream.normal())
}

/// Adds the kept products ρ_a·ρ_b of one realization's stacked residuals, and its single pair.
fn add_products<const N: usize, const M: usize>(acc: &mut Accumulator<N, M>, rho: &[f64]) {
    let layout = &acc.layout;
    for (a, &ra) in rho.iter().enumerate() {
        let first = layout.first_col(a);
        let start = layout.row_start(a);
        for (k, &rb) in rho[first..=a].iter().enumerate() {
            acc.residual_products[start + k] += ra * rb;
        }
    }
    let [m, i] = acc.pair;
    for j in 0..M {
        for k in 0..M {
            acc.pair_products[(j, k)] += rho[M * i + j] * rho[M * m + k];
        }
    }
}

/// A square root L·Lᵀ = A of a symmetric positive semi-definite matrix: Cholesky, with a column
/// of zeros where a pivot vanishes (a state without noise of its own, e.g. a constant bias in Q).
pub(super) fn psd_root<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let scale = a.diagonal().amax();
    let mut l = SMatrix::<f64, N, N>::zeros();
    for c in 0..N {
        let pivot = a[(c, c)] - (0..c).map(|k| l[(c, k)] * l[(c, k)]).sum::<f64>();
        if pivot <= 1e-14 * scale {
            continue;
        }
        let d = pivot.sqrt();
        l[(c, c)] = d;
        for r in c + 1..N {
            let dot: f64 = (0..c).map(|k| l[(r, k)] * l[(c, k)]).sum();
            l[(r, c)] = (a[(r, c)] - dot) / d;
        }
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_of_a_singular_covariance_reproduces_it() {
        // Rank one, as the error state's Q: Γ·Γᵀ with Γ = (−τ²/2, −τ, 0).
        let g = SVector::<f64, 3>::new(-0.5e-4, -0.01, 0.0);
        let q = g * g.transpose() * 4e-4;
        let l = psd_root(&q);
        assert!((l * l.transpose() - q).norm() <= 1e-15 * q.norm());
        let p = SMatrix::<f64, 3, 3>::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let l = psd_root(&p);
        assert!((l * l.transpose() - p).norm() <= 1e-14 * p.norm());
    }
}
