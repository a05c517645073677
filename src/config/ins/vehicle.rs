//! A car's keys (`model = "car"`, `[vehicle]`): how the IMU sits in the vehicle and the
//! vehicle's constraint on its own motion, with their accepted ranges.

use serde::{Deserialize, Serialize};

use super::InsConfig;
use crate::config::show;
use crate::error::ConfigError;

/// The vehicle an IMU is mounted in: its mounting and the non-holonomic constraint (the
/// vehicle does not slide sideways or leave the road: its lateral and vertical velocity are zero
/// up to the tyres' slip).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleConfig {
    /// The rotation from the IMU's axes to the vehicle's forward-right-down, as roll, pitch and
    /// yaw (ZYX), degrees, each in [−180, 180]: [180, 0, 0] is an IMU mounted upside down.
    pub mounting_rpy_deg: [f64; 3],
    /// The σ of the small angles by which the true mounting differs from `mounting_rpy_deg`,
    /// per axis, degrees, in [0, 10]: drawn once per realization; the filter's prior of them.
    pub mounting_sigma_deg: f64,
    /// The σ of the vehicle's lateral and vertical velocity (the slip), m/s, in [10⁻⁴, 10].
    pub nhc_sigma_m_s: f64,
    /// The rate of the non-holonomic updates, Hz, in (0, the IMU's rate].
    pub nhc_rate_hz: f64,
    /// The speed above which the constraint is applied, m/s, in [0, 100].
    pub nhc_min_speed_m_s: f64,
}

impl Default for VehicleConfig {
    fn default() -> Self {
        VehicleConfig {
            mounting_rpy_deg: [180.0, 0.0, 0.0],
            mounting_sigma_deg: 2.0,
            nhc_sigma_m_s: 0.05,
            nhc_rate_hz: 5.0,
            nhc_min_speed_m_s: 1.0,
        }
    }
}

impl InsConfig {
    /// Whether the file describes a car (`model = "car"`, or a `[vehicle]` section).
    pub fn is_car(&self) -> bool {
        self.model.as_deref() == Some("car") || self.vehicle.is_some()
    }

    /// The filter's error states: `filter.error_states`, else 15, or a car's 18 (the mounting
    /// estimated).
    pub fn error_states(&self) -> usize {
        let default = if self.is_car() { 18 } else { 15 };
        self.filter.error_states.map_or(default, |n| n as usize)
    }

    /// The vehicle as it is, when the file describes a car: its keys over the defaults.
    pub fn vehicle(&self) -> Option<VehicleConfig> {
        self.is_car()
            .then(|| self.vehicle.clone().unwrap_or_default())
    }

    /// The vehicle the filter assumes: `[filter]`'s `mounting_rpy_deg` and `nhc_sigma_m_s`
    /// over the truth's.
    pub fn assumed_vehicle(&self) -> Option<VehicleConfig> {
        self.vehicle().map(|v| VehicleConfig {
            mounting_rpy_deg: self.filter.mounting_rpy_deg.unwrap_or(v.mounting_rpy_deg),
            nhc_sigma_m_s: self.filter.nhc_sigma_m_s.unwrap_or(v.nhc_sigma_m_s),
            ..v
        })
    }

    /// The vehicle's keys, the truth's and the filter's, against their ranges.
    pub(super) fn vehicle_fields(&self) -> Result<(), ConfigError> {
        if self.model.as_deref() == Some("ins") && self.vehicle.is_some() {
            return Err(ConfigError::invalid(
                "model",
                "ins",
                "\"car\" in a file with a [vehicle] section",
            ));
        }
        let Some(v) = self.vehicle() else {
            for (field, set) in [
                (
                    "filter.mounting_rpy_deg",
                    self.filter.mounting_rpy_deg.is_some(),
                ),
                ("filter.nhc_sigma_m_s", self.filter.nhc_sigma_m_s.is_some()),
            ] {
                if set {
                    return Err(ConfigError::invalid(
                        field,
                        "set",
                        "left out unless model = \"car\"",
                    ));
                }
            }
            return Ok(());
        };
        let f = self.assumed_vehicle().unwrap_or_default();
        let rate = self.imu.imu_rate_hz;
        let angles = [
            ("vehicle.mounting_rpy_deg", v.mounting_rpy_deg),
            ("filter.mounting_rpy_deg", f.mounting_rpy_deg),
        ];
        for (field, rpy) in angles {
            if let Some(a) = rpy.iter().find(|a| !(-180.0..=180.0).contains(*a)) {
                return Err(ConfigError::invalid(
                    field,
                    show(*a),
                    "three angles in [−180, 180] degrees",
                ));
            }
        }
        let ranges = [
            (
                "vehicle.mounting_sigma_deg",
                v.mounting_sigma_deg,
                0.0,
                10.0,
                "degrees",
            ),
            ("vehicle.nhc_sigma_m_s", v.nhc_sigma_m_s, 1e-4, 10.0, "m/s"),
            ("filter.nhc_sigma_m_s", f.nhc_sigma_m_s, 1e-4, 10.0, "m/s"),
            (
                "vehicle.nhc_rate_hz",
                v.nhc_rate_hz,
                1e-3,
                rate,
                "Hz (at most the IMU's rate)",
            ),
            (
                "vehicle.nhc_min_speed_m_s",
                v.nhc_min_speed_m_s,
                0.0,
                100.0,
                "m/s",
            ),
        ];
        for (field, value, lo, hi, unit) in ranges {
            super::validate::within(field, value, lo, hi, unit)?;
        }
        Ok(())
    }
}
