//! Exact draws of an ensemble's fix-level sums without simulating its realizations.
//!
//! In the model-exact world a realization's joint state z = (e, δx̂) is linear and Gaussian:
//! between fixes z ← F·z + G·w (the error takes the truth's process noise, the estimate is only
//! propagated), at a fix the innovation r = H·e + η moves δx̂ by K·r and e by −K·r. Every check
//! except the residual whiteness sees an ensemble of N realizations only through two statistics
//! per fix: the mean z̄ and the scatter S = Σ (z − z̄)(z − z̄)ᵀ. Both are Markov chains over the
//! fixes, independent of each other:
//!
//! - z̄ moves like one realization with its noise divided by √N;
//! - S starts Wishart(n, P(0)) with n = N − 1 and moves by a noncentral Wishart step: with any
//!   L such that L·Lᵀ = S, S ← (F·L + G·B)(F·L + G·B)ᵀ + G·W·Gᵀ, where B (r × d) has
//!   independent standard normal entries and W is Wishart(n − d, I_r).
//!
//! The step follows from writing the n centred realizations as L·Uᵀ with U orthonormal: the noise
//! splits into its projection on U (B) and the rest (W), independent by rotational invariance. One
//! draw of the sums of an ensemble of any size therefore costs about as much as one realization at
//! fix level, which makes the detection probability of a check, whose members are strongly
//! correlated across fixes, a matter of thousands of cheap draws.

use nalgebra::{SMatrix, SVector};
use rand_distr::{ChiSquared, Distribution};
use rayon::prelude::*;

use crate::checks::{self, Budget, CheckId};
use crate::ensemble::{Accumulator, EnsembleStats, ResidualLayout, StageSums};
use crate::filter::{ErrorStateModel, FilterSchedule};
use crate::model::{NoiseStats, Timeline};
use crate::random::Stream;
use crate::state::{ErrorState, MeasMatrix, StateMatrix};

/// States N of the error state e (and of the estimate δx̂).
const N: usize = ErrorState::DIM;
/// Measured components M.
const M: usize = ErrorState::MEAS;
/// Dimension of the joint state z = (e, δx̂).
const JOINT: usize = 2 * N;
/// Dimension of the joint state with the measurement noise at a fix, (z, η).
const WITH_NOISE: usize = JOINT + M;

/// A matrix of the joint state z: F, a scatter.
type JointMatrix = SMatrix<f64, JOINT, JOINT>;
/// A matrix of (z, η).
type WithNoiseMatrix = SMatrix<f64, WITH_NOISE, WITH_NOISE>;
/// A vector of the joint state z.
type JointVector = SVector<f64, JOINT>;

/// The transitions of one fix: the propagation from the previous fix and the update.
#[derive(Clone, Debug)]
struct FixStep {
    /// z ← F·z over the interval.
    f: JointMatrix,
    /// Noise loading over the interval: G·Gᵀ is the truth's accumulated process noise.
    g: SMatrix<f64, JOINT, N>,
    /// (z, η) ↦ z⁺ at the fix.
    update: SMatrix<f64, JOINT, WITH_NOISE>,
    /// (z, η) ↦ r at the fix.
    residual: SMatrix<f64, M, WITH_NOISE>,
    p_prior_inv: StateMatrix,
    p_post_inv: StateMatrix,
    s_inv: MeasMatrix,
}

/// Draws the sums of ensembles of the filter `schedule` in the world of `truth`.
#[derive(Clone, Debug)]
pub struct Sampler {
    realizations: u64,
    /// A square root of the truth's P(0).
    p0_root: StateMatrix,
    /// A square root of the truth's R.
    r_root: MeasMatrix,
    steps: Vec<FixStep>,
    layout: ResidualLayout,
    pair: [usize; 2],
}

impl Sampler {
    /// The fewest realizations the sampler draws for: the Bartlett factors of the propagation's
    /// Wishart(n − 1 − 2N, I_N) need n − 1 − 2N − (N − 1) ≥ 1 degrees of freedom, n ≥ 3N + 1.
    pub const MIN_REALIZATIONS: u64 = (JOINT + N + 1) as u64;

