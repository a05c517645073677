//! The three-axis study for the report: the default drive, one realization's biases and attitude
//! errors against the truth, an ensemble judged by the check catalogue on each realization's own
//! covariance, and negative controls — filters that are wrong in a known way — judged the same.

use crate::checks::{Budget, Verdicts, evaluate};
use crate::config::ins::InsConfig;
use crate::ins::ensemble::{self, Calibration, RealizationError, Track, filter_realization};
use crate::ins::error_state::{ACCEL_BIAS, ATTITUDE, GYRO_BIAS, STATES, STATES_WITH_SCALE};
use crate::ins::gnss::ned_difference_m;
use crate::ins::setup::Scenario;
use crate::progress::Progress;

/// Realizations of each ensemble in the report.
pub const REPORT_REALIZATIONS: u64 = 100;

/// A filter wrong in a known way, and what the checks said of it.
#[derive(Clone, Debug)]
pub struct Control {
    /// What is wrong, in words ("assumes half the gyro ARW").
    pub what: &'static str,
    /// The checks' verdicts on its ensemble.
    pub verdicts: Verdicts,
    /// The fixes' times, s (for the members' words).
    pub times_s: Vec<f64>,
}

/// One realization at every fix: the six biases' estimates with their σ and truth, and the
/// attitude errors with their σ, after the update.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// The fixes' times, s.
    pub t_s: Vec<f64>,
    /// Gyro x, y, z (rad/s) then accelerometer x, y, z (m/s²) bias estimates.
    pub bias: Vec<[f64; 6]>,
    /// Their σ's.
    pub bias_sigma: Vec<[f64; 6]>,
    /// The true biases.
    pub bias_truth: Vec<[f64; 6]>,
    /// Attitude errors about north, east, down, rad.
    pub attitude_error: Vec<[f64; 3]>,
    /// Their σ's.
    pub attitude_sigma: Vec<[f64; 3]>,
}

/// The three-axis section's results.
#[derive(Clone, Debug)]
pub struct InsResults {
    /// Its configuration (the default three-axis file).
    pub config: InsConfig,
    /// Realizations of each ensemble.
    pub realizations: u64,
    /// The track every second: north, east (m from the start) and height (m).
    pub track: Vec<[f64; 4]>,
    /// Realization 0.
    pub trace: Trace,
    /// The consistent filter's verdicts.
    pub verdicts: Verdicts,
    /// The fixes' times, s.
    pub times_s: Vec<f64>,
    /// The calibration at the end of the drive.
    pub calibration: Calibration,
    /// The filter of 21 states on sensors with [`SCALE_PPM`] scale factors.
    pub scaled: Control,
    /// The negative controls.
    pub controls: Vec<Control>,
}

/// The scale factors' σ of the sensors the 21-state filter and the control that leaves them out
/// run on, ppm.
pub const SCALE_PPM: f64 = 1000.0;

/// `s` with sensors whose scale factors have σ [`SCALE_PPM`] (the filter assuming the same prior).
fn with_scale_factors(s: &mut Scenario) {
    for imu in [&mut s.truth_imu, &mut s.filter_imu] {
        imu.gyro_scale_sigma = SCALE_PPM * 1e-6;
        imu.accel_scale_sigma = SCALE_PPM * 1e-6;
    }
}

/// The verdicts and calibration of `realizations` realizations of `scenario`'s 15-state filter.
fn judged(
    scenario: &Scenario,
    track: &Track,
    realizations: u64,
    progress: &mut dyn Progress,
    label: &str,
) -> Result<(Verdicts, Calibration, Vec<f64>), RealizationError> {
    judged_of::<STATES>(scenario, track, realizations, progress, label)
}

/// [`judged`] with a filter of `N` error states.
fn judged_of<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    realizations: u64,
    progress: &mut dyn Progress,
    label: &str,
) -> Result<(Verdicts, Calibration<N>, Vec<f64>), RealizationError> {
    progress.start(label, realizations);
    let sums = ensemble::sums::<N>(scenario, track, realizations, |done| progress.advance(done))?;
    progress.finish();
    let outcome = sums.outcome(scenario);
    let verdicts = evaluate(&outcome.stats, &Budget::study(scenario.false_alarm_rate));
    Ok((verdicts, outcome.calibration, sums.normalized.times_s))
}

