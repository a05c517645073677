//! A calibration's results as they are handed on: the summary and the per-fix series.

use super::summary::{Calibration, FilterRecord, FixReport, StateRecord, Summary};
use super::{Prepared, StepMode, diagnose, nis_test, noise, robust, warnings};
use crate::state::{ErrorState, StateVector};

/// Up to this many fixes the figures are drawn from every one.
const FIGURE_ALL_FIXES: usize = 1 << 16;
/// A longer log's figures are drawn from this many slices of its fixes, equal in number.
const FIGURE_SLICES: usize = 2048;

/// The fixes the figures draw, `report(i)` of fix `i` of `n`: every one up to
/// [`FIGURE_ALL_FIXES`]. Beyond, a figure a thousand pixels wide cannot show more than the
/// extremes of each pixel column, so each of [`FIGURE_SLICES`] slices of consecutive fixes keeps
/// its first and last fix and those that hold the least and the greatest of every number the
/// figures plot (estimates, their ±σ edges, residuals, NIS): a million fixes are drawn from at
/// most 2 048·(2 + 2·40) of them, not held whole (176 bytes a fix).
fn figure_fixes(n: usize, report: impl Fn(usize) -> FixReport) -> Vec<FixReport> {
    if n <= FIGURE_ALL_FIXES {
        return (0..n).map(report).collect();
    }
    let mut kept = Vec::new();
    for slice in 0..FIGURE_SLICES {
        let (from, to) = (slice * n / FIGURE_SLICES, (slice + 1) * n / FIGURE_SLICES);
        let mut least = [(f64::INFINITY, usize::MAX); PLOTTED];
        let mut most = [(f64::NEG_INFINITY, usize::MAX); PLOTTED];
        for i in from..to {
            for (k, v) in plotted(&report(i)).into_iter().enumerate() {
                // NaN compares false: never an extreme.
                if v < least[k].0 {
                    least[k] = (v, i);
                }
                if v > most[k].0 {
                    most[k] = (v, i);
                }
            }
        }
        let mut at: Vec<usize> = [from, to - 1]
            .into_iter()
            .chain(least.iter().chain(&most).map(|&(_, i)| i))
            .filter(|&i| i < to)
            .collect();
        at.sort_unstable();
        at.dedup();
        kept.extend(at.into_iter().map(&report));
    }
    kept
}

/// How many numbers of a fix the figures plot.
const PLOTTED: usize = 8 * ErrorState::DIM + 7 * ErrorState::MEAS + 2;

/// The numbers of `f` the figures plot: each estimate, its σ and ±σ edges; the fix, the
/// integration, the corrected trajectory and the drift; the residuals and their ±σ; the NIS and
/// the bias's departure.
fn plotted(f: &FixReport) -> [f64; PLOTTED] {
    const _: () = assert!(
        ErrorState::MEAS == 2,
        "the measured components' states below"
    );
    let states = [ErrorState::POSITION, ErrorState::VELOCITY];
    let b = ErrorState::BIAS;
    let departure = super::diagnose::bias_departure(
        [f.filtered[b], f.filtered_sigma[b].powi(2)],
        [f.smoothed[b], f.smoothed_sigma[b].powi(2)],
    );
    let estimates = (0..ErrorState::DIM).flat_map(|k| {
        [
            (f.filtered[k], f.filtered_sigma[k]),
            (f.smoothed[k], f.smoothed_sigma[k]),
        ]
        .into_iter()
        .flat_map(|(x, s)| [x, x - s, x + s, s])
    });
    let measured = states.into_iter().enumerate().flat_map(|(k, state)| {
        let (r, s, pc) = (f.residual[k], f.residual_sigma[k], f.integrated[k]);
        [f.z[k], pc, r, -s, s, pc + f.smoothed[state], pc - f.z[k]]
    });
    let mut numbers = estimates
        .chain(measured)
        .chain([f.nis, departure.unwrap_or(f64::NAN)]);
    let v = std::array::from_fn(|_| numbers.next().expect("PLOTTED numbers"));
    assert!(numbers.next().is_none(), "more than PLOTTED numbers");
    v
}

