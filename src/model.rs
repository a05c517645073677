//! The validated study model: time grid, acceleration profile, truth, and the noise statistics of
//! the truth and of the filter. Built once from a [`Config`]; everything downstream reads it.

use crate::config::{Config, TruthModel};
use crate::error::ConfigError;

/// Largest number of accelerometer samples in a run.
pub const MAX_STEPS: usize = 10_000_000;
/// Largest number of GPS fixes in a run (the residual-pair statistics grow with its square).
pub const MAX_FIXES: usize = 1_000;
/// Largest ensemble.
pub const MAX_REALIZATIONS: u64 = 100_000_000;

/// Smallest variance or standard deviation the filter may assume.
pub const FILTER_FLOOR: f64 = 1e-12;

/// Relative tolerance used to decide that a ratio of rates or times is a whole number.
const WHOLE_TOL: f64 = 1e-9;

/// The time grid: accelerometer samples t_j = j·Δt, j = 0..=steps, and the GPS fixes among them.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// Accelerometer sample period Δt, s.
    pub dt_s: f64,
    /// Number of accelerometer samples integrated; the run ends at t = steps·Δt.
    pub steps: usize,
    /// Accelerometer samples between two GPS fixes.
    pub steps_per_fix: usize,
    /// Sample index j of every GPS fix, increasing.
    pub fix_steps: Vec<usize>,
}

impl Timeline {
    /// Time of accelerometer sample j, s.
    pub fn time_s(&self, j: usize) -> f64 {
        j as f64 * self.dt_s
    }

    /// Times of the GPS fixes, s.
    pub fn fix_times_s(&self) -> Vec<f64> {
        self.fix_steps.iter().map(|&j| self.time_s(j)).collect()
    }

    /// Number of GPS fixes.
    pub fn fixes(&self) -> usize {
        self.fix_steps.len()
    }

    /// Index of the fix at time `t_s`, if a fix falls there.
    pub fn fix_index_at(&self, t_s: f64) -> Option<usize> {
        let j = whole(t_s / self.dt_s)?;
        self.fix_steps.binary_search(&(j as usize)).ok()
    }
}

/// Noise statistics of the error-state system: the truth's, or the ones the filter assumes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseStats {
    /// Accelerometer white-noise variance W, (m/s²)².
    pub accel_noise_var_m2_s4: f64,
    /// Bias prior variance, (m/s²)².
    pub bias_var_m2_s4: f64,
    /// GPS position noise σ, m.
    pub gps_position_sigma_m: f64,
    /// GPS velocity noise σ, m/s.
    pub gps_velocity_sigma_m_s: f64,
    /// Initial position σ, m.
    pub initial_position_sigma_m: f64,
    /// Initial velocity σ, m/s.
    pub initial_velocity_sigma_m_s: f64,
}

/// The validated model of one study.
#[derive(Clone, Debug)]
pub struct Model {
    /// The configuration it was built from.
    pub config: Config,
    /// The time grid.
    pub timeline: Timeline,
    /// Which truth model the ensemble simulates.
    pub truth: TruthModel,
    /// True acceleration a(t_j) at every sample j = 0..steps, m/s².
    pub accel_m_s2: Vec<f64>,
    /// The truth's noise statistics.
    pub truth_stats: NoiseStats,
    /// The filter's assumed noise statistics.
    pub filter_stats: NoiseStats,
    /// The single residual pair (t_m, t_i) of the checks, s: configured, or the fixes nearest
    /// one third and two thirds of the run.
    pub residual_pair_s: [f64; 2],
    /// The part of the closed-form truth that does not depend on p(0), v(0), at every fix:
    /// (p(t) − p(0) − v(0)·t, v(t) − v(0)), so eq. (1) costs no trigonometry per realization.
    pub analytic_offsets_at_fix: Vec<[f64; 2]>,
}