/// Realization 0 of `scenario`, every fix.
fn trace(scenario: &Scenario, track: &Track) -> Result<Trace, RealizationError> {
    let mut t = Trace::default();
    filter_realization::<STATES>(scenario, track, 0, |v| {
        let p = &v.ekf.covariance;
        let sigma = |k: usize| p[(k, k)].sqrt();
        let (g, a) = (v.ekf.gyro_bias_rad_s, v.ekf.accel_bias_m_s2);
        let (tg, ta) = (v.imu.gyro_bias_rad_s, v.imu.accel_bias_m_s2);
        t.t_s.push(v.t_s);
        t.bias.push([g.x, g.y, g.z, a.x, a.y, a.z]);
        t.bias_truth.push([tg.x, tg.y, tg.z, ta.x, ta.y, ta.z]);
        t.bias_sigma.push(std::array::from_fn(|i| {
            sigma(if i < 3 {
                GYRO_BIAS + i
            } else {
                ACCEL_BIAS + i - 3
            })
        }));
        let e = &v.input.post.error;
        t.attitude_error
            .push(std::array::from_fn(|i| e[ATTITUDE + i]));
        t.attitude_sigma
            .push(std::array::from_fn(|i| sigma(ATTITUDE + i)));
        Ok(())
    })?;
    Ok(t)
}

/// The default drive every second: north, east from the start and height, m, at time t.
fn track_every_second(scenario: &Scenario, track: &Track) -> Vec<[f64; 4]> {
    let per_s = scenario.imu_rate_hz.round() as usize;
    let start = &track.start.position;
    std::iter::once((0, &track.start))
        .chain(track.steps.iter().enumerate().map(|(k, s)| (k + 1, &s.1)))
        .filter(|(k, _)| k % per_s == 0)
        .map(|(k, pva)| {
            let d = ned_difference_m(&pva.position, start);
            [
                k as f64 / scenario.imu_rate_hz,
                d.x,
                d.y,
                pva.position.height_m,
            ]
        })
        .collect()
}

/// A negative control: what is wrong, and the edit of the scenario that makes it so.
pub type ControlEdit = (&'static str, fn(&mut Scenario));

/// The negative controls: each edit of the default scenario and what it makes wrong.
pub const CONTROLS: [ControlEdit; 5] = [
    ("assumes half the gyros' angle random walk", |s| {
        s.filter_imu.gyro_arw_rad_per_sqrt_s /= 2.0;
    }),
    ("leaves the antenna's lever arm out", |s| {
        s.filter_gnss.lever_arm_b_m = nalgebra::Vector3::zeros();
    }),
    (
        "leaves the Earth's rotation out of its mechanization",
        |s| {
            s.filter_earth_rotation_rad_s = 0.0;
        },
    ),
    ("starts with a 30° heading σ", |s| {
        s.initial_sigma[8] = 30f64.to_radians();
    }),
    (
        "leaves out the sensors' scale factors of 1 000 ppm (15 states)",
        with_scale_factors,
    ),
];

/// Runs the three-axis study of `config` with `realizations` per ensemble.
///
/// # Errors
/// [`RealizationError`] when a filter's covariance stops being positive definite.
pub fn run(
    config: &InsConfig,
    realizations: u64,
    progress: &mut dyn Progress,
) -> Result<InsResults, RealizationError> {
    let scenario = Scenario::from_config(config).expect("a valid three-axis configuration");
    let track = Track::of(&scenario);
    let (verdicts, calibration, times_s) =
        judged(&scenario, &track, realizations, progress, "3-axis")?;
    let mut s = scenario.clone();
    with_scale_factors(&mut s);
    let (v, _, t) =
        judged_of::<STATES_WITH_SCALE>(&s, &track, realizations, progress, "21 states")?;
    let scaled = Control {
        what: "estimates the sensors' scale factors of 1 000 ppm (21 states)",
        verdicts: v,
        times_s: t,
    };
    let mut controls = Vec::new();
    for (what, edit) in CONTROLS {
        let mut s = scenario.clone();
        edit(&mut s);
        let (verdicts, _, times_s) = judged(&s, &track, realizations, progress, "control")?;
        controls.push(Control {
            what,
            verdicts,
            times_s,
        });
    }
    Ok(InsResults {
        config: config.clone(),
        realizations,
        track: track_every_second(&scenario, &track),
        trace: trace(&scenario, &track)?,
        verdicts,
        times_s,
        calibration,
        scaled,
        controls,
    })
}