impl Prepared<'_> {
    /// The calibration's summary and per-fix series.
    pub fn calibration(&self) -> Calibration {
        let (x_end, p_end) = &self.end;
        let s = &self.settings;
        let f = &s.filter_stats;
        let sc = &self.scan;
        let start_smoothed = match (self.fixes.first(), self.smoothed.first()) {
            (Some(fix), Some(sm)) => sm.carry(fix).smooth(
                &StateVector::zeros(),
                &self.model.p0,
                &fix.phi_from_previous,
            ),
            _ => (StateVector::zeros(), self.model.p0),
        };
        let nis: Vec<f64> = self.fixes.iter().map(|f| f.nis).collect();
        let fixes = figure_fixes(self.fixes.len(), |i| {
            let (f, sm) = (&self.fixes[i], &self.smoothed[i]);
            FixReport {
                t_s: f.t_s,
                z: f.z.into(),
                integrated: f.integrated.into(),
                filtered: f.post.into(),
                filtered_sigma: f.p_post.sigma(),
                smoothed: sm.x.into(),
                smoothed_sigma: sm.p.sigma(),
                residual: f.residual.into(),
                residual_sigma: std::array::from_fn(|k| f.s[(k, k)].sqrt()),
                nis: f.nis,
            }
        });
        let (lo, hi) = sc.accepted_step_s();
        let nis_test = nis_test(&nis, s.false_alarm_rate);
        let diagnostics = diagnose::diagnose(
            &self.fixes,
            &self.smoothed,
            f,
            &nis_test,
            s.false_alarm_rate,
        );
        let rejected_by = robust::rejected_by(&nis_test, &diagnostics);
        let (bias, bias_sigma) = (
            x_end[ErrorState::BIAS],
            p_end[(ErrorState::BIAS, ErrorState::BIAS)].sqrt(),
        );
        let summary = Summary {
            accelcal_version: env!("CARGO_PKG_VERSION"),
            accelerometer_log: self.accel.name().to_string(),
            gps_log: sc.gps_name.clone(),
            bias_m_s2: bias,
            bias_sigma_m_s2: bias_sigma,
            intervals_conditional: !rejected_by.is_empty(),
            rejected_by,
            bias_robust: robust::bias_robust(bias, bias_sigma, &self.fixes),
            samples: sc.samples,
            fixes: self.fixes.len(),
            start_s: sc.span_s.0,
            end_s: sc.span_s.1,
            duration_s: sc.span_s.1 - sc.span_s.0,
            dt_mode: sc.mode,
            nominal_dt_s: s.nominal_dt_s.unwrap_or(sc.median_step_s),
            median_step_s: sc.median_step_s,
            min_step_s: sc.step_range_s.0,
            max_step_s: sc.step_range_s.1,
            accepted_step_s: [lo, hi],
            fix_tolerance_s: sc.tolerance_s(),
            start_smoothed: StateRecord::new(&start_smoothed.0, &start_smoothed.1),
            end_estimate: StateRecord::new(x_end, p_end),
            end_smoothed: StateRecord::new(x_end, p_end),
            nis: nis_test,
            filter: self.filter_record(),
            // A prior taken from the first fix agrees with it by construction; it may lie far
            // from the log's start.
            warnings: if s.prior_from_first_fix {
                self.first_fix_warnings()
            } else {
                warnings::prior_warnings(fixes.first())
            },
            diagnostics,
            log_likelihood: noise::log_likelihood(&self.fixes),
            noise_estimate: self.noise.clone().map(noise::NoiseRecord),
        };
        Calibration { summary, fixes }
    }

    /// The noise statistics estimated from the drive, if asked for.
    pub fn noise_estimate(&self) -> Option<&crate::likelihood::NoiseEstimate> {
        self.noise.as_ref()
    }

    /// A prior carried back from a first fix that lies so long after the log's first sample
    /// that the bias, at its prior σ_b, moves the carried-back velocity by more than the prior's
    /// velocity σ: σ_b·Δ > σ_v (P(0) takes the two as independent; they are not, by b·Δ).
    fn first_fix_warnings(&self) -> Vec<String> {
        let (Some(first), f) = (self.scan.gps.first(), &self.settings.filter_stats) else {
            return Vec::new();
        };
        let after_s = first.t_s - self.scan.span_s.0;
        let moved_m_s = f.bias_var_m2_s4.sqrt() * after_s;
        if moved_m_s <= f.initial_velocity_sigma_m_s {
            return Vec::new();
        }
        vec![format!(
            "the prior is the first fix, {} s after the first accelerometer sample: over that \
             time the bias (σ {} m/s²) moves the velocity carried back to the start by up to {} \
             m/s, more than the prior's σ of {} m/s; trim the accelerometer log to start near \
             the first fix, or give an [initial] section",
            crate::format::short(after_s),
            crate::format::short(f.bias_var_m2_s4.sqrt()),
            crate::format::short(moved_m_s),
            crate::format::short(f.initial_velocity_sigma_m_s)
        )]
    }

    /// The filter's assumptions as `summary.json` gives them.
    fn filter_record(&self) -> FilterRecord {
        let (s, start) = (&self.settings, self.start);
        let f = &s.filter_stats;
        let (bias_model, bias_random_walk_m_s2_per_sqrt_s, bias_correlation_time_s) =
            FilterRecord::bias_fields(f.bias_model);
        FilterRecord {
            initial_position_mean_m: start.pc_m,
            initial_velocity_mean_m_s: start.vc_m_s,
            initial_position_sigma_m: f.initial_position_sigma_m,
            initial_velocity_sigma_m_s: f.initial_velocity_sigma_m_s,
            bias_var_m2_s4: f.bias_var_m2_s4,
            accel_noise_var_m2_s4: f.accel_noise_var_m2_s4,
            gps_position_sigma_m: f.gps_position_sigma_m,
            gps_velocity_sigma_m_s: f.gps_velocity_sigma_m_s,
            bias_model,
            bias_random_walk_m_s2_per_sqrt_s,
            bias_correlation_time_s,
        }
    }

    /// Which Δt mode runs.
    pub fn mode(&self) -> StepMode {
        self.scan.mode
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fix `i`'s report: noise-like numbers from a hash of `i`, the NIS with a lone spike.
    fn report(i: usize) -> FixReport {
        let u = |k: u64| {
            let h = (i as u64 ^ (k << 40)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            (h >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        FixReport {
            t_s: i as f64 * 0.005,
            z: [u(1), u(2)],
            integrated: [u(3), u(4)],
            filtered: [u(5), u(6), u(7)],
            filtered_sigma: [1.0 + u(8), 1.0 + u(9), 1.0 + u(10)],
            smoothed: [u(11), u(12), u(13)],
            smoothed_sigma: [0.5 + u(14), 0.5 + u(15), 0.5 + u(16)],
            residual: [u(17), u(18)],
            residual_sigma: [1.0 + u(19), 1.0 + u(20)],
            nis: if i == 123_457 { 1e6 } else { 2.0 + u(21) },
        }
    }

    #[test]
    fn a_short_log_keeps_every_fix() {
        let kept = figure_fixes(FIGURE_ALL_FIXES, report);
        assert_eq!(kept.len(), FIGURE_ALL_FIXES);
        assert!(kept.iter().enumerate().all(|(i, f)| *f == report(i)));
    }

    #[test]
    fn a_long_log_keeps_each_slice_s_ends_and_extremes() {
        let n = 300_000;
        let kept = figure_fixes(n, report);
        assert!(
            kept.len() <= FIGURE_SLICES * (2 + 2 * PLOTTED),
            "{}",
            kept.len()
        );
        assert!(kept.len() < n / 2, "{} of {n} kept", kept.len());
        // In time order, each fix once, the log's ends and its spike among them.
        assert!(kept.windows(2).all(|w| w[0].t_s < w[1].t_s));
        assert_eq!(kept[0], report(0));
        assert_eq!(kept.last(), Some(&report(n - 1)));
        assert!(kept.iter().any(|f| f.nis == 1e6));
        // Every slice's least and greatest of every plotted number are drawn.
        for slice in [0, 1, FIGURE_SLICES / 2, FIGURE_SLICES - 1] {
            let (from, to) = (slice * n / FIGURE_SLICES, (slice + 1) * n / FIGURE_SLICES);
            let in_slice: Vec<&FixReport> = kept
                .iter()
                .filter(|f| (from as f64 * 0.005..to as f64 * 0.005).contains(&f.t_s))
                .collect();
            for k in 0..PLOTTED {
                let all = (from..to).map(|i| plotted(&report(i))[k]);
                let drawn = in_slice.iter().map(|f| plotted(f)[k]);
                let lo = |v: &mut dyn Iterator<Item = f64>| v.fold(f64::INFINITY, f64::min);
                let hi = |v: &mut dyn Iterator<Item = f64>| v.fold(f64::NEG_INFINITY, f64::max);
                assert_eq!(
                    lo(&mut all.clone()),
                    lo(&mut drawn.clone()),
                    "slice {slice} {k}"
                );
                assert_eq!(
                    hi(&mut all.clone()),
                    hi(&mut drawn.clone()),
                    "slice {slice} {k}"
                );
            }
        }
    }
}