impl Model {
    /// Validates `config` and derives the model.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first field outside its accepted range.
    pub fn new(config: &Config) -> Result<Self, ConfigError> {
        validate(config)?;
        let p = &config.profile;
        let a = &config.accelerometer;
        let g = &config.gps;
        let dt_s = 1.0 / a.sample_rate_hz;
        let steps = whole(p.duration_s * a.sample_rate_hz).expect("validated") as usize;
        let steps_per_fix = whole(a.sample_rate_hz / g.sample_rate_hz).expect("validated") as usize;
        let first = if g.fix_at_start { 0 } else { steps_per_fix };
        let fix_steps: Vec<usize> = (first..=steps).step_by(steps_per_fix).collect();
        let timeline = Timeline {
            dt_s,
            steps,
            steps_per_fix,
            fix_steps,
        };
        let accel_m_s2 = (0..steps)
            .map(|j| {
                p.accel_amplitude_m_s2 * (p.accel_angular_freq_rad_s * timeline.time_s(j)).sin()
            })
            .collect();
        let truth_stats = NoiseStats {
            accel_noise_var_m2_s4: a.noise_var_m2_s4,
            bias_var_m2_s4: a.bias_var_m2_s4,
            gps_position_sigma_m: g.position_sigma_m,
            gps_velocity_sigma_m_s: g.velocity_sigma_m_s,
            initial_position_sigma_m: config.initial.position_sigma_m,
            initial_velocity_sigma_m_s: config.initial.velocity_sigma_m_s,
        };
        let filter_stats = NoiseStats {
            accel_noise_var_m2_s4: config.filter_accel_noise_var_m2_s4(),
            bias_var_m2_s4: config.filter_bias_var_m2_s4(),
            gps_position_sigma_m: config.filter_gps_position_sigma_m(),
            gps_velocity_sigma_m_s: config.filter_gps_velocity_sigma_m_s(),
            initial_position_sigma_m: config.filter_initial_position_sigma_m(),
            initial_velocity_sigma_m_s: config.filter_initial_velocity_sigma_m_s(),
        };
        let residual_pair_s = config.checks.residual_pair_s.unwrap_or_else(|| {
            let n = timeline.fixes();
            let near = |frac: f64| {
                let t = frac * timeline.time_s(timeline.steps);
                (0..n)
                    .min_by(|&a, &b| {
                        let da = (timeline.time_s(timeline.fix_steps[a]) - t).abs();
                        let db = (timeline.time_s(timeline.fix_steps[b]) - t).abs();
                        da.total_cmp(&db)
                    })
                    .expect("at least two fixes")
            };
            let m = near(1.0 / 3.0).min(n - 2);
            let i = near(2.0 / 3.0).max(m + 1);
            [
                timeline.time_s(timeline.fix_steps[m]),
                timeline.time_s(timeline.fix_steps[i]),
            ]
        });
        let analytic_offsets_at_fix = timeline
            .fix_steps
            .iter()
            .map(|&j| analytic_offsets(config, timeline.time_s(j)))
            .collect();
        Ok(Self {
            config: config.clone(),
            residual_pair_s,
            analytic_offsets_at_fix,
            timeline,
            truth: config.ensemble.truth,
            accel_m_s2,
            truth_stats,
            filter_stats,
        })
    }

    /// The same model with another truth model.
    pub fn with_truth(&self, truth: TruthModel) -> Self {
        let mut m = self.clone();
        m.truth = truth;
        m.config.ensemble.truth = truth;
        m
    }

    /// Closed-form true position and velocity at time `t_s` for initial values `p0_m`, `v0_m_s`:
    /// eq. (1), p(t) = p0 + (v0 + A/ω)·t − (A/ω²)·sin(ωt), v(t) = v0 + (A/ω)·(1 − cos(ωt)).
    pub fn analytic_truth(&self, t_s: f64, p0_m: f64, v0_m_s: f64) -> (f64, f64) {
        let [dp, dv] = analytic_offsets(&self.config, t_s);
        (p0_m + v0_m_s * t_s + dp, v0_m_s + dv)
    }

    /// [`Model::analytic_truth`] at fix `i`, from the tabulated offsets.
    #[inline]
    pub fn analytic_truth_at_fix(&self, i: usize, t_s: f64, p0_m: f64, v0_m_s: f64) -> (f64, f64) {
        let [dp, dv] = self.analytic_offsets_at_fix[i];
        (p0_m + v0_m_s * t_s + dp, v0_m_s + dv)
    }
}

