//! The three-axis configuration's accepted ranges: every field named with its dotted path.

use super::{GnssConfig, ImuConfig, InsConfig, LONGEST_DRIVE_S};
use crate::config::{BiasModelKind, show};
use crate::error::ConfigError;

impl InsConfig {
    /// Checks every field against its accepted range, the truth's and the filter's.
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the first field out of range and what is accepted.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if let Some(m) = &self.model
            && m != "ins"
            && m != "car"
        {
            return Err(ConfigError::invalid(
                "model",
                m,
                "\"ins\" or \"car\" in a three-axis file",
            ));
        }
        self.vehicle_fields()?;
        let (d, i) = (&self.drive, &self.initial);
        let ranges: [(&'static str, f64, f64, f64, &str); 9] = [
            ("drive.duration_s", d.duration_s, 1.0, LONGEST_DRIVE_S, "s"),
            (
                "drive.start_lat_deg",
                d.start_lat_deg,
                -80.0,
                80.0,
                "degrees",
            ),
            (
                "drive.start_lon_deg",
                d.start_lon_deg,
                -180.0,
                180.0,
                "degrees",
            ),
            (
                "drive.start_height_m",
                d.start_height_m,
                -500.0,
                10_000.0,
                "m",
            ),
            ("imu.imu_rate_hz", self.imu.imu_rate_hz, 20.0, 2000.0, "Hz"),
            (
                "initial.position_sigma_m",
                i.position_sigma_m,
                1e-3,
                1e4,
                "m",
            ),
            (
                "initial.velocity_sigma_m_s",
                i.velocity_sigma_m_s,
                1e-4,
                100.0,
                "m/s",
            ),
            (
                "initial.tilt_sigma_deg",
                i.tilt_sigma_deg,
                1e-4,
                30.0,
                "degrees",
            ),
            (
                "initial.yaw_sigma_deg",
                i.yaw_sigma_deg,
                1e-4,
                180.0,
                "degrees",
            ),
        ];
        for (field, value, lo, hi, unit) in ranges {
            within(field, value, lo, hi, unit)?;
        }
        self.rates()?;
        imu_fields(false, &self.imu)?;
        gnss_fields(false, &self.gnss)?;
        let assumed = self.assumed();
        imu_fields(true, &assumed.imu)?;
        gnss_fields(true, &assumed.gnss)?;
        self.check_error_states(&assumed.imu)?;
        self.checks()
    }

    /// The ensemble's size, the checks' false-alarm rate and the whiteness check's lag.
    fn checks(&self) -> Result<(), ConfigError> {
        if self.ensemble.realizations < 2 {
            return Err(ConfigError::invalid(
                "ensemble.realizations",
                self.ensemble.realizations,
                "at least 2",
            ));
        }
        crate::config::validate_false_alarm_rate(self.checks.false_alarm_rate)?;
        if self.checks.residual_max_lag == Some(0) {
            return Err(ConfigError::invalid(
                "checks.residual_max_lag",
                0,
                "a whole number of fixes ≥ 1 (or left out)",
            ));
        }
        Ok(())
    }

    /// A car's filter estimating its mounting needs a prior σ above 0.
    fn check_mounting_prior(&self) -> Result<(), ConfigError> {
        let sigma = self.vehicle().unwrap_or_default().mounting_sigma_deg;
        if sigma > 0.0 {
            return Ok(());
        }
        Err(ConfigError::invalid(
            "vehicle.mounting_sigma_deg",
            show(sigma),
            "above 0 degrees when the filter estimates the mounting (a car's \
             filter.error_states = 18, its default); 0 with filter.error_states = 15",
        ))
    }

    /// The filter's error states: 15, 21 with a prior σ for each scale factor group, or a
    /// car's 18 with the mounting angles.
    fn check_error_states(&self, assumed: &ImuConfig) -> Result<(), ConfigError> {
        match self.filter.error_states {
            Some(15) => Ok(()),
            None if !self.is_car() => Ok(()),
            None => self.check_mounting_prior(),
            Some(18) if self.is_car() => self.check_mounting_prior(),
            Some(21) => {
                for (field, sigma) in [
                    (
                        "filter.gyro_scale_factor_sigma_ppm",
                        assumed.gyro_scale_factor_sigma_ppm,
                    ),
                    (
                        "filter.accel_scale_factor_sigma_ppm",
                        assumed.accel_scale_factor_sigma_ppm,
                    ),
                ] {
                    if sigma <= 0.0 {
                        return Err(ConfigError::invalid(
                            field,
                            show(sigma),
                            "a prior σ above 0 ppm when filter.error_states = 21 (set it in \
                             [imu] or [filter])",
                        ));
                    }
                }
                Ok(())
            }
            Some(n) => Err(ConfigError::invalid(
                "filter.error_states",
                n,
                "15, 21 with the six scale factors, or 18 with a car's mounting angles \
                 (model = \"car\")",
            )),
        }
    }

