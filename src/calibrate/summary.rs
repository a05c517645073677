//! What a calibration hands on: `estimates.csv` rows, the `summary.json` record, and the per-fix
//! series the report draws.

use serde::Serialize;

use crate::input::csv::text::push_row;
use crate::state::{BiasModel, ErrorState, StateMatrix, StateVector};

use super::StepMode;
use super::forward::FilteredFix;
use super::nis::NisTest;
use super::smoother::SmoothedFix;

// The columns and records below name the three states of the error state one by one.
const _: () = assert!(
    ErrorState::DIM == 3,
    "calibrate/summary.rs: add the new state's columns and records"
);

/// Columns of `estimates.csv`: one row per accelerometer sample. Filtered values are a
/// posteriori at a fix; corrected position and velocity are the integration plus the estimated
/// error, p_c + δp̂ and v_c + δv̂.
pub const ESTIMATES_COLUMNS: [&str; 20] = [
    "t_s",
    "gps_fix",
    "p_integrated_m",
    "v_integrated_m_s",
    "dp_filtered_m",
    "dv_filtered_m_s",
    "bias_filtered_m_s2",
    "sigma_dp_filtered_m",
    "sigma_dv_filtered_m_s",
    "sigma_bias_filtered_m_s2",
    "dp_smoothed_m",
    "dv_smoothed_m_s",
    "bias_smoothed_m_s2",
    "sigma_dp_smoothed_m",
    "sigma_dv_smoothed_m_s",
    "sigma_bias_smoothed_m_s2",
    "p_filtered_m",
    "v_filtered_m_s",
    "p_smoothed_m",
    "v_smoothed_m_s",
];

/// Columns of `estimates.csv` by default: one row per GPS fix, at the accelerometer sample it
/// is applied at (`t_s`). The columns it shares with [`ESTIMATES_COLUMNS`] hold the same
/// numbers as that file's row of the fix; "prior" is the a priori estimate δx̂⁻ and its σ, the
/// innovation r = δz − H·δx̂⁻ with σ = √diag S, and `nis` = rᵀ·S⁻¹·r.
pub const FIX_ESTIMATES_COLUMNS: [&str; 33] = [
    "t_s",
    "gps_t_s",
    "gps_position_m",
    "gps_velocity_m_s",
    "p_integrated_m",
    "v_integrated_m_s",
    "dp_prior_m",
    "dv_prior_m_s",
    "bias_prior_m_s2",
    "sigma_dp_prior_m",
    "sigma_dv_prior_m_s",
    "sigma_bias_prior_m_s2",
    "dp_filtered_m",
    "dv_filtered_m_s",
    "bias_filtered_m_s2",
    "sigma_dp_filtered_m",
    "sigma_dv_filtered_m_s",
    "sigma_bias_filtered_m_s2",
    "dp_smoothed_m",
    "dv_smoothed_m_s",
    "bias_smoothed_m_s2",
    "sigma_dp_smoothed_m",
    "sigma_dv_smoothed_m_s",
    "sigma_bias_smoothed_m_s2",
    "innovation_p_m",
    "innovation_v_m_s",
    "sigma_innovation_p_m",
    "sigma_innovation_v_m_s",
    "nis",
    "p_filtered_m",
    "v_filtered_m_s",
    "p_smoothed_m",
    "v_smoothed_m_s",
];