/// The closed-form truth less its initial-value terms: ((A/ω)·t − (A/ω²)·sin ωt, (A/ω)·(1 − cos ωt)),
/// written as (A·t²·(x − sin x)/x², A·t·2·sin²(x/2)/x) with x = ωt so that no large terms cancel
/// when ωt is small.
fn analytic_offsets(config: &Config, t_s: f64) -> [f64; 2] {
    let a = config.profile.accel_amplitude_m_s2;
    let x = config.profile.accel_angular_freq_rad_s * t_s;
    if x == 0.0 {
        return [0.0, 0.0];
    }
    // (x − sin x)/x²: its Taylor series below 0.5 rad, where the difference would lose digits.
    let g = if x.abs() < 0.5 {
        let x2 = x * x;
        x / 6.0
            * (1.0
                - x2 / 20.0
                    * (1.0
                        - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0 * (1.0 - x2 / 156.0)))))
    } else {
        (x - x.sin()) / (x * x)
    };
    let h = 2.0 * (0.5 * x).sin().powi(2) / x;
    [a * t_s * t_s * g, a * t_s * h]
}

/// `x` rounded to the nearest whole number when it is one within [`WHOLE_TOL`].
fn whole(x: f64) -> Option<u64> {
    let r = x.round();
    (x.is_finite() && r >= 0.0 && (x - r).abs() <= WHOLE_TOL * r.max(1.0)).then_some(r as u64)
}

