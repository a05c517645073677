//! The likelihood of the GNSS innovations linearized about one run of the filter: the run's
//! nominal trajectory held, the error state's linear model between fixes (Φ, Q_d by noise group,
//! H, the corrections the run applied) kept, and the Kalman recursion over the fixes alone
//! evaluated at any noise statistics (Mehra, IEEE Trans. Automatic Control 15(2), 1970: the
//! innovations' Gaussian likelihood of a linear model; Maybeck, Stochastic Models, Estimation
//! and Control vol. 2 §10.3: the same with the model linearized about a nominal).
//!
//! With e the error of the run's solution (estimate minus truth), e⁻ₖ = Φₖ(e⁺ₖ₋₁) + wₖ and the
//! run's correction Δₖ leaving e⁺ₖ = e⁻ₖ − Δₖ; the innovation against the run's solution is
//! yₖ = Hₖe⁻ₖ + vₖ. A Kalman filter of this model with mean m: m⁻ₖ = Φₖ(m⁺ₖ₋₁ − Δₖ₋₁),
//! νₖ = yₖ − Hₖm⁻ₖ, Sₖ = HₖP⁻ₖHₖᵀ + Rₖ(θ), P⁻ₖ = ΦₖP⁺ₖ₋₁Φₖᵀ + Σ_g d_g(θ)·Q_g,ₖ, P(0) from the
//! alignment at θ. At the run's own θ it reproduces the run's innovations and S exactly (m stays
//! 0); elsewhere it is the filter the run would be had its solution been the same. The
//! receiver's time offset δ moves each fix by ε = δ − δ_run along the run's solution: the
//! predicted velocity by Δv = C·(∫f dt − b̂_a·ε) + (γ − (2Ω_ie + Ω_en)×v)·ε with the specific
//! force integrated over the IMU steps between the two times (shared in proportion, as the run
//! cuts a step at a fix; divided by 1 + ŝ_a per axis with the scale factors), the position by
//! v·ε + Δv·ε/2. Each evaluation costs O(fixes) 15×15 products (21×21 with the scale factors)
//! instead of a run over every IMU step.

use nalgebra::{SMatrix, SVector, Vector3};

use super::Settings;
use super::align;
use super::run::{ImuCalibrateError, alignment_sources, filter_tracked, shifted};
use super::step::{fix_of, initial_covariance, noise};
use crate::input::imu_csv::HeldSteps;
use crate::input::records::{GnssRow, ImuStep};
use crate::ins::discrete::transition_congruence;
use crate::ins::error_state::{ATTITUDE, STATES, Square};
use crate::ins::filter::{LinearView, NOISE_GROUPS};

/// One fix of the linearized model.
#[derive(Clone, Debug)]
struct LinearFix<const N: usize> {
    /// The fix as the run read it (its σ's where the log has them, what it measures; its time
    /// moved by the run's offset).
    row: GnssRow,
    /// The first IMU step that ends at or after the fix.
    step: usize,
    /// Φ from the previous fix (or the start).
    transition: Square<N>,
    /// Q_d from the previous fix by noise group at unit density.
    noise_parts: [Square<N>; NOISE_GROUPS],
    /// H and the motion at the run's solution.
    view: LinearView<N>,
    /// The run's innovation (NaN where not measured).
    innovation: [f64; 6],
    /// The errors the run's update took out of its solution.
    correction: SVector<f64, N>,
}

/// The likelihood of a drive linearized about one run of the filter.
#[derive(Clone, Debug)]
pub struct Linearized<'a, const N: usize = STATES> {
    /// The IMU steps.
    steps: &'a [ImuStep],
    /// The assumptions of the run.
    pub reference: Settings,
    /// The alignment's fix (the filter's start) among the GNSS rows.
    pub start: usize,
    /// The alignment's first fix and its heading fix.
    fixes_of_alignment: (GnssRow, GnssRow),
    /// The mean specific force over the alignment's window.
    mean_f_b: Vector3<f64>,
    /// One per fix after the start.
    fixes: Vec<LinearFix<N>>,
    /// The filter's view at its start and the first IMU step ending at or after it.
    start_view: (LinearView<N>, usize),
    /// The first IMU step ending at or after the alignment's first fix.
    first_step: usize,
}

