//! A calibration's results as they are handed on: the summary and the per-fix series.

use super::summary::{Calibration, FilterRecord, FixReport, StateRecord, Summary, sigma};
use super::{Prepared, StepMode, diagnose, nis_test, noise, robust, warnings};
use crate::state::{ErrorState, StateVector};

impl Prepared<'_> {
    /// The calibration's summary and per-fix series.
    pub fn calibration(&self) -> Calibration {
        let (x_end, p_end) = &self.end;
        let s = &self.settings;
        let f = &s.filter_stats;
        let sc = &self.scan;
        let start_smoothed = match (self.fixes.first(), self.smoothed.first()) {
            (Some(fix), Some(sm)) => sm.smooth(
                &StateVector::zeros(),
                &self.model.p0,
                &fix.phi_from_previous,
            ),
            _ => (StateVector::zeros(), self.model.p0),
        };
        let nis: Vec<f64> = self.fixes.iter().map(|f| f.nis).collect();
        let fixes: Vec<FixReport> = self
            .fixes
            .iter()
            .zip(&self.smoothed)
            .map(|(f, sm)| FixReport {
                t_s: f.t_s,
                z: f.z.into(),
                integrated: f.integrated.into(),
                filtered: f.post.into(),
                filtered_sigma: sigma(&f.p_post),
                smoothed: sm.x.into(),
                smoothed_sigma: sigma(&sm.p),
                residual: f.residual.into(),
                residual_sigma: std::array::from_fn(|k| f.s[(k, k)].sqrt()),
                nis: f.nis,
            })
            .collect();
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