/// Appends the row of fix `f` (taken at `gps_t_s`), smoothed as `sm`, in the order of
/// [`FIX_ESTIMATES_COLUMNS`].
pub(super) fn push_fix_row(out: &mut String, f: &FilteredFix, gps_t_s: f64, sm: &SmoothedFix) {
    let (gp, gv) = (ErrorState::GPS_POSITION, ErrorState::GPS_VELOCITY);
    let (dp, dv, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
    let (pc, vc) = (f.integrated[gp], f.integrated[gv]);
    let (s0, s1, s2) = (f.p_prior.sigma(), f.p_post.sigma(), sm.p.sigma());
    let (x0, x1, x2) = (&f.prior, &f.post, &sm.x);
    push_row(
        out,
        &[
            f.t_s,
            gps_t_s,
            f.z[gp],
            f.z[gv],
            pc,
            vc,
            x0[dp],
            x0[dv],
            x0[b],
            s0[dp],
            s0[dv],
            s0[b],
            x1[dp],
            x1[dv],
            x1[b],
            s1[dp],
            s1[dv],
            s1[b],
            x2[dp],
            x2[dv],
            x2[b],
            s2[dp],
            s2[dv],
            s2[b],
            f.residual[gp],
            f.residual[gv],
            f.s[(gp, gp)].sqrt(),
            f.s[(gv, gv)].sqrt(),
            f.nis,
            pc + x1[dp],
            vc + x1[dv],
            pc + x2[dp],
            vc + x2[dv],
        ],
    );
}

/// σ = √diag P.
pub fn sigma(p: &StateMatrix) -> [f64; ErrorState::DIM] {
    std::array::from_fn(|k| p[(k, k)].sqrt())
}

/// One sample: time, whether a fix was applied, the integration, the filtered and smoothed
/// estimates with their covariances.
pub(super) struct EstimateRow<'a> {
    pub t_s: f64,
    pub fix: bool,
    pub integrated: [f64; ErrorState::MEAS],
    pub filtered: (&'a StateVector, &'a StateMatrix),
    pub smoothed: (&'a StateVector, &'a StateMatrix),
}

impl EstimateRow<'_> {
    /// The row's numbers in the order of [`ESTIMATES_COLUMNS`].
    pub fn values(&self) -> [f64; ESTIMATES_COLUMNS.len()] {
        let (pc, vc) = (
            self.integrated[ErrorState::GPS_POSITION],
            self.integrated[ErrorState::GPS_VELOCITY],
        );
        let (x, p) = self.filtered;
        let (xs, ps) = self.smoothed;
        let (sf, ss) = (sigma(p), sigma(ps));
        let (dp, dv, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
        [
            self.t_s,
            if self.fix { 1.0 } else { 0.0 },
            pc,
            vc,
            x[dp],
            x[dv],
            x[b],
            sf[dp],
            sf[dv],
            sf[b],
            xs[dp],
            xs[dv],
            xs[b],
            ss[dp],
            ss[dv],
            ss[b],
            pc + x[dp],
            vc + x[dv],
            pc + xs[dp],
            vc + xs[dv],
        ]
    }
}

/// Rows of [`ESTIMATES_COLUMNS`] formatted at once.
const ROWS_PER_CHUNK: usize = 1 << 16;

/// Rows of `estimates.csv` gathered, then formatted on all threads and written in order: the
/// shortest round-trip form of 20 numbers a row is most of the work of writing the file.
pub(super) struct EstimateChunks<'w> {
    out: &'w mut dyn std::io::Write,
    rows: Vec<[f64; ESTIMATES_COLUMNS.len()]>,
}

impl<'w> EstimateChunks<'w> {
    /// Rows to be written to `out`.
    pub fn new(out: &'w mut dyn std::io::Write) -> Self {
        Self {
            out,
            rows: Vec::with_capacity(ROWS_PER_CHUNK),
        }
    }

