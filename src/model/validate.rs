//! Validation of a parsed [`Config`]: every field against its accepted range, once, naming the
//! first offending field. A configuration that passes builds a [`super::Model`].

use super::memory::sums_bytes;
use super::{
    MAX_FIXES, MAX_REALIZATIONS, MAX_STEPS, MAX_SUMS_BYTES, RESIDUAL_WIDTH, SUM_FLOATS_PER_FIX,
    WHOLE_TOL,
};
use crate::config::statistics::Range;
use crate::config::{Config, STATISTICS, show};
use crate::error::ConfigError;

mod bias;
mod calibrate;

pub(crate) use crate::config::validate_false_alarm_rate;
pub use calibrate::validate_calibration;

/// `x` rounded to the nearest whole number when it is one within [`WHOLE_TOL`].
pub(super) fn whole(x: f64) -> Option<u64> {
    let r = x.round();
    (x.is_finite() && r >= 0.0 && (x - r).abs() <= WHOLE_TOL * r.max(1.0)).then_some(r as u64)
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

/// `x` in `range`, or an error naming `field` with the range.
fn within(field: &'static str, x: f64, range: Range) -> Result<(), ConfigError> {
    finite_in(field, x, range.lo, range.hi, range.lo_open)
}

/// The truth's noise statistics of `section` (but a bias model's parameters, which
/// [`bias::validate_bias`] checks with the model), each in its accepted range, in the table's
/// order.
fn truth_statistics(c: &Config, section: &str) -> Result<(), ConfigError> {
    let rows = STATISTICS.iter().filter(|s| s.bias_model.is_none());
    for s in rows.filter(|s| s.truth_section() == section) {
        let x = c
            .truth_value(s)
            .expect("the truth sets every statistic but a bias model's");
        within(s.truth_path, x, s.truth_range)?;
    }
    Ok(())
}

fn positive(field: &'static str, x: f64, hi: f64) -> Result<(), ConfigError> {
    finite_in(field, x, 0.0, hi, true)
}

fn non_negative(field: &'static str, x: f64, hi: f64) -> Result<(), ConfigError> {
    finite_in(field, x, 0.0, hi, false)
}

/// Checks every field against its accepted range, in file order.
pub(super) fn validate(c: &Config) -> Result<(), ConfigError> {
    let grid = validate_grid(c)?;
    validate_initial(c)?;
    validate_filter(c)?;
    bias::validate_bias(c)?;
    let e = &c.ensemble;
    if !(2..=MAX_REALIZATIONS).contains(&e.realizations) {
        return Err(ConfigError::invalid(
            "ensemble.realizations",
            e.realizations,
            format!("must be a whole number in [2, {MAX_REALIZATIONS}]"),
        ));
    }
    c.sensitivity.check([
        "sensitivity.factors",
        "sensitivity.ensembles",
        "sensitivity.draws",
    ])?;
    let k = &c.checks;
    validate_false_alarm_rate(k.false_alarm_rate)?;
    if k.residual_max_lag == Some(0) {
        return Err(ConfigError::invalid(
            "checks.residual_max_lag",
            0,
            "must be a whole number of fixes ≥ 1 (or left out)",
        ));
    }
    validate_sums_memory(c, grid.fixes)?;
    validate_residual_pair(c, &grid)
}

/// The time grid a valid configuration has: accelerometer samples, samples per fix, fixes.
struct Grid {
    steps: u64,
    per_fix: u64,
    fixes: u64,
}

/// The profile, the accelerometer and the GPS, and the time grid they make.
fn validate_grid(c: &Config) -> Result<Grid, ConfigError> {
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
    truth_statistics(c, "accelerometer")?;
    let Some(steps) =
        whole(p.duration_s * a.sample_rate_hz).filter(|&n| n >= 1 && n as usize <= MAX_STEPS)
    else {
        return Err(ConfigError::invalid(
            "profile.duration_s",
            show(p.duration_s),
            format!(
                "duration_s × accelerometer.sample_rate_hz ({} Hz) must be a whole number of \
                 samples in [1, {MAX_STEPS}]",
                show(a.sample_rate_hz)
            ),
        ));
    };

    let g = &c.gps;
    positive("gps.sample_rate_hz", g.sample_rate_hz, a.sample_rate_hz)?;
    // Two fixes need two GPS periods within the run (one with a fix at the start): a slower GPS
    // is the rate's fault, whatever the run's length.
    let slowest_hz = (2.0 - f64::from(u8::from(g.fix_at_start))) / p.duration_s;
    if g.sample_rate_hz < slowest_hz * (1.0 - WHOLE_TOL) {
        return Err(ConfigError::invalid(
            "gps.sample_rate_hz",
            show(g.sample_rate_hz),
            format!(
                "a run of profile.duration_s = {} s holds fewer than 2 fixes at this rate: it must \
                 be at least {} Hz (or lengthen the run)",
                show(p.duration_s),
                show(slowest_hz)
            ),
        ));
    }
    let Some(per_fix) = whole(a.sample_rate_hz / g.sample_rate_hz) else {
        return Err(ConfigError::invalid(
            "gps.sample_rate_hz",
            show(g.sample_rate_hz),
            format!(
                "must divide accelerometer.sample_rate_hz ({} Hz) into a whole number of samples \
                 per fix",
                show(a.sample_rate_hz)
            ),
        ));
    };
    truth_statistics(c, "gps")?;
    let fixes = steps / per_fix + u64::from(g.fix_at_start);
    if !(2..=MAX_FIXES as u64).contains(&fixes) {
        return Err(ConfigError::invalid(
            "profile.duration_s",
            show(p.duration_s),
            format!(
                "must hold between 2 and {MAX_FIXES} GPS fixes at gps.sample_rate_hz = {} Hz \
                 (it holds {fixes})",
                show(g.sample_rate_hz)
            ),
        ));
    }
    Ok(Grid {
        steps,
        per_fix,
        fixes,
    })
}

/// The prior of the initial position and velocity: the means, then the σ's.
fn validate_initial(c: &Config) -> Result<(), ConfigError> {
    let i = &c.initial;
    finite_in(
        "initial.position_mean_m",
        i.position_mean_m,
        -1e9,
        1e9,
        false,
    )?;
    finite_in(
        "initial.velocity_mean_m_s",
        i.velocity_mean_m_s,
        -1e6,
        1e6,
        false,
    )?;
    truth_statistics(c, "initial")
}

/// The filter's statistics must keep its covariance positive definite: each `[filter]` key
/// set in its range (at least [`crate::config::FILTER_FLOOR`]), and each left out whose
/// truth's value, which it takes, may lie below that range (the truth's range includes its
/// lower end).
fn validate_filter(c: &Config) -> Result<(), ConfigError> {
    let rows = || STATISTICS.iter().filter(|s| s.bias_model.is_none());
    // Floors keep S and P well inside double precision; below them the covariance recursion
    // cannot stay positive definite.
    for s in rows() {
        if let Some(x) = c.filter_key(s) {
            within(s.filter_path, x, s.filter_range)?;
        }
    }
    // A [filter] key left out takes the truth's value: one below the floor is the truth's key's
    // to name, at its line.
    let resolved = rows()
        .filter(|s| !s.truth_range.lo_open && s.truth_range.lo < s.filter_range.lo)
        .map(|s| (s, c.filter_value(s).expect("the truth's value")));
    match resolved.into_iter().find(|(s, x)| *x < s.filter_range.lo) {
        Some((s, x)) => {
            let (name, r) = (s.key(), s.filter_range);
            Err(ConfigError::invalid(
                s.truth_path,
                show(x),
                format!(
                    "the filter takes its {name} from this key (filter.{name} is not set) and \
                     needs at least {}: set filter.{name} to a value in [{}, {}]",
                    show(r.lo),
                    show(r.lo),
                    show(r.hi)
                ),
            ))
        }
        None => Ok(()),
    }
}

/// The running sums of one block of realizations must fit the memory budget: the fix-level sums
/// ([`SUM_FLOATS_PER_FIX`] per fix) and the kept residual products (every pair, or a band of
/// lags).
fn validate_sums_memory(c: &Config, fixes: u64) -> Result<(), ConfigError> {
    let (k, g) = (&c.checks, &c.gps);
    let f = fixes as f64;
    let m = RESIDUAL_WIDTH as f64;
    let per_fix = SUM_FLOATS_PER_FIX as f64;
    let float_bytes = std::mem::size_of::<f64>() as f64;
    let bytes = sums_bytes(c, fixes);
    if bytes > MAX_SUMS_BYTES as f64 {
        let budget = MAX_SUMS_BYTES as f64 / float_bytes - per_fix * f;
        let most = ((budget / (m * f) - m) / m).floor();
        let mib = |b: f64| format!("{:.0} MiB", b / 1048576.0);
        return Err(match k.residual_max_lag {
            Some(l) if most >= 1.0 => ConfigError::invalid(
                "checks.residual_max_lag",
                l,
                format!(
                    "with {fixes} fixes the running sums would take {} per block of realizations; \
                     at most {} lags keep them within {}",
                    mib(bytes),
                    most,
                    mib(MAX_SUMS_BYTES as f64)
                ),
            ),
            _ => ConfigError::invalid(
                "gps.sample_rate_hz",
                show(g.sample_rate_hz),
                format!(
                    "the run would hold {fixes} fixes, whose running sums would take {} per block \
                     of realizations (at most {}): lower the GPS rate or shorten the run",
                    mib(bytes),
                    mib(MAX_SUMS_BYTES as f64)
                ),
            ),
        });
    }
    Ok(())
}

/// The single residual pair, when configured: two fix times of the run, in order.
fn validate_residual_pair(c: &Config, grid: &Grid) -> Result<(), ConfigError> {
    let (a, g) = (&c.accelerometer, &c.gps);
    let (steps, per_fix) = (grid.steps, grid.per_fix);
    let Some([tm, ti]) = c.checks.residual_pair_s else {
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
            format!("[{}, {}]", show(tm), show(ti)),
            format!(
                "must be two GPS fix times [t_m, t_i] with t_m < t_i, multiples of {} s in \
                 [{}, {}]",
                show(period),
                show(first),
                show(last)
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::config::Config;
    use crate::error::ConfigError;
    use crate::model::Model;

    #[test]
    fn residual_pair_must_name_two_different_fixes() {
        let mut c = Config::default();
        c.checks.residual_pair_s = Some([10.0, 10.000_000_000_1]);
        assert_eq!(field_of(&c), "checks.residual_pair_s");
        c.checks.residual_pair_s = Some([10.0, 10.2]);
        assert!(Model::new(&c).is_ok());
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
        assert_eq!(field_of(&c), "accelerometer.noise_var_m2_s4");
        let mut c = Config::default();
        c.filter.gps_position_sigma_m = Some(1e-200);
        assert_eq!(field_of(&c), "filter.gps_position_sigma_m");
        let mut c = Config::default();
        c.profile.accel_angular_freq_rad_s = 1e-300;
        assert_eq!(field_of(&c), "profile.accel_angular_freq_rad_s");
    }
}
