//! The forward pass over a log: the accelerometer integrated by eq. (3) and the error-state
//! filter, one sample at a time, with the step of each pair of time stamps. A fix between two
//! samples cuts the filter's step in two: Φ and Q of the fraction up to the fix, the update
//! there, then Φ and Q of the rest of the step; the integration at the samples runs whole steps,
//! and the fix's (p_c, v_c) is the sample's carried over the fraction by eq. (3).

use crate::error::FilterError;
use crate::filter::{ErrorStateModel, propagate_over};
use crate::input::csv::GpsFix;
use crate::simulation::measurement;
use crate::state::step::Euler;
use crate::state::{ErrorState, MeasMatrix, MeasVector, StateMatrix, StateModel, StateVector};

// `Forward::transition_to` inverts the error state's Φ in closed form, entry by entry: a new
// state needs its row and column of the inverse there.
const _: () = assert!(
    ErrorState::DIM == 3,
    "calibrate/forward.rs: add the new state to Forward::transition_to's closed-form inverse"
);

use super::StepMode;
use super::integration::Integrated;
use super::symmetric::Symmetric;

/// What the filter did at one GPS fix: everything the smoother and the report need.
#[derive(Clone, Debug, PartialEq)]
pub struct FilteredFix {
    /// Line of the fix in the GPS log.
    pub line: u64,
    /// Accelerometer sample whose step holds the fix (0 = the log's first).
    pub sample: u64,
    /// Time of the update, s: the fix's own (the end sample's for a fix beyond an end).
    pub t_s: f64,
    /// The fix z = (z_p, z_v), (m, m/s).
    pub z: MeasVector,
    /// Integrated accelerometer (p_c, v_c) at the fix, (m, m/s).
    pub integrated: MeasVector,
    /// A priori estimate δx̂⁻.
    pub prior: StateVector,
    /// A posteriori estimate δx̂⁺.
    pub post: StateVector,
    /// Residual r = δz − H·δx̂⁻, (m, m/s).
    pub residual: MeasVector,
    /// Innovation covariance S = H·P⁻·Hᵀ + R.
    pub s: MeasMatrix,
    /// Normalized innovation squared rᵀ·S⁻¹·r.
    pub nis: f64,
    /// A priori covariance P⁻.
    pub p_prior: Symmetric,
    /// A posteriori covariance P⁺.
    pub p_post: Symmetric,
    /// Transition of the estimate from the previous fix (or the log's first sample).
    pub phi_from_previous: StateMatrix,
}

impl FilteredFix {
    /// The measurement update of the fix `gps` applied at accelerometer sample `sample`, time
    /// `t_s`, where the accelerometer integrates to `integrated` = (p_c, v_c): the a priori
    /// estimate `prior` with covariance `p` (before the update) reached by `phi` from the
    /// previous fix. The one update both the fix-to-fix filter and the per-sample recursion run.
    ///
    /// # Errors
    /// [`FilterError`] when a covariance is not positive definite.
    pub fn update(
        model: &ErrorStateModel,
        gps: &GpsFix,
        (sample, t_s): (u64, f64),
        integrated: MeasVector,
        (prior, p, phi): (StateVector, &StateMatrix, StateMatrix),
    ) -> Result<Self, FilterError> {
        let cov = model.update_covariance(p, t_s, phi)?;
        let z = measurement(gps.position_m, gps.velocity_m_s);
        // eq. (6): δz = z − (p_c, v_c).
        let dz = z - integrated;
        let (post, residual) = model.update_estimate(&cov, &prior, &dz);
        Ok(FilteredFix {
            line: gps.line,
            sample,
            t_s,
            z,
            integrated,
            prior,
            post,
            residual,
            s: cov.s,
            nis: (residual.transpose() * cov.s_inv * residual)[0],
            p_prior: Symmetric::of(&cov.p_prior),
            p_post: Symmetric::of(&cov.p_post),
            phi_from_previous: phi,
        })
    }

    /// Whether every number the smoother and the report take from the fix is finite.
    pub fn is_finite(&self) -> bool {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        self.nis.is_finite()
            && finite(self.integrated.as_slice())
            && finite(self.residual.as_slice())
            && finite(self.s.as_slice())
            && finite(self.prior.as_slice())
            && finite(self.post.as_slice())
            && finite(self.p_prior.entries())
            && finite(self.p_post.entries())
            && finite(self.p_prior_inv().as_slice())
    }

    /// (P⁻)⁻¹ by Cholesky, as the update formed it ([`ErrorStateModel::update_covariance`]):
    /// not kept, at 72 bytes a fix.
    pub fn p_prior_inv(&self) -> StateMatrix {
        self.p_prior
            .matrix()
            .cholesky()
            .expect("the update checked P⁻ positive definite")
            .inverse()
    }
}