    /// Adds one row, writing the chunk when it is full.
    ///
    /// # Errors
    /// When writing fails.
    pub fn push(&mut self, row: [f64; ESTIMATES_COLUMNS.len()]) -> std::io::Result<()> {
        self.rows.push(row);
        if self.rows.len() == ROWS_PER_CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the rows gathered.
    ///
    /// # Errors
    /// When writing fails.
    pub fn flush(&mut self) -> std::io::Result<()> {
        use rayon::prelude::*;
        let texts: Vec<String> = self
            .rows
            .par_chunks(ROWS_PER_CHUNK / 16)
            .map(|rows| {
                let mut text = String::with_capacity(rows.len() * 400);
                for row in rows {
                    push_row(&mut text, row);
                }
                text
            })
            .collect();
        for text in texts {
            self.out.write_all(text.as_bytes())?;
        }
        self.rows.clear();
        self.out.flush()
    }
}

/// An estimate of the error state with its σ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateRecord {
    /// Position error δp̂, m.
    pub dp_m: f64,
    /// Velocity error δv̂, m/s.
    pub dv_m_s: f64,
    /// Bias b̂, m/s².
    pub bias_m_s2: f64,
    /// σ of δp̂, m.
    pub sigma_dp_m: f64,
    /// σ of δv̂, m/s.
    pub sigma_dv_m_s: f64,
    /// σ of b̂, m/s².
    pub sigma_bias_m_s2: f64,
}

impl StateRecord {
    /// The record of estimate `x` with covariance `p`.
    pub fn new(x: &StateVector, p: &StateMatrix) -> Self {
        let s = sigma(p);
        let (dp, dv, b) = (ErrorState::POSITION, ErrorState::VELOCITY, ErrorState::BIAS);
        Self {
            dp_m: x[dp],
            dv_m_s: x[dv],
            bias_m_s2: x[b],
            sigma_dp_m: s[dp],
            sigma_dv_m_s: s[dv],
            sigma_bias_m_s2: s[b],
        }
    }
}

/// The filter's assumptions, from the configuration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FilterRecord {
    /// p_c(0) = mean of p(0), m.
    pub initial_position_mean_m: f64,
    /// v_c(0) = mean of v(0), m/s.
    pub initial_velocity_mean_m_s: f64,
    /// σ of p(0), m.
    pub initial_position_sigma_m: f64,
    /// σ of v(0), m/s.
    pub initial_velocity_sigma_m_s: f64,
    /// Prior variance of the bias, (m/s²)².
    pub bias_var_m2_s4: f64,
    /// Accelerometer white-noise variance W, (m/s²)².
    pub accel_noise_var_m2_s4: f64,
    /// GPS position noise σ, m.
    pub gps_position_sigma_m: f64,
    /// GPS velocity noise σ, m/s.
    pub gps_velocity_sigma_m_s: f64,
    /// The bias model the filter assumes: "constant", "random_walk" or "gauss_markov".
    pub bias_model: &'static str,
    /// K of a random-walk bias, m/s² per √s (only with `random_walk`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_random_walk_m_s2_per_sqrt_s: Option<f64>,
    /// τ_b of a Gauss–Markov bias, s (only with `gauss_markov`; its stationary variance is
    /// `bias_var_m2_s4`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_correlation_time_s: Option<f64>,
}

impl FilterRecord {
    /// The bias model's fields of the record: its name and its parameter.
    pub fn bias_fields(model: BiasModel) -> (&'static str, Option<f64>, Option<f64>) {
        match model {
            BiasModel::Constant => (model.name(), None, None),
            BiasModel::RandomWalk { k_m_s2_per_sqrt_s } => {
                (model.name(), Some(k_m_s2_per_sqrt_s), None)
            }
            BiasModel::GaussMarkov { correlation_time_s } => {
                (model.name(), None, Some(correlation_time_s))
            }
        }
    }
}