    /// The sampler of ensembles of `realizations` (at least [`Sampler::MIN_REALIZATIONS`]) of
    /// the filter `schedule` over `timeline`, in the model-exact world with the statistics
    /// `truth`. The residual products are kept at lag 0 only and the single pair `pair` is not
    /// drawn (its products are NaN).
    pub fn new(
        timeline: &Timeline,
        schedule: &FilterSchedule,
        truth: &NoiseStats,
        realizations: u64,
        pair: [usize; 2],
    ) -> Self {
        assert!(
            realizations >= Self::MIN_REALIZATIONS,
            "the sampler needs at least {} realizations",
            Self::MIN_REALIZATIONS
        );
        let world = ErrorStateModel::new(timeline.dt_s, truth);
        let h = schedule.model.h;
        // With the filter's Φ_f not the truth's Φ_t, e ← Φ_t·e + (Φ_t − Φ_f)·δx̂ + w: the joint
        // step A = [[Φ_t, Φ_t − Φ_f], [0, Φ_f]], composed over the interval.
        let same_phi = world.phi == schedule.model.phi;
        let mut step = JointMatrix::zeros();
        step.fixed_view_mut::<N, N>(0, 0).copy_from(&world.phi);
        step.fixed_view_mut::<N, N>(0, N)
            .copy_from(&(world.phi - schedule.model.phi));
        step.fixed_view_mut::<N, N>(N, N)
            .copy_from(&schedule.model.phi);
        let mut j = 0;
        let steps = timeline
            .fix_steps
            .iter()
            .zip(&schedule.fixes)
            .map(|(&jf, fix)| {
                let mut q = StateMatrix::zeros();
                let mut phi = StateMatrix::identity();
                let mut joint = JointMatrix::identity();
                while j < jf {
                    q = world.propagate(&q);
                    phi = world.phi * phi;
                    if !same_phi {
                        joint = step * joint;
                    }
                    j += 1;
                }
                // Rows and columns: e in 0..N, δx̂ in N..2N, η in 2N..2N + M.
                let mut f = JointMatrix::zeros();
                if same_phi {
                    f.fixed_view_mut::<N, N>(0, 0).copy_from(&phi);
                    f.fixed_view_mut::<N, N>(N, N).copy_from(&phi);
                } else {
                    f = joint;
                }
                let mut g = SMatrix::<f64, JOINT, N>::zeros();
                g.fixed_view_mut::<N, N>(0, 0).copy_from(&psd_cholesky(&q));
                let k = fix.gain;
                let kh = k * h;
                let mut update = SMatrix::<f64, JOINT, WITH_NOISE>::zeros();
                update
                    .fixed_view_mut::<N, N>(0, 0)
                    .copy_from(&(StateMatrix::identity() - kh));
                update.fixed_view_mut::<N, M>(0, JOINT).copy_from(&(-k));
                update.fixed_view_mut::<N, N>(N, 0).copy_from(&kh);
                update
                    .fixed_view_mut::<N, N>(N, N)
                    .copy_from(&StateMatrix::identity());
                update.fixed_view_mut::<N, M>(N, JOINT).copy_from(&k);
                let mut residual = SMatrix::<f64, M, WITH_NOISE>::zeros();
                residual.fixed_view_mut::<M, N>(0, 0).copy_from(&h);
                residual
                    .fixed_view_mut::<M, M>(0, JOINT)
                    .copy_from(&MeasMatrix::identity());
                FixStep {
                    f,
                    g,
                    update,
                    residual,
                    p_prior_inv: fix.p_prior_inv,
                    p_post_inv: fix.p_post_inv,
                    s_inv: fix.s_inv,
                }
            })
            .collect::<Vec<_>>();
        Self {
            realizations,
            p0_root: psd_cholesky(&world.p0),
            r_root: psd_cholesky(&world.r),
            layout: ResidualLayout::new(steps.len(), Some(0)),
            steps,
            pair,
        }
    }

