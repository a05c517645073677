//! The filter over the reduced log, fix to fix, and the checks that needed the whole log first
//! (the median step): gaps, two fixes applied at one end sample. The first problem in the order
//! of the samples is reported, as a sample-by-sample pass meets it.

use crate::error::FilterError;
use crate::filter::ErrorStateModel;
use crate::input::csv::GpsFix;
use crate::input::{LogError, LogProblem};
use crate::model::NoiseStats;
use crate::simulation::measurement;
use crate::state::{ErrorState, StateMatrix, StateModel, StateVector};

use super::chunked::Chunked;
use super::forward::FilteredFix;
use super::pass::{FixAt, Reduced};
use super::scan::Scan;
use super::{CalibrateError, StepMode};

/// A problem found after the pass, at the sample where a sample-by-sample pass meets it, and
/// in the order it meets them there (a step, a fix on the sample, the integration over the
/// step, a fix inside the step).
struct Found {
    sample: u64,
    phase: u8,
    error: LogError,
}

impl Found {
    fn key(&self) -> (u64, u8) {
        (self.sample, self.phase)
    }
}

/// The first step outside the accepted band, as the first problem found at the sample before it.
fn first_gap(scan: &Scan, reduced: &Reduced, accel: &str) -> Option<Found> {
    let (lo, hi) = scan.accepted_step_s();
    let (short, long) = reduced.step_range;
    let at = [
        reduced.median.first_outside(lo, hi),
        Some(short),
        Some(long),
    ]
    .into_iter()
    .flatten()
    .filter(|at| !(lo..=hi).contains(&at.step_s()))
    .min_by_key(|at| at.sample)?;
    let step_s = at.step_s();
    let problem = LogProblem::Gap {
        previous_s: at.previous_s,
        t_s: at.t_s,
        step_s,
        ratio: step_s / scan.median_step_s,
        median_s: scan.median_step_s,
    };
    Some(Found {
        sample: at.sample - 1,
        phase: 0,
        error: LogError::at(accel, at.line, problem),
    })
}

/// The first fix applied at the time of the fix before it (two fixes beyond one end of the log,
/// both applied at its end sample), and its index.
fn first_misplaced_fix(scan: &Scan, fixes: &Chunked<FixAt>) -> Option<(usize, Found)> {
    let i = (1..fixes.len()).find(|&i| fixes[i - 1].t_s == fixes[i].t_s)?;
    let (f, gps) = (&fixes[i], &scan.gps[fixes[i].fix]);
    let problem = LogProblem::FixOnTakenSample {
        t_s: gps.t_s,
        sample_s: f.t_s,
        other_line: scan.gps[fixes[i - 1].fix].line,
    };
    let error = LogError::at(&scan.gps_name, gps.line, problem);
    Some((
        i,
        Found {
            sample: f.sample,
            phase: 1,
            error,
        },
    ))
}

/// The first sample whose step overflows the integration in `mode`.
fn overflow(reduced: &Reduced, mode: StepMode, accel: &str) -> Option<Found> {
    let (sample, line) = reduced.overflow[mode_index(mode)]?;
    let what = "the step to the next row, the integrated velocity and position or their \
                covariance is no longer a finite number: a time stamp or acceleration here is \
                too large"
        .to_string();
    let error = LogError::at(accel, line, LogProblem::Overflow { what });
    Some(Found {
        sample,
        phase: 3,
        error,
    })
}

/// Which of the pass's two integrations `mode` takes.
pub fn mode_index(mode: StepMode) -> usize {
    match mode {
        StepMode::Nominal => 0,
        StepMode::PerStep => 1,
    }
}

/// The filter at the last fix (the log's first sample before any). A fix between samples is
/// reached over the fractions of the steps it cuts (the pass's units hold them as steps of their
/// own), so per-step intervals run from fix time to fix time.
struct FixFilter<'m> {
    model: &'m ErrorStateModel,
    stats: NoiseStats,
    /// Φ over n nominal steps, by n: the product of the steps for a bias whose Φ does not
    /// compose (a nominal log's intervals take few lengths).
    powers: Vec<(u64, StateMatrix)>,
    mode: StepMode,
    /// Sample and time of the last fix.
    last: (u64, f64),
    x: StateVector,
    p: StateMatrix,
}