impl<'a, const N: usize> Linearized<'a, N> {
    /// The model about the run of the filter over `steps` and the fixes `rows` (as read) with
    /// the assumptions `s`.
    ///
    /// # Errors
    /// As the filter's run.
    pub fn new(
        rows: &[GnssRow],
        steps: &'a [ImuStep],
        s: &Settings,
    ) -> Result<Self, ImuCalibrateError> {
        let rows = shifted(rows, s.gnss_time_offset_s);
        let run = filter_tracked::<N>(&rows, &mut HeldSteps::new(steps), s, "")?;
        let start = run.plan.start;
        let fixes = run
            .records
            .into_iter()
            .zip(&rows[start + 1..])
            .map(|(r, row)| {
                let linear = r.linear.expect("a tracked run records the linear model");
                LinearFix {
                    row: *row,
                    step: steps.partition_point(|st| st.t_s < row.t_s),
                    transition: r.transition,
                    noise_parts: linear.noise_parts,
                    view: linear.view,
                    innovation: r.innovation,
                    correction: r.correction,
                }
            })
            .collect();
        Ok(Linearized {
            steps,
            reference: *s,
            start,
            fixes_of_alignment: (rows[run.plan.first], rows[start]),
            mean_f_b: run.mean_f_b,
            fixes,
            first_step: steps.partition_point(|st| st.t_s < rows[run.plan.first].t_s),
            start_view: (
                run.start_view.expect("a tracked run records its start"),
                steps.partition_point(|st| st.t_s < rows[start].t_s),
            ),
        })
    }

    /// The fixes the model holds.
    pub fn len(&self) -> usize {
        self.fixes.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.fixes.is_empty()
    }

    /// ℓ(θ) = −½ Σₖ (mₖ ln 2π + ln det Sₖ + νₖᵀSₖ⁻¹νₖ) over the first `fixes` fixes with the
    /// assumptions `t`; −∞ when a covariance is not positive definite or the model holds fewer.
    pub fn log_likelihood(&self, t: &Settings, fixes: usize) -> f64 {
        self.recursion(t, fixes, |_, _| {})
    }

    /// The innovations (position NED m, velocity NED m/s; 0 where not measured) of the first
    /// `fixes` fixes with the assumptions `t`.
    pub fn innovations(&self, t: &Settings, fixes: usize) -> Vec<[f64; 6]> {
        let mut out = Vec::with_capacity(fixes);
        self.recursion(t, fixes, |_, y| out.push(*y));
        out
    }

    /// The recursion over the first `fixes` fixes, calling `seen` with each fix's index and
    /// innovation; ℓ.
    fn recursion(&self, t: &Settings, fixes: usize, mut seen: impl FnMut(usize, &[f64; 6])) -> f64 {
        if self.fixes.len() < fixes {
            return f64::NEG_INFINITY;
        }
        let (first, heading) = &self.fixes_of_alignment;
        let shift = t.gnss_time_offset_s - self.reference.gnss_time_offset_s;
        let (view, step) = &self.start_view;
        // A later window gives the alignment another mean specific force.
        let mean_f_b = if shift == 0.0 {
            self.mean_f_b
        } else {
            let window = heading.t_s - first.t_s;
            let end = specific_force_integral(self.steps, *step, heading.t_s, heading.t_s + shift);
            let begin =
                specific_force_integral(self.steps, self.first_step, first.t_s, first.t_s + shift);
            self.mean_f_b + (end - begin) / window
        };
        let a = align::align(first, heading, &mean_f_b, &alignment_sources(heading, t));
        let mut p = initial_covariance::<N>(heading, &a, t);
        let d = noise(t).0.groups();
        let ln_2pi = (2.0 * std::f64::consts::PI).ln();
        // A later start leaves the run's solution ahead of the filter's by the motion, and its
        // attitude off the other alignment's by the rotation between them.
        let moved = motion(self.steps, (view, *step, heading.t_s), shift);
        let mut m = SVector::<f64, N>::zeros();
        m.fixed_rows_mut::<6>(0).copy_from_slice(&moved);
        if shift != 0.0 {
            let [roll, pitch, yaw] = a.euler_rad;
            let c = crate::ins::attitude_from_euler(roll, pitch, yaw);
            let run = nalgebra::UnitQuaternion::from_matrix(&view.c_bn);
            m.fixed_rows_mut::<3>(ATTITUDE)
                .copy_from(&(run * c.inverse()).scaled_axis());
        }
        let mut applied = SVector::<f64, N>::zeros();
        let mut sum = 0.0;
        for (index, fx) in self.fixes[..fixes].iter().enumerate() {
            m = fx.transition * (m - applied);
            p = transition_congruence(&fx.transition, &p);
            for (q, dg) in fx.noise_parts.iter().zip(d) {
                p.zip_apply(q, |a, b| *a += dg * b);
            }
            let (fix, measured) = fix_of(&fx.row, t);
            let sigma = [fix.position_sigma_m, fix.velocity_sigma_m_s];
            let motion = motion(self.steps, (&fx.view, fx.step, fx.row.t_s), shift);
            let mut h = fx.view.observation;
            let mut y = SVector::<f64, 6>::zeros();
            let mut r = SVector::<f64, 6>::repeat(1.0);
            let mut rows = 0;
            for i in 0..6 {
                if i < 3 || measured[i - 3] {
                    y[i] = fx.innovation[i] + motion[i];
                    r[i] = sigma[i / 3][i % 3].powi(2);
                    rows += 1;
                } else {
                    // A component not measured: a row of H of zeros with unit variance adds
                    // nothing to ln det S, to the NIS or to the gain.
                    h.row_mut(i).fill(0.0);
                }
            }
            y -= h * m;
            seen(index, &y.into());
            let hp = h * p;
            let s = hp * h.transpose() + SMatrix::<f64, 6, 6>::from_diagonal(&r);
            let Some(chol) = s.cholesky() else {
                return f64::NEG_INFINITY;
            };
            let log_det: f64 = 2.0 * chol.l_dirty().diagonal().map(f64::ln).sum();
            let nis = y.dot(&chol.solve(&y));
            sum += rows as f64 * ln_2pi + log_det + nis;
            // K = P Hᵀ S⁻¹ from S Kᵀ = H P; P⁺ = P − K H P.
            let k = chol.solve(&hp).transpose();
            m += k * y;
            p.gemm(-1.0, &k, &hp, 1.0);
            symmetrize(&mut p);
            applied = fx.correction;
        }
        -0.5 * sum
    }
}