/// `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// The program's version.
    pub accelcal_version: &'static str,
    /// The accelerometer log as named on the command line.
    pub accelerometer_log: String,
    /// The GPS log as named on the command line.
    pub gps_log: String,
    /// The bias estimate at the last sample, m/s² (filtered and smoothed agree there).
    pub bias_m_s2: f64,
    /// Its σ, m/s².
    pub bias_sigma_m_s2: f64,
    /// Whether a test rejects the model the bias's σ assumes: `rejected_by` is not empty.
    pub intervals_conditional: bool,
    /// The tests that reject, by name ([`rejected_by`](super::robust::rejected_by)).
    pub rejected_by: Vec<String>,
    /// The bias with an interval that does not assume white innovations.
    pub bias_robust: super::robust::BiasRobust,
    /// Accelerometer samples.
    pub samples: u64,
    /// GPS fixes applied.
    pub fixes: usize,
    /// First accelerometer time stamp, s.
    pub start_s: f64,
    /// Last accelerometer time stamp, s.
    pub end_s: f64,
    /// end_s − start_s.
    pub duration_s: f64,
    /// "nominal": every step equals the configured Δt within a relative 10⁻⁹ and the in-memory
    /// recursion runs with it; "per_step": Φ(Δt_j), Q(Δt_j) from each pair of time stamps.
    pub dt_mode: StepMode,
    /// The configured Δt = 1 / accelerometer.sample_rate_hz, s.
    pub nominal_dt_s: f64,
    /// Median step of the log, s.
    pub median_step_s: f64,
    /// Shortest step, s.
    pub min_step_s: f64,
    /// Longest step, s.
    pub max_step_s: f64,
    /// The accepted steps, [0.5, 1.5] × the median, s.
    pub accepted_step_s: [f64; 2],
    /// How far from its sample a fix may lie: half the median step, s.
    pub fix_tolerance_s: f64,
    /// The smoothed estimate at the first sample: the initial position and velocity errors, and
    /// the bias at the start (which differs from the end's when the bias drifts).
    pub start_smoothed: StateRecord,
    /// The filtered estimate at the last sample.
    pub end_estimate: StateRecord,
    /// The smoothed estimate at the last sample: no measurement follows it, so it equals the
    /// filtered one, `end_estimate` (the smoother starts there).
    pub end_smoothed: StateRecord,
    /// The NIS test of the whole log.
    pub nis: NisTest,
    /// The filter's assumptions.
    pub filter: FilterRecord,
    /// What the user should know before trusting the numbers, in words (empty when nothing):
    /// a prior that disagrees with the first fix
    /// ([`prior_warnings`](super::warnings::prior_warnings)).
    pub warnings: Vec<String>,
    /// What the innovations, the per-fix NIS and the bias's path point to, with the sentences
    /// they choose (field names in [`super::diagnose::Diagnostics`]).
    pub diagnostics: super::diagnose::Diagnostics,
    /// The filter's Gaussian log-likelihood of its innovations, −½ Σ (ln det(2π S) + NIS).
    pub log_likelihood: f64,
    /// The statistics estimated from the drive (`--estimate-noise`), absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_estimate: Option<super::noise::NoiseRecord>,
}

/// One fix as the report draws it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixReport {
    /// Time of the fix's sample, s.
    pub t_s: f64,
    /// The fix (z_p, z_v), (m, m/s).
    pub z: [f64; ErrorState::MEAS],
    /// Integrated accelerometer (p_c, v_c), (m, m/s).
    pub integrated: [f64; ErrorState::MEAS],
    /// A posteriori estimate.
    pub filtered: [f64; ErrorState::DIM],
    /// Its σ.
    pub filtered_sigma: [f64; ErrorState::DIM],
    /// Smoothed estimate.
    pub smoothed: [f64; ErrorState::DIM],
    /// Its σ.
    pub smoothed_sigma: [f64; ErrorState::DIM],
    /// Residual r = δz − H·δx̂⁻, (m, m/s).
    pub residual: [f64; ErrorState::MEAS],
    /// √diag S: the residual's predicted σ, (m, m/s).
    pub residual_sigma: [f64; ErrorState::MEAS],
    /// rᵀ S⁻¹ r.
    pub nis: f64,
}

/// A calibration's results: the summary and the per-fix series.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// `summary.json`.
    pub summary: Summary,
    /// Every fix.
    pub fixes: Vec<FixReport>,
}

impl Summary {
    /// `summary.json` as text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("finite numbers serialize")
    }
}
