//! Whether the accelerometer's white-noise variance W can be measured from GPS depends on the
//! drive. Two drives estimated with W among the statistics: the configured one (its rates and
//! W) over [`QUIET_DURATION_S`], and a vibrating car ([`VIBRATING_W_M2_S4`], GPS at
//! [`VIBRATING_GPS_HZ`], [`VIBRATING_DURATION_S`]). Both on the euler truth, the filter starting
//! at the truth's statistics; the estimator says for each whether W is identifiable.

use super::noise::run_drive;
use crate::config::{Config, TruthModel};
use crate::error::FilterError;
use crate::filter::FilterSchedule;
use crate::likelihood::{Key, NoiseEstimate, Request};
use crate::model::Model;

/// Length of the configured drive, s.
pub const QUIET_DURATION_S: f64 = 120.0;
/// W of the vibrating car, (m/s²)².
pub const VIBRATING_W_M2_S4: f64 = 0.4;
/// GPS rate of the vibrating car, Hz.
pub const VIBRATING_GPS_HZ: f64 = 10.0;
/// Length of the vibrating car's drive, s.
pub const VIBRATING_DURATION_S: f64 = 60.0;
/// The statistics estimated on both drives: the two GPS σ's and W.
pub const WHITE_NOISE_KEYS: [Key; 3] = [Key::GpsPosition, Key::GpsVelocity, Key::AccelNoiseVar];

/// One drive with W estimated.
#[derive(Clone, Debug)]
pub struct WhiteNoiseDrive {
    /// Length of the drive, s.
    pub duration_s: f64,
    /// GPS rate, Hz.
    pub gps_rate_hz: f64,
    /// The true W, (m/s²)².
    pub truth_w_m2_s4: f64,
    /// The estimate of [`WHITE_NOISE_KEYS`].
    pub estimate: NoiseEstimate,
}

impl WhiteNoiseDrive {
    /// W's estimate and interval.
    pub fn w(&self) -> &crate::likelihood::KeyEstimate {
        &self.estimate.keys[2]
    }
}

/// The two drives.
#[derive(Clone, Debug)]
pub struct WhiteNoiseDrives {
    /// The configured drive.
    pub quiet: WhiteNoiseDrive,
    /// The vibrating car.
    pub vibrating: WhiteNoiseDrive,
}

/// Drive 0 of `config` (euler truth, the filter at the truth's statistics) estimated with
/// [`WHITE_NOISE_KEYS`]; `None` when the configuration makes no model or no estimate.
fn one(config: &Config) -> Result<Option<WhiteNoiseDrive>, FilterError> {
    let Ok(model) = Model::new(config) else {
        return Ok(None);
    };
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    let request = Request {
        keys: WHITE_NOISE_KEYS.to_vec(),
        confidence: super::noise::NOISE_CONFIDENCE,
    };
    Ok(run_drive(&model, &schedule, 0, &request)
        .ok()
        .map(|estimate| WhiteNoiseDrive {
            duration_s: config.profile.duration_s,
            gps_rate_hz: config.gps.sample_rate_hz,
            truth_w_m2_s4: config.accelerometer.noise_var_m2_s4,
            estimate,
        }))
}

/// Runs both drives of `config`; `None` when either cannot be made.
///
/// # Errors
/// [`FilterError`] when a filter's covariance is not positive definite.
pub fn run(config: &Config) -> Result<Option<WhiteNoiseDrives>, FilterError> {
    let mut quiet = config.clone();
    quiet.profile.duration_s = QUIET_DURATION_S;
    quiet.ensemble.truth = TruthModel::Euler;
    quiet.checks.residual_pair_s = None;
    quiet.filter = Default::default();
    let mut car = quiet.clone();
    car.profile.duration_s = VIBRATING_DURATION_S;
    car.gps.sample_rate_hz = VIBRATING_GPS_HZ;
    car.accelerometer.noise_var_m2_s4 = VIBRATING_W_M2_S4;
    Ok(match (one(&quiet)?, one(&car)?) {
        (Some(quiet), Some(vibrating)) => Some(WhiteNoiseDrives { quiet, vibrating }),
        _ => None,
    })
}