    /// One draw of the sums of an ensemble, as [`crate::ensemble::Ensemble::sums`] would add them up, from
    /// the engines' generator `rng`: its ziggurat for the normal numbers, and `rand_distr`'s χ²
    /// on its bits for the Bartlett factors.
    pub fn draw(&self, rng: &mut Stream) -> Accumulator {
        let n_real = self.realizations as f64;
        let n = self.realizations - 1;
        let sqrt_n = n_real.sqrt();
        let mut acc: Accumulator = Accumulator::new(&self.layout, self.pair);
        acc.count = self.realizations;
        acc.pair_products.fill(f64::NAN);

        // Start: e ~ N(0, P(0)), δx̂ = 0.
        let mut scatter = JointMatrix::zeros();
        let w0 = wishart::<N>(n, rng);
        scatter
            .fixed_view_mut::<N, N>(0, 0)
            .copy_from(&(self.p0_root * w0 * self.p0_root.transpose()));
        let mut mean = JointVector::zeros();
        let e0: SVector<f64, N> = normals(rng);
        mean.fixed_rows_mut::<N>(0)
            .copy_from(&(self.p0_root * e0 / sqrt_n));

        for (i, step) in self.steps.iter().enumerate() {
            // Propagation to the fix.
            let l = psd_cholesky(&scatter);
            let b: SMatrix<f64, N, JOINT> = normals(rng);
            let a = step.f * l + step.g * b;
            let w = wishart::<N>(n - JOINT as u64, rng);
            scatter = symmetric(a * a.transpose() + step.g * w * step.g.transpose());
            let noise: SVector<f64, N> = normals(rng);
            mean = step.f * mean + step.g * noise / sqrt_n;
            let prior = stage_sums(&scatter, &mean, n_real, &step.p_prior_inv);

            // The joint (z, η) at the fix.
            let l = psd_cholesky(&scatter);
            let b: SMatrix<f64, M, JOINT> = normals(rng);
            let mut a = SMatrix::<f64, WITH_NOISE, JOINT>::zeros();
            a.fixed_view_mut::<JOINT, JOINT>(0, 0).copy_from(&l);
            a.fixed_view_mut::<M, JOINT>(JOINT, 0)
                .copy_from(&(self.r_root * b));
            let w = wishart::<M>(n - JOINT as u64, rng);
            let mut joint: WithNoiseMatrix = a * a.transpose();
            let wr = self.r_root * w * self.r_root.transpose();
            for x in 0..M {
                for y in 0..M {
                    joint[(JOINT + x, JOINT + y)] += wr[(x, y)];
                }
            }
            let joint = symmetric(joint);
            let eta: SVector<f64, M> = normals(rng);
            let mut joint_mean = SVector::<f64, WITH_NOISE>::zeros();
            joint_mean.fixed_rows_mut::<JOINT>(0).copy_from(&mean);
            joint_mean
                .fixed_rows_mut::<M>(JOINT)
                .copy_from(&(self.r_root * eta / sqrt_n));

            let r_scatter = step.residual * joint * step.residual.transpose();
            let r_mean = step.residual * joint_mean;
            let rr = r_scatter + r_mean * r_mean.transpose() * n_real;
            scatter = symmetric(step.update * joint * step.update.transpose());
            mean = step.update * joint_mean;
            let post = stage_sums(&scatter, &mean, n_real, &step.p_post_inv);

            let sums = &mut acc.fixes[i];
            sums.prior = prior;
            sums.post = post;
            sums.nis = (step.s_inv * rr).trace();
            // The lower triangle of r·rᵀ at lag 0: components M·i + x and M·i + y, y ≤ x.
            for x in 0..M {
                for y in 0..=x {
                    let k = self
                        .layout
                        .index(M * i + x, M * i + y)
                        .expect("lag 0 is kept");
                    acc.residual_products[k] = rr[(x, y)];
                }
            }
        }
        acc
    }
}