    /// The IMU's rate in whole hertz, the GNSS rate dividing it.
    fn rates(&self) -> Result<(), ConfigError> {
        let rate = self.imu.imu_rate_hz;
        if rate.fract() != 0.0 {
            return Err(ConfigError::invalid(
                "imu.imu_rate_hz",
                rate,
                "a whole number of hertz (the drive's segments join on whole seconds)",
            ));
        }
        let g = self.gnss.gnss_rate_hz;
        within(
            "gnss.gnss_rate_hz",
            g,
            0.01,
            rate,
            "Hz (at most the IMU's rate)",
        )?;
        let per_fix = rate / g;
        if (per_fix - per_fix.round()).abs() > 1e-9 {
            return Err(ConfigError::invalid(
                "gnss.gnss_rate_hz",
                g,
                format!("a rate that divides the IMU's {rate} Hz (a fix at an IMU sample)"),
            ));
        }
        Ok(())
    }
}

/// `value` within [lo, hi] (and finite), else the error naming `field`.
pub(super) fn within(
    field: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    unit: &str,
) -> Result<(), ConfigError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(ConfigError::invalid(
            field,
            show(value),
            format!("a number from {} to {} {unit}", show(lo), show(hi)),
        ))
    }
}

/// The dotted path of `key`: in `[filter]` when `filter`, else in `section`.
macro_rules! field {
    ($filter:expr, $section:literal, $key:literal) => {
        if $filter {
            concat!("filter.", $key)
        } else {
            concat!($section, ".", $key)
        }
    };
}

fn imu_fields(filter: bool, m: &ImuConfig) -> Result<(), ConfigError> {
    within(
        field!(filter, "imu", "gyro_arw_rad_per_sqrt_s"),
        m.gyro_arw_rad_per_sqrt_s,
        0.0,
        1.0,
        "rad/√s",
    )?;
    within(
        field!(filter, "imu", "accel_vrw_m_s_per_sqrt_s"),
        m.accel_vrw_m_s_per_sqrt_s,
        0.0,
        10.0,
        "m/s/√s",
    )?;
    within(
        field!(filter, "imu", "gyro_bias_sigma_rad_s"),
        m.gyro_bias_sigma_rad_s,
        0.0,
        1.0,
        "rad/s",
    )?;
    within(
        field!(filter, "imu", "accel_bias_sigma_m_s2"),
        m.accel_bias_sigma_m_s2,
        0.0,
        10.0,
        "m/s²",
    )?;
    within(
        field!(filter, "imu", "gyro_bias_random_walk_rad_s_per_sqrt_s"),
        m.gyro_bias_random_walk_rad_s_per_sqrt_s,
        0.0,
        1.0,
        "rad/s per √s",
    )?;
    within(
        field!(filter, "imu", "accel_bias_random_walk_m_s2_per_sqrt_s"),
        m.accel_bias_random_walk_m_s2_per_sqrt_s,
        0.0,
        10.0,
        "m/s² per √s",
    )?;
    within(
        field!(filter, "imu", "gyro_scale_factor_sigma_ppm"),
        m.gyro_scale_factor_sigma_ppm,
        0.0,
        1e5,
        "ppm",
    )?;
    within(
        field!(filter, "imu", "accel_scale_factor_sigma_ppm"),
        m.accel_scale_factor_sigma_ppm,
        0.0,
        1e5,
        "ppm",
    )?;
    if m.gyro_bias_model == BiasModelKind::GaussMarkov {
        within(
            field!(filter, "imu", "gyro_bias_correlation_time_s"),
            m.gyro_bias_correlation_time_s,
            1.0,
            1e7,
            "s",
        )?;
    }
    if m.accel_bias_model == BiasModelKind::GaussMarkov {
        within(
            field!(filter, "imu", "accel_bias_correlation_time_s"),
            m.accel_bias_correlation_time_s,
            1.0,
            1e7,
            "s",
        )?;
    }
    Ok(())
}

fn gnss_fields(filter: bool, g: &GnssConfig) -> Result<(), ConfigError> {
    for &x in &g.gnss_lever_arm_m {
        let key = field!(filter, "gnss", "gnss_lever_arm_m");
        within(key, x, -10.0, 10.0, "m per component")?;
    }
    for &x in &g.gnss_position_sigma_m {
        let key = field!(filter, "gnss", "gnss_position_sigma_m");
        within(key, x, 1e-3, 1e3, "m per component")?;
    }
    let key = field!(filter, "gnss", "gnss_velocity_sigma_m_s");
    within(key, g.gnss_velocity_sigma_m_s, 1e-4, 100.0, "m/s")
}