/// A number as a person would write it: exponent notation when it is very small or large.
fn show(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn finite_in(
    field: &'static str,
    x: f64,
    lo: f64,
    hi: f64,
    lo_open: bool,
) -> Result<(), ConfigError> {
    let ok = x.is_finite() && (if lo_open { x > lo } else { x >= lo }) && x <= hi;
    if ok {
        Ok(())
    } else {
        let open = if lo_open { "(" } else { "[" };
        Err(ConfigError::invalid(
            field,
            show(x),
            format!(
                "must be a finite number in {open}{}, {}]",
                show(lo),
                show(hi)
            ),
        ))
    }
}

fn positive(field: &'static str, x: f64, hi: f64) -> Result<(), ConfigError> {
    finite_in(field, x, 0.0, hi, true)
}

fn non_negative(field: &'static str, x: f64, hi: f64) -> Result<(), ConfigError> {
    finite_in(field, x, 0.0, hi, false)
}

/// Checks every field against its accepted range, in file order.
fn validate(c: &Config) -> Result<(), ConfigError> {
    let p = &c.profile;
    non_negative("profile.accel_amplitude_m_s2", p.accel_amplitude_m_s2, 1e4)?;
    finite_in(
        "profile.accel_angular_freq_rad_s",
        p.accel_angular_freq_rad_s,
        1e-9,
        1e4,
        false,
    )?;
    positive("profile.duration_s", p.duration_s, 1e5)?;

    let a = &c.accelerometer;
    positive("accelerometer.sample_rate_hz", a.sample_rate_hz, 1e6)?;
    non_negative("accelerometer.noise_var_m2_s4", a.noise_var_m2_s4, 1e6)?;
    non_negative("accelerometer.bias_var_m2_s4", a.bias_var_m2_s4, 1e6)?;
    match whole(p.duration_s * a.sample_rate_hz) {
        Some(n) if n >= 1 && n as usize <= MAX_STEPS => {}
        _ => {
            return Err(ConfigError::invalid(
                "profile.duration_s",
                p.duration_s,
                format!(
                    "duration_s × accelerometer.sample_rate_hz ({} Hz) must be a whole number of \
                     samples in [1, {MAX_STEPS}]",
                    a.sample_rate_hz
                ),
            ));
        }
    }

    let g = &c.gps;
    positive("gps.sample_rate_hz", g.sample_rate_hz, a.sample_rate_hz)?;
    if whole(a.sample_rate_hz / g.sample_rate_hz).is_none() {
        return Err(ConfigError::invalid(
            "gps.sample_rate_hz",
            g.sample_rate_hz,
            format!(
                "must divide accelerometer.sample_rate_hz ({} Hz) into a whole number of samples \
                 per fix",
                a.sample_rate_hz
            ),
        ));
    }
    positive("gps.position_sigma_m", g.position_sigma_m, 1e6)?;
    positive("gps.velocity_sigma_m_s", g.velocity_sigma_m_s, 1e6)?;
    let steps = whole(p.duration_s * a.sample_rate_hz).expect("checked above");
    let per_fix = whole(a.sample_rate_hz / g.sample_rate_hz).expect("checked above");
    let fixes = steps / per_fix + u64::from(g.fix_at_start);
    if !(2..=MAX_FIXES as u64).contains(&fixes) {
        return Err(ConfigError::invalid(
            "profile.duration_s",
            p.duration_s,
            format!(
                "must hold between 2 and {MAX_FIXES} GPS fixes at gps.sample_rate_hz = {} Hz \
                 (it holds {fixes})",
                g.sample_rate_hz
            ),
        ));
    }

    let i = &c.initial;
    finite_in(
        "initial.position_mean_m",
        i.position_mean_m,
        -1e9,
        1e9,
        false,
    )?;
    non_negative("initial.position_sigma_m", i.position_sigma_m, 1e6)?;
    finite_in(
        "initial.velocity_mean_m_s",
        i.velocity_mean_m_s,
        -1e6,
        1e6,
        false,
    )?;
    non_negative("initial.velocity_sigma_m_s", i.velocity_sigma_m_s, 1e6)?;

    // The filter's statistics must keep its covariance positive definite: all strictly positive.
    let f = &c.filter;
    let filter_fields: [(&'static str, Option<f64>); 6] = [
        ("filter.accel_noise_var_m2_s4", f.accel_noise_var_m2_s4),
        ("filter.bias_var_m2_s4", f.bias_var_m2_s4),
        ("filter.gps_position_sigma_m", f.gps_position_sigma_m),
        ("filter.gps_velocity_sigma_m_s", f.gps_velocity_sigma_m_s),
        (
            "filter.initial_position_sigma_m",
            f.initial_position_sigma_m,
        ),
        (
            "filter.initial_velocity_sigma_m_s",
            f.initial_velocity_sigma_m_s,
        ),
    ];
    // Floors keep S and P well inside double precision; below them the covariance recursion
    // cannot stay positive definite.
    for (field, value) in filter_fields {
        if let Some(x) = value {
            finite_in(field, x, FILTER_FLOOR, 1e6, false)?;
        }
    }
    let resolved: [(&'static str, f64); 4] = [
        ("accel_noise_var_m2_s4", c.filter_accel_noise_var_m2_s4()),
        ("bias_var_m2_s4", c.filter_bias_var_m2_s4()),
        (
            "initial_position_sigma_m",
            c.filter_initial_position_sigma_m(),
        ),
        (
            "initial_velocity_sigma_m_s",
            c.filter_initial_velocity_sigma_m_s(),
        ),
    ];
    for (name, x) in resolved {
        if x < FILTER_FLOOR {
            return Err(ConfigError::invalid(
                "filter",
                format!("{name} = {x} (taken from the truth)"),
                format!(
                    "the filter needs {name} ≥ {FILTER_FLOOR}; set filter.{name} to a value in [{FILTER_FLOOR}, 1000000]"
                ),
            ));
        }
    }

    let e = &c.ensemble;
    if !(2..=MAX_REALIZATIONS).contains(&e.realizations) {
        return Err(ConfigError::invalid(
            "ensemble.realizations",
            e.realizations,
            format!("must be a whole number in [2, {MAX_REALIZATIONS}]"),
        ));
    }

    let k = &c.checks;
    finite_in(
        "checks.false_alarm_rate",
        k.false_alarm_rate,
        0.0,
        0.5,
        true,
    )?;
    let Some([tm, ti]) = k.residual_pair_s else {
        return Ok(());
    };
    let period = per_fix as f64 / a.sample_rate_hz;
    let first = if g.fix_at_start { 0.0 } else { period };
    let last = (steps / per_fix) as f64 * period;
    // The index of the fix at `t`, when `t` is a fix time of the run.
    let fix_index = |t: f64| {
        (t.is_finite() && t >= first - 1e-9 && t <= last + 1e-9)
            .then(|| whole(t / period))
            .flatten()
    };
    let ordered = matches!((fix_index(tm), fix_index(ti)), (Some(m), Some(i)) if m < i);
    if !ordered {
        return Err(ConfigError::invalid(
            "checks.residual_pair_s",
            format!("[{tm}, {ti}]"),
            format!(
                "must be two GPS fix times [t_m, t_i] with t_m < t_i, multiples of {period} s in \
                 [{first}, {last}]"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_timeline_matches_the_statement() {
        let m = Model::new(&Config::default()).unwrap();
        let t = &m.timeline;
        assert_eq!(t.steps, 6000);
        assert_eq!(t.steps_per_fix, 40);
        assert_eq!(t.fixes(), 150);
        assert_eq!(t.fix_steps[0], 40);
        assert_eq!(*t.fix_steps.last().unwrap(), 6000);
        assert_eq!(t.fix_index_at(10.0), Some(49));
        assert_eq!(m.residual_pair_s, [10.0, 20.0]);
        let mut c = Config::default();
        c.profile.duration_s = 0.4;
        assert_eq!(Model::new(&c).unwrap().residual_pair_s, [0.2, 0.4]);
    }

    #[test]
    fn fix_at_start_adds_a_fix_at_zero() {
        let mut c = Config::default();
        c.gps.fix_at_start = true;
        let m = Model::new(&c).unwrap();
        assert_eq!(m.timeline.fixes(), 151);
        assert_eq!(m.timeline.fix_steps[0], 0);
    }

    #[test]
    fn analytic_truth_is_accurate_for_small_angles() {
        let mut c = Config::default();
        c.profile.accel_angular_freq_rad_s = 1e-9;
        let m = Model::new(&c).unwrap();
        // For ωt → 0 the profile is a ≈ A·ω·t: v = A·ω·t²/2, p = A·ω·t³/6.
        let (p, v) = m.analytic_truth(30.0, 0.0, 0.0);
        approx::assert_relative_eq!(v, 10.0 * 1e-9 * 900.0 / 2.0, max_relative = 1e-9);
        approx::assert_relative_eq!(p, 10.0 * 1e-9 * 27000.0 / 6.0, max_relative = 1e-9);
        // Both branches of the series agree where they meet.
        let c = Config::default();
        let w = c.profile.accel_angular_freq_rad_s;
        let below = analytic_offsets(&c, 0.4999999 / w);
        let above = analytic_offsets(&c, 0.5000001 / w);
        approx::assert_relative_eq!(below[0], above[0], max_relative = 1e-5);
    }

    #[test]
    fn residual_pair_must_name_two_different_fixes() {
        let mut c = Config::default();
        c.checks.residual_pair_s = Some([10.0, 10.000_000_000_1]);
        assert_eq!(field_of(&c), "checks.residual_pair_s");
        c.checks.residual_pair_s = Some([10.0, 10.2]);
        assert!(Model::new(&c).is_ok());
    }

    #[test]
    fn analytic_truth_integrates_the_profile() {
        let m = Model::new(&Config::default()).unwrap();
        let (p0, v0) = m.analytic_truth(0.0, 3.0, 100.0);
        assert!((p0 - 3.0).abs() < 1e-12 && (v0 - 100.0).abs() < 1e-12);
        // Central difference of v must be a(t).
        let (t, h) = (7.3, 1e-4);
        let dv =
            (m.analytic_truth(t + h, 0.0, 0.0).1 - m.analytic_truth(t - h, 0.0, 0.0).1) / (2.0 * h);
        let a = 10.0 * (m.config.profile.accel_angular_freq_rad_s * t).sin();
        assert!((dv - a).abs() < 1e-6, "{dv} vs {a}");
    }

    fn field_of(c: &Config) -> &'static str {
        match Model::new(c) {
            Err(ConfigError::Invalid { field, .. }) => field,
            Err(e) => panic!("unexpected {e}"),
            Ok(_) => panic!("accepted an invalid configuration"),
        }
    }

    #[test]
    fn invalid_fields_are_named() {
        let mut c = Config::default();
        c.gps.sample_rate_hz = 7.0;
        assert_eq!(field_of(&c), "gps.sample_rate_hz");
        let mut c = Config::default();
        c.accelerometer.noise_var_m2_s4 = -1.0;
        assert_eq!(field_of(&c), "accelerometer.noise_var_m2_s4");
        let mut c = Config::default();
        c.profile.duration_s = f64::NAN;
        assert_eq!(field_of(&c), "profile.duration_s");
        let mut c = Config::default();
        c.ensemble.realizations = 1;
        assert_eq!(field_of(&c), "ensemble.realizations");
        let mut c = Config::default();
        c.checks.residual_pair_s = Some([20.0, 10.0]);
        assert_eq!(field_of(&c), "checks.residual_pair_s");
        let mut c = Config::default();
        c.filter.gps_position_sigma_m = Some(0.0);
        assert_eq!(field_of(&c), "filter.gps_position_sigma_m");
        let mut c = Config::default();
        c.accelerometer.noise_var_m2_s4 = 0.0;
        assert_eq!(field_of(&c), "filter");
        let mut c = Config::default();
        c.filter.gps_position_sigma_m = Some(1e-200);
        assert_eq!(field_of(&c), "filter.gps_position_sigma_m");
        let mut c = Config::default();
        c.profile.accel_angular_freq_rad_s = 1e-300;
        assert_eq!(field_of(&c), "profile.accel_angular_freq_rad_s");
    }
}