impl FixFilter<'_> {
    /// The transition from the last fix to `sample` at `t_s` and P propagated there, with the
    /// per-step noise `units` of the interval: the nominal step's recursion sample by sample
    /// (the in-memory filter's operations), or Φ and Q of the interval from the units.
    fn propagate(
        &mut self,
        sample: u64,
        t_s: f64,
        units: &super::pass::NoiseUnits,
    ) -> (StateMatrix, StateMatrix) {
        match self.mode {
            StepMode::Nominal => {
                let n = sample - self.last.0;
                (
                    self.nominal_transition(n),
                    propagate_steps(self.model, &self.p, n),
                )
            }
            StepMode::PerStep => {
                let phi = units.interval_transition(t_s - self.last.1, self.stats.bias_model);
                let q = units.interval_noise(&self.stats);
                let p = phi * self.p * phi.transpose() + q;
                (phi, (p + p.transpose()) * 0.5)
            }
        }
    }

    /// Φ over `n` nominal steps as `FilterSchedule` computes it: in one piece when the model's
    /// Φ composes, else the product of the steps, Φ(Δt)·(…·(Φ(Δt)·I)).
    fn nominal_transition(&mut self, n: u64) -> StateMatrix {
        let state = ErrorState { stats: self.stats };
        if state.transition_composes() {
            return state.transition(0.0, n as f64 * self.model.dt_s);
        }
        if let Some((_, phi)) = self.powers.iter().find(|(m, _)| *m == n) {
            return *phi;
        }
        let phi = step_product(self.model, n);
        if self.powers.len() < 16 {
            self.powers.push((n, phi));
        }
        phi
    }

    /// The measurement update with `gps` at `fix`, as `forward::Forward::update`.
    fn update(&mut self, fix: &FixAt, gps: &GpsFix) -> Result<FilteredFix, FilterError> {
        let (phi, p) = self.propagate(fix.sample, fix.t_s, &fix.units);
        let prior = phi * self.x;
        let integrated = fix.integrated[mode_index(self.mode)];
        let integrated = measurement(integrated.pc_m, integrated.vc_m_s);
        let at = (fix.sample, fix.t_s);
        let fixed = FilteredFix::update(self.model, gps, at, integrated, (prior, &p, phi))?;
        (self.x, self.p, self.last) = (fixed.post, fixed.p_post.matrix(), (fix.sample, fix.t_s));
        Ok(fixed)
    }

    /// The estimate and covariance at the log's last sample.
    fn end(&mut self, reduced: &Reduced) -> (StateVector, StateMatrix) {
        let (samples, last_s) = (reduced.samples - 1, reduced.span_s.1);
        match self.mode {
            StepMode::Nominal => {
                // Sample by sample, as the per-sample estimate runs after the last fix.
                let mut x = self.x;
                for _ in self.last.0..samples {
                    x = self.model.phi * x;
                }
                (
                    x,
                    propagate_steps(self.model, &self.p, samples - self.last.0),
                )
            }
            StepMode::PerStep => {
                let (phi, p) = self.propagate(samples, last_s, &reduced.end.1);
                (phi * self.x, p)
            }
        }
    }
}

/// Φ(Δt)ⁿ as the product of the steps, I multiplied by Φ(Δt) n times from the left: the
/// in-memory filter's transition over an interval of a model whose Φ does not compose.
pub fn step_product(model: &ErrorStateModel, n: u64) -> StateMatrix {
    let mut phi = StateMatrix::identity();
    for _ in 0..n {
        phi = model.phi * phi;
    }
    phi
}

/// `p` after `n` steps of [`ErrorStateModel::propagate`], P ← (Φ·P·Φᵀ + Q + (Φ·P·Φᵀ + Q)ᵀ)/2,
/// with the same operations in the same order on plain arrays (the same bits, a few times
/// faster: it runs once per sample of a nominal log).
pub fn propagate_steps(model: &ErrorStateModel, p: &StateMatrix, n: u64) -> StateMatrix {
    type M = [[f64; 3]; 3];
    let get =
        |m: &StateMatrix| -> M { std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])) };
    let (phi, q) = (get(&model.phi), get(&model.q));
    // c_ij = (a_i0·b_0j + a_i1·b_1j) + a_i2·b_2j, nalgebra's order for a product of 3×3.
    let product = |a: &M, b: &M| -> M {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
        })
    };
    let phi_t: M = std::array::from_fn(|i| std::array::from_fn(|j| phi[j][i]));
    let mut m = get(p);
    for _ in 0..n {
        let mut a = product(&product(&phi, &m), &phi_t);
        for (row, q) in a.iter_mut().zip(&q) {
            for (v, q) in row.iter_mut().zip(q) {
                *v += q;
            }
        }
        m = std::array::from_fn(|i| std::array::from_fn(|j| (a[i][j] + a[j][i]) * 0.5));
    }
    StateMatrix::from_fn(|i, j| m[i][j])
}

/// The fixes filtered and the estimate at the last sample.
pub type Filtered = (Vec<FilteredFix>, (StateVector, StateMatrix));

/// Checks the reduced log against the median step and runs the filter over its fixes.
///
/// # Errors
/// The first problem in sample order: a gap, two fixes applied at one end sample, a
/// covariance not positive definite, a non-finite residual, or an overflowing integration.
pub fn filter(
    scan: &Scan,
    reduced: &Reduced,
    model: &ErrorStateModel,
    stats: &NoiseStats,
    accel: &str,
) -> Result<Filtered, CalibrateError> {
    let found = first_problem(scan, reduced, accel);
    run(
        scan,
        reduced,
        reduced.fixes.iter(),
        found,
        (model, stats, accel),
    )
}

