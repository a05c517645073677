//! The study-wide false-alarm rate's accepted range, shared by both models' `[checks]`.

use super::show;
use crate::error::ConfigError;
use crate::stats::MIN_ACCURATE_RATE;

/// The smallest accepted `checks.false_alarm_rate` (see [`validate_false_alarm_rate`]).
pub const MIN_FALSE_ALARM_RATE: f64 = 1e-6;

/// The study-wide false-alarm rate α must be in [[`MIN_FALSE_ALARM_RATE`], 0.5].
///
/// Each member of a check is tested at α over the number of checks and over its members, up to
/// about 10⁷ members within the memory budget of the running sums; at α = 10⁻⁶ those shares stay
/// above [`MIN_ACCURATE_RATE`], the smallest rate whose normal bound double precision computes
/// accurately.
pub fn validate_false_alarm_rate(alpha: f64) -> Result<(), ConfigError> {
    if alpha.is_finite() && (MIN_FALSE_ALARM_RATE..=0.5).contains(&alpha) {
        return Ok(());
    }
    Err(ConfigError::invalid(
        "checks.false_alarm_rate",
        show(alpha),
        format!(
            "must be a finite number in [{}, 0.5]: below {}, the share of each member of a large \
             check falls under {}, where the normal quantile Φ⁻¹(1 − p/2) is no longer accurate \
             in double precision",
            show(MIN_FALSE_ALARM_RATE),
            show(MIN_FALSE_ALARM_RATE),
            show(MIN_ACCURATE_RATE)
        ),
    ))
}