impl Sampler {
    /// The fraction of `draws` ensembles in which each check fails within `budget`, in
    /// [`CheckId::ALL`] order; `None` for the residual whiteness, whose products across fixes the
    /// fix-level sums do not carry. Draw k has its own generator, stream k of those keyed by
    /// `seed` (as a realization's is in the engines), so the fractions do not depend on the
    /// thread count.
    pub fn detection(
        &self,
        schedule: &FilterSchedule,
        budget: &Budget,
        draws: u64,
        seed: u64,
    ) -> Vec<Option<f64>> {
        let stats = |k: u64| {
            let mut rng = Stream::new(seed, k);
            EnsembleStats::from_sums(&self.draw(&mut rng), schedule)
        };
        // The bands depend only on N and the members: judged once, reused for every draw.
        let reference = checks::evaluate(&stats(0), budget).checks;
        let failed = (0..draws)
            .into_par_iter()
            .map(|k| {
                let s = stats(k);
                reference
                    .iter()
                    .map(|c| u64::from(checks::fails_again(c, &s)))
                    .collect::<Vec<_>>()
            })
            .reduce(
                || vec![0; reference.len()],
                |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect(),
            );
        CheckId::ALL
            .iter()
            .zip(failed)
            .map(|(&id, f)| {
                (id != CheckId::RESIDUAL_WHITENESS && draws > 0).then(|| f as f64 / draws as f64)
            })
            .collect()
    }
}

/// The raw sums Σ e, Σ e·eᵀ, … of one stage from the scatter and the mean of z = (e, δx̂).
fn stage_sums(scatter: &JointMatrix, mean: &JointVector, n: f64, p_inv: &StateMatrix) -> StageSums {
    let raw = scatter + mean * mean.transpose() * n;
    // Σ e·eᵀ from its upper triangle, exactly symmetric.
    let ee = StateMatrix::from_fn(|r, c| raw[(r.min(c), r.max(c))]);
    StageSums {
        e: mean.fixed_rows::<N>(0) * n,
        ee,
        ex: raw.fixed_view::<N, N>(0, N).into_owned(),
        x: mean.fixed_rows::<N>(N) * n,
        xx: raw.fixed_view::<N, N>(N, N).diagonal(),
        nees: (p_inv * ee).trace(),
    }
}

/// A matrix of independent standard normal draws.
fn normals<const R: usize, const C: usize>(rng: &mut Stream) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|_, _| rng.normal())
}

/// A Wishart(ν, I_D) draw by the Bartlett decomposition T·Tᵀ, T lower triangular with
/// T_kk² ~ χ²(ν − k) and standard normal entries below the diagonal.
fn wishart<const D: usize>(nu: u64, rng: &mut Stream) -> SMatrix<f64, D, D> {
    let mut t = SMatrix::<f64, D, D>::zeros();
    for k in 0..D {
        let chi = ChiSquared::new((nu - k as u64) as f64).expect("positive degrees of freedom");
        t[(k, k)] = chi.sample(rng).sqrt();
        for c in 0..k {
            t[(k, c)] = rng.normal();
        }
    }
    t * t.transpose()
}

/// A lower-triangular L with L·Lᵀ = S for a positive semi-definite S: a Cholesky factorization
/// that leaves a column at zero where the pivot has vanished (to rounding, relative to the
/// diagonal), as the scatter of an estimate that has not moved yet needs.
fn psd_cholesky<const D: usize>(s: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    let mut l = SMatrix::<f64, D, D>::zeros();
    for j in 0..D {
        let mut d = s[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        if d <= 1e-12 * s[(j, j)].abs() || d <= 0.0 {
            continue;
        }
        let d = d.sqrt();
        l[(j, j)] = d;
        for i in j + 1..D {
            let mut v = s[(i, j)];
            for k in 0..j {
                v -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = v / d;
        }
    }
    l
}

fn symmetric<const D: usize>(m: SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    (m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn semi_definite_cholesky_reproduces_its_matrix() {
        let v = SMatrix::<f64, 4, 2>::new(1.0, 0.0, 2.0, 1.0, 0.0, 3.0, 1.0, 1.0);
        let s = v * v.transpose(); // rank 2
        let l = psd_cholesky(&s);
        assert!((l * l.transpose() - s).abs().max() < 1e-12);
        let spd = s + SMatrix::<f64, 4, 4>::identity();
        let l = psd_cholesky(&spd);
        assert!((l - spd.cholesky().expect("definite").l()).abs().max() < 1e-12);
    }
}