/// How far the predicted measurement at a fix moves when the fix is `shift` s later, from the
/// filter's `view` there, the first IMU step ending at or after it, and its time: the antenna's
/// position (NED, m) and velocity (m/s).
fn motion<const N: usize>(
    steps: &[ImuStep],
    (v, step, t): (&LinearView<N>, usize, f64),
    shift: f64,
) -> [f64; 6] {
    if shift == 0.0 {
        return [0.0; 6];
    }
    let f = specific_force_integral(steps, step, t, t + shift);
    let compensated = (f - v.accel_bias_m_s2 * shift).component_div(&v.accel_scale.add_scalar(1.0));
    let dv = v.c_bn * compensated + v.field_acceleration_ned_m_s2 * shift;
    let dp = v.antenna_velocity_ned_m_s * shift + dv * (0.5 * shift);
    [dp.x, dp.y, dp.z, dv.x, dv.y, dv.z]
}

/// ∫ f^b dt from `from` to `to` (negative when `to` is earlier) over the IMU steps, each shared
/// in proportion to its part inside; `step` is the first step that ends at or after `from`.
fn specific_force_integral(steps: &[ImuStep], step: usize, from: f64, to: f64) -> Vector3<f64> {
    let (lo, hi, sign) = if to >= from {
        (from, to, 1.0)
    } else {
        (to, from, -1.0)
    };
    let overlap = |st: &ImuStep| {
        let (t1, dt) = (st.t_s, st.increment.dt_s);
        let inside = (t1.min(hi) - (t1 - dt).max(lo)).max(0.0);
        st.increment.dvel_m_s * (inside / dt)
    };
    let mut sum = Vector3::zeros();
    // Forward from the step holding `from` while steps start before `hi`; backward while they
    // end after `lo`.
    for st in steps.iter().skip(step) {
        if st.t_s - st.increment.dt_s >= hi {
            break;
        }
        sum += overlap(st);
    }
    for st in steps[..step.min(steps.len())].iter().rev() {
        if st.t_s <= lo {
            break;
        }
        sum += overlap(st);
    }
    sum * sign
}

/// P ← (P + Pᵀ)/2 in place.
fn symmetrize<const N: usize>(p: &mut Square<N>) {
    for i in 0..N {
        for j in i + 1..N {
            let v = 0.5 * (p[(i, j)] + p[(j, i)]);
            p[(i, j)] = v;
            p[(j, i)] = v;
        }
    }
}