/// The integration and the filter at the current sample.
pub struct Forward<'m> {
    model: &'m ErrorStateModel,
    /// The error state the filter assumes, for steps of their own length.
    state: ErrorState,
    mode: StepMode,
    /// The nominal step of eq. (3), as the simulation's, so that the bits agree.
    nominal: Euler,
    /// Index of the current sample.
    pub k: u64,
    /// Its time stamp, s.
    pub t_s: f64,
    /// The time the estimate refers to: the sample's, or a fix's after an update between
    /// samples, s.
    filter_t_s: f64,
    /// Integrated position p_c, m.
    pub pc_m: f64,
    /// Integrated velocity v_c, m/s.
    pub vc_m_s: f64,
    /// Estimate δx̂ (a posteriori at a fix).
    pub x: StateVector,
    /// Its covariance P.
    pub p: StateMatrix,
    /// Sample, time and a posteriori estimate of the last fix (the start before any).
    last_fix: (u64, f64, StateVector),
    /// Whether the filter's Φ composes over an interval ([`StateModel::transition_composes`]).
    composes: bool,
    /// Π Φ(Δt_j) over the steps since the last fix, when Φ does not compose (I otherwise).
    phi_since_fix: StateMatrix,
}

impl<'m> Forward<'m> {
    /// The start of the log at `t0_s`: eq. (3) from `start`, δx̂ = 0, P = P(0).
    pub fn new(
        model: &'m ErrorStateModel,
        state: ErrorState,
        mode: StepMode,
        start: Integrated,
        t0_s: f64,
    ) -> Self {
        Self {
            model,
            state,
            mode,
            nominal: Euler::new(model.dt_s),
            k: 0,
            t_s: t0_s,
            filter_t_s: t0_s,
            pc_m: start.pc_m,
            vc_m_s: start.vc_m_s,
            x: StateVector::zeros(),
            p: model.p0,
            last_fix: (0, t0_s, StateVector::zeros()),
            composes: state.transition_composes(),
            phi_since_fix: StateMatrix::identity(),
        }
    }

    /// Integrates the output `accel_m_s2` of the current sample up to the next one at
    /// `t_next_s`, and propagates the estimate and its covariance over the step.
    pub fn advance(&mut self, accel_m_s2: f64, t_next_s: f64) {
        let a = accel_m_s2;
        match self.mode {
            StepMode::Nominal => {
                // The simulation's recursion, operation for operation.
                (self.pc_m, self.vc_m_s) = self.nominal.step((self.pc_m, self.vc_m_s), a);
                self.x = self.model.phi * self.x;
                self.p = self.model.propagate(&self.p);
                if !self.composes {
                    // The in-memory filter's product of the steps (`FilterSchedule::of`).
                    self.phi_since_fix = self.model.phi * self.phi_since_fix;
                }
            }
            StepMode::PerStep => {
                let dt = t_next_s - self.t_s;
                // eq. (3) with this step's Δt_j; Φ(Δt_j) and Q(Δt_j) for eq. (5), from the last
                // fix when one cut the step.
                (self.pc_m, self.vc_m_s) = Euler::new(dt).step((self.pc_m, self.vc_m_s), a);
                // The rest of a step a fix cut is a piece of it.
                let cut = (self.filter_t_s != self.t_s).then_some(dt);
                self.propagate_to(t_next_s, cut);
            }
        }
        self.k += 1;
        self.t_s = t_next_s;
        self.filter_t_s = t_next_s;
    }

    /// The estimate and its covariance carried from their time to `t_s` (per-step mode): a
    /// whole step, or a piece of the step of `cut` = Some(Δt_j) that a fix cuts, whose white
    /// noise is taken as white within the step ([`ErrorState::piece_noise`]).
    fn propagate_to(&mut self, t_s: f64, cut: Option<f64>) {
        let tau = t_s - self.filter_t_s;
        let phi = self.state.transition(self.filter_t_s, tau);
        self.x = phi * self.x;
        self.p = match cut {
            None => propagate_over(&self.state, &self.p, self.filter_t_s, tau),
            Some(step_s) => {
                let q = self.state.piece_noise(self.filter_t_s, tau, step_s);
                let p = phi * self.p * phi.transpose() + q;
                (p + p.transpose()) * 0.5
            }
        };
        if !self.composes {
            self.phi_since_fix = phi * self.phi_since_fix;
        }
        self.filter_t_s = t_s;
    }

