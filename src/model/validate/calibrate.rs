//! What `calibrate` takes from a configuration, checked alone: the keys of a simulation it never
//! reads (`profile`, `gps.sample_rate_hz`, `ensemble`, `sensitivity`, the residual checks) are
//! neither required nor checked, so a recording's configuration holds only what the recording
//! needs.

use super::{positive, validate_false_alarm_rate, validate_filter, validate_initial};
use crate::config::{Config, STATISTICS};
use crate::error::ConfigError;

/// Largest accepted `accelerometer.sample_rate_hz`, Hz (as the study's).
const MAX_SAMPLE_RATE_HZ: f64 = 1e6;

/// Checks the keys `calibrate` uses against their accepted ranges, in file order:
/// `accelerometer.sample_rate_hz` when `rate_set` (else the log's median step is taken), the
/// truth's noise statistics the filter's keys default to, the `[initial]` prior when
/// `initial_set`, every `[filter]` key, the bias models and `checks.false_alarm_rate`.
///
/// # Errors
/// [`ConfigError::Invalid`] naming the first key outside its range, with the range. Without an
/// `[initial]` section the prior comes from the first fix with the GPS σ's, so
/// `filter.initial_position_sigma_m` or `filter.initial_velocity_sigma_m_s` set alone is refused
/// (it would be silently replaced).
pub fn validate_calibration(
    c: &Config,
    rate_set: bool,
    initial_set: bool,
) -> Result<(), ConfigError> {
    let a = &c.accelerometer;
    if rate_set {
        positive(
            "accelerometer.sample_rate_hz",
            a.sample_rate_hz,
            MAX_SAMPLE_RATE_HZ,
        )?;
    }
    super::truth_statistics(c, "accelerometer")?;
    super::truth_statistics(c, "gps")?;
    if initial_set {
        validate_initial(c)?;
    } else {
        let alone = STATISTICS
            .iter()
            .filter(|s| s.truth_section() == "initial")
            .find_map(|s| c.filter_key(s).map(|x| (s.filter_path, x)));
        if let Some((field, x)) = alone {
            return Err(ConfigError::invalid(
                field,
                crate::config::show(x),
                "needs an [initial] section: without one the prior is the first GPS fix, with \
                 the GPS σ's (filter.gps_position_sigma_m, filter.gps_velocity_sigma_m_s); \
                 add [initial] with the prior's means to use this σ, or leave it out",
            ));
        }
    }
    validate_filter(c)?;
    super::bias::validate_bias(c)?;
    validate_false_alarm_rate(c.checks.false_alarm_rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(c: &Config, rate_set: bool, initial_set: bool) -> Option<&'static str> {
        match validate_calibration(c, rate_set, initial_set) {
            Err(ConfigError::Invalid { field, .. }) => Some(field),
            Err(e) => panic!("unexpected {e}"),
            Ok(()) => None,
        }
    }

    #[test]
    fn only_the_keys_calibrate_uses_are_checked() {
        let mut c = Config::default();
        c.accelerometer.sample_rate_hz = 104.356_682_826_889_78;
        // The study refuses this rate with the default run and GPS: calibrate does not.
        assert!(crate::model::Model::new(&c).is_err());
        assert_eq!(field_of(&c, true, false), None);
        c.profile.duration_s = -1.0;
        c.gps.sample_rate_hz = 7.0;
        c.ensemble.realizations = 0;
        assert_eq!(field_of(&c, true, true), None);
        // A key it uses is still checked, and the one left out is not.
        c.accelerometer.sample_rate_hz = -3.0;
        assert_eq!(
            field_of(&c, true, true),
            Some("accelerometer.sample_rate_hz")
        );
        assert_eq!(field_of(&c, false, true), None);
        let mut c = Config::default();
        c.initial.velocity_mean_m_s = f64::NAN;
        assert_eq!(field_of(&c, false, true), Some("initial.velocity_mean_m_s"));
        assert_eq!(field_of(&c, false, false), None);
        c.filter.initial_velocity_sigma_m_s = Some(2.0);
        assert_eq!(
            field_of(&c, false, false),
            Some("filter.initial_velocity_sigma_m_s")
        );
        let mut c = Config::default();
        c.filter.gps_position_sigma_m = Some(0.0);
        assert_eq!(
            field_of(&c, false, false),
            Some("filter.gps_position_sigma_m")
        );
        let mut c = Config::default();
        c.checks.false_alarm_rate = 0.9;
        assert_eq!(field_of(&c, false, false), Some("checks.false_alarm_rate"));
    }
}