/// [`filter`] for the last time: the reduced fixes taken, each chunk freed once filtered.
///
/// # Errors
/// As [`filter`].
pub fn filter_last(
    scan: &Scan,
    mut reduced: Reduced,
    model: &ErrorStateModel,
    stats: &NoiseStats,
    accel: &str,
) -> Result<Filtered, CalibrateError> {
    let found = first_problem(scan, &reduced, accel);
    let fixes = std::mem::take(&mut reduced.fixes).into_items();
    run(scan, &reduced, fixes, found, (model, stats, accel))
}

/// The first problem a sample-by-sample pass would meet, with the fixes to filter before it.
fn first_problem(scan: &Scan, reduced: &Reduced, accel: &str) -> (usize, Option<Found>) {
    let misplaced = first_misplaced_fix(scan, &reduced.fixes);
    let stop_fix = misplaced.as_ref().map_or(reduced.fixes.len(), |(i, _)| *i);
    let found = [
        first_gap(scan, reduced, accel),
        misplaced.map(|(_, f)| f),
        overflow(reduced, scan.mode, accel),
    ]
    .into_iter()
    .flatten()
    .min_by_key(Found::key);
    (stop_fix, found)
}

/// The filter over the first `stop_fix` of `fixes` up to the problem `found`, then to the end
/// of `reduced`.
fn run<F: std::borrow::Borrow<FixAt>>(
    scan: &Scan,
    reduced: &Reduced,
    fixes: impl Iterator<Item = F>,
    (stop_fix, found): (usize, Option<Found>),
    (model, stats, accel): (&ErrorStateModel, &NoiseStats, &str),
) -> Result<Filtered, CalibrateError> {
    let mut f = FixFilter {
        model,
        stats: *stats,
        powers: Vec::new(),
        mode: scan.mode,
        last: (0, scan.span_s.0),
        x: StateVector::zeros(),
        p: model.p0,
    };
    let mut filtered_fixes = Vec::with_capacity(stop_fix);
    let mut since_line = reduced.first_line;
    for fix in fixes.take(stop_fix) {
        let fix = fix.borrow();
        // A fix inside a step needs the step: after the step's own overflow (phase 3).
        let phase = if fix.tau_s > 0.0 { 4 } else { 2 };
        if found
            .as_ref()
            .is_some_and(|e| e.key() < (fix.sample, phase))
        {
            break;
        }
        let gps = &scan.gps[fix.fix];
        let filtered = f.update(fix, gps)?;
        if !filtered.is_finite() {
            return Err(not_finite(&filtered, scan, gps, (accel, since_line)).into());
        }
        since_line = fix.line;
        filtered_fixes.push(filtered);
    }
    if let Some(e) = found {
        return Err(e.error.into());
    }
    let end = f.end(reduced);
    Ok((filtered_fixes, end))
}

/// The overflow at a fix whose residual, NIS or estimate is not finite: naming the fix's line
/// when the fix is the larger of the fix and the integrated (p_c, v_c) it is compared with, else
/// the accelerometer rows integrated since the previous fix (from `since_line` of `accel`).
fn not_finite(
    fix: &FilteredFix,
    scan: &Scan,
    gps: &GpsFix,
    (accel, since_line): (&str, u64),
) -> LogError {
    let largest = |v: &[f64]| v.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
    if largest(fix.z.as_slice()) >= largest(fix.integrated.as_slice()) {
        let what = "the filter's residual, NIS or estimate at this fix is no longer a finite \
                    number: its position or velocity is too large"
            .to_string();
        LogError::at(&scan.gps_name, gps.line, LogProblem::Overflow { what })
    } else {
        let what = format!(
            "the residual of the fix at {} line {} is no longer a finite number: the velocity \
             and position integrated from this row to that fix's sample are too large (an \
             acceleration of those rows is)",
            scan.gps_name, gps.line
        );
        LogError::at(accel, since_line.max(1), LogProblem::Overflow { what })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_written_out_propagation_is_the_model_s_bit_for_bit() {
        let constant = crate::model::Model::new(&crate::config::Config::default())
            .unwrap()
            .filter_stats;
        for bias_model in [
            crate::state::BiasModel::Constant,
            crate::state::BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: 0.02,
            },
            crate::state::BiasModel::GaussMarkov {
                correlation_time_s: 20.0,
            },
        ] {
            let stats = NoiseStats {
                bias_model,
                ..constant
            };
            written_out_equals_the_model(&stats);
        }
    }

    fn written_out_equals_the_model(stats: &NoiseStats) {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for dt in [0.005, 0.001, 0.0123] {
            let model = ErrorStateModel::new(dt, stats);
            for _ in 0..200 {
                let a = StateMatrix::from_fn(|_, _| uniform());
                let p0 = a * a.transpose() + StateMatrix::identity() * 1e-3;
                let mut p = p0;
                for _ in 0..7 {
                    p = model.propagate(&p);
                }
                let fast = propagate_steps(&model, &p0, 7);
                let bits = |m: &StateMatrix| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&p), "Δt {dt}");
            }
        }
    }
}