    /// Whether the time stamp, the integration, the estimate and its covariance are finite.
    pub fn is_finite(&self) -> bool {
        [self.t_s, self.pc_m, self.vc_m_s]
            .iter()
            .chain(self.x.iter())
            .chain(self.p.iter())
            .all(|v| v.is_finite())
    }

    /// Transition Φ from the current sample to the sample of the next fix `next`.
    ///
    /// # Formula
    /// When Φ composes, Φ(t_b − t_k) (n·Δt in nominal mode). Otherwise (a Gauss–Markov bias)
    /// Φ(b←k) = Φ(b←a)·Φ(k←a)⁻¹ from the fix's transition since the previous fix a and the
    /// product of the steps from a to k, with the closed-form inverse of
    /// M = [[1, T, c_p], [0, 1, c_v], [0, 0, φ]]:
    /// M⁻¹ = [[1, −T, (T·c_v − c_p)/φ], [0, 1, −c_v/φ], [0, 0, 1/φ]]. Its bias column is a
    /// difference of terms of size |c|/φ(k←a): relative rounding ε·e^((t_k − t_a)/τ_b), small
    /// while the GPS interval is not many τ_b.
    pub fn transition_to(&self, next: &FilteredFix) -> StateMatrix {
        if self.composes {
            return match self.mode {
                StepMode::Nominal => self
                    .state
                    .transition(0.0, (next.sample - self.k) as f64 * self.model.dt_s),
                StepMode::PerStep => self
                    .state
                    .transition(self.filter_t_s, next.t_s - self.filter_t_s),
            };
        }
        let (p, v, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
        let m = &self.phi_since_fix;
        let (t, c_p, c_v, phi) = (m[(p, v)], m[(p, b)], m[(v, b)], m[(b, b)]);
        let mut inverse = StateMatrix::identity();
        inverse[(p, v)] = -t;
        inverse[(p, b)] = (t * c_v - c_p) / phi;
        inverse[(v, b)] = -c_v / phi;
        inverse[(b, b)] = 1.0 / phi;
        next.phi_from_previous * inverse
    }

    /// The measurement update with `fix` at the current sample.
    ///
    /// # Errors
    /// [`FilterError`] when a covariance is not positive definite.
    pub fn update(&mut self, fix: &GpsFix) -> Result<FilteredFix, FilterError> {
        let integrated = measurement(self.pc_m, self.vc_m_s);
        self.update_at(fix, self.t_s, integrated)
    }

    /// The measurement update with `fix` at `t_fix_s`, inside the step of `step_s` from the
    /// current sample whose output is `accel_m_s2` (per-step mode): the filter propagated over
    /// the piece of the step up to the fix, the integration carried there by eq. (3).
    ///
    /// # Errors
    /// [`FilterError`] when a covariance is not positive definite.
    pub fn update_within(
        &mut self,
        fix: &GpsFix,
        accel_m_s2: f64,
        (t_fix_s, step_s): (f64, f64),
    ) -> Result<FilteredFix, FilterError> {
        self.propagate_to(t_fix_s, Some(step_s));
        let at_sample = Integrated {
            pc_m: self.pc_m,
            vc_m_s: self.vc_m_s,
        };
        let i = at_sample.advanced(accel_m_s2, t_fix_s - self.t_s);
        self.update_at(fix, t_fix_s, measurement(i.pc_m, i.vc_m_s))
    }

    /// The update at `t_s` (the filter's time), where the accelerometer integrates to
    /// `integrated`.
    fn update_at(
        &mut self,
        fix: &GpsFix,
        t_s: f64,
        integrated: MeasVector,
    ) -> Result<FilteredFix, FilterError> {
        let (k0, t0, post0) = self.last_fix;
        let (phi, prior) = match self.mode {
            // As the in-memory filter: one transition over the whole interval since the last fix
            // (the product of the steps when Φ does not compose).
            StepMode::Nominal => {
                let phi = if self.composes {
                    self.state
                        .transition(0.0, (self.k - k0) as f64 * self.model.dt_s)
                } else {
                    self.phi_since_fix
                };
                (phi, phi * post0)
            }
            StepMode::PerStep if self.composes => (self.state.transition(t0, t_s - t0), self.x),
            StepMode::PerStep => (self.phi_since_fix, self.x),
        };
        self.phi_since_fix = StateMatrix::identity();
        let at = (self.k, t_s);
        let fixed = FilteredFix::update(self.model, fix, at, integrated, (prior, &self.p, phi))?;
        self.x = fixed.post;
        self.p = fixed.p_post.matrix();
        self.last_fix = (self.k, t_s, fixed.post);
        Ok(fixed)
    }
}
