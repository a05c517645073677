//! What a three-axis calibration reports: `summary.json` (the six biases and the attitude at the
//! end with σ's, 95 % intervals and whether the drive determined them; the NIS test; the
//! innovations' whiteness per component; the alignment; every assumption) and `estimates.csv`
//! (one row per fix).

use std::io::{self, Write};

use serde::Serialize;

use super::Settings;
use super::gate::GateRecord;
use super::noise::NoiseEstimate;
use super::run::{Calibrated, FixRecord, bias_sigmas, euler_sigmas};
use super::smoother::Smoothed;
use super::triad::{IDENTIFIABLE_SIGMA_RATIO, Triad, triad};
use crate::calibrate::diagnose::whiteness::{Whiteness, whiteness};
use crate::calibrate::{NisTest, nis_test_rows};
use crate::ins::euler_of;

/// The attitude at the end, degrees.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attitude {
    /// Roll, °.
    pub roll: f64,
    /// Pitch, °.
    pub pitch: f64,
    /// Yaw, °.
    pub yaw: f64,
    /// σ of roll, °.
    pub sigma_roll: f64,
    /// σ of pitch, °.
    pub sigma_pitch: f64,
    /// σ of yaw, °.
    pub sigma_yaw: f64,
    /// Whether the drive determined the yaw beyond the alignment's course.
    pub yaw_identifiable: bool,
}

/// The alignment as the summary tells it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AlignmentRecord {
    /// The fix the filter starts at, s.
    pub t_s: f64,
    /// The window's first fix, s.
    pub window_start_s: f64,
    /// The horizontal speed there, m/s.
    pub speed_m_s: f64,
    /// Roll, pitch and yaw at the start, °.
    pub roll_deg: f64,
    /// Pitch at the start, °.
    pub pitch_deg: f64,
    /// Yaw at the start (the course), °.
    pub yaw_deg: f64,
    /// Their prior σ's, °.
    pub sigma_roll_deg: f64,
    /// σ of pitch, °.
    pub sigma_pitch_deg: f64,
    /// σ of yaw, °.
    pub sigma_yaw_deg: f64,
    /// IMU rows before the start, which the filter does not use.
    pub rows_before: u64,
}

/// One innovation component's whiteness test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ComponentWhiteness {
    /// The component, e.g. `position_north`.
    pub component: &'static str,
    /// The fixes that measured it.
    pub fixes: usize,
    /// The test.
    #[serde(flatten)]
    pub test: Whiteness,
}

/// The fixes left out for lying outside the IMU log.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FixesOutsideLog {
    /// Before its first sample.
    pub before: usize,
    /// After its last.
    pub after: usize,
}

/// `summary.json` of a three-axis calibration.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// `"ins"`: the three-axis calibration.
    pub model: &'static str,
    /// The IMU log, as named.
    pub imu_file: String,
    /// The GNSS log, as named.
    pub gnss_file: String,
    /// What the IMU rows hold.
    pub imu_layout: crate::input::imu_csv::ImuLayout,
    /// IMU rows.
    pub imu_rows: u64,
    /// The median IMU step's rate, Hz.
    pub imu_rate_hz: f64,
    /// Fixes in the GNSS log.
    pub fixes: usize,
    /// Fixes the filter used (after the alignment's).
    pub fixes_used: usize,
    /// Fixes left out for lying outside the IMU log: before its first sample, after its last.
    pub fixes_outside_log: FixesOutsideLog,
    /// The alignment.
    pub alignment: AlignmentRecord,
    /// The gyro biases at the end, rad/s.
    pub gyro_bias_rad_s: Triad,
    /// The accelerometer biases at the end, m/s².
    pub accel_bias_m_s2: Triad,
    /// The gyro scale factors at the end, ppm, when estimated (`error_states` = 21).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gyro_scale_factor_ppm: Option<Triad>,
    /// The accelerometer scale factors at the end, ppm, when estimated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel_scale_factor_ppm: Option<Triad>,
    /// The attitude at the end.
    pub attitude_deg: Attitude,
    /// The NIS test over the fixes the filter took.
    pub nis: NisTest,
    /// What the χ² innovation gate did.
    pub gate: GateRecord,
    /// Whiteness of each innovation component's normalized sequence.
    pub whiteness: Vec<ComponentWhiteness>,
    /// Whether the intervals rest on a model a test rejects.
    pub intervals_conditional: bool,
    /// The tests that reject it.
    pub rejected_by: Vec<String>,
    /// What the reader should know.
    pub warnings: Vec<String>,
    /// Every assumption made (with `--estimate-noise`, the estimates in place).
    pub assumptions: Settings,
    /// The statistics estimated from the drive (`--estimate-noise`), or `null`.
    pub noise_estimate: Option<NoiseEstimate>,
}

pub use super::step::COMPONENTS;

/// The σ a bias would have at `t` s after the start from its prior and its process alone.
fn prior_sigma(sigma0: f64, k: f64, tau: Option<f64>, t: f64) -> f64 {
    match tau {
        Some(_) => sigma0,
        None => (sigma0 * sigma0 + k * k * t).sqrt(),
    }
}

/// The summary of `c` calibrated with `s`, the IMU log named `imu_file`.
pub fn summary<const N: usize>(c: &Calibrated<N>, s: &Settings, imu_file: &str) -> Summary {
    let last = c.records.last();
    let elapsed = last.map_or(0.0, |r| r.t_s - c.start_s);
    let (gyro, accel, attitude) = match last {
        Some(r) => end_estimates(r, c, s, elapsed),
        None => (
            triad([f64::NAN; 3], [f64::NAN; 3], [1.0; 3]),
            triad([f64::NAN; 3], [f64::NAN; 3], [1.0; 3]),
            Attitude {
                roll: f64::NAN,
                pitch: f64::NAN,
                yaw: f64::NAN,
                sigma_roll: f64::NAN,
                sigma_pitch: f64::NAN,
                sigma_yaw: f64::NAN,
                yaw_identifiable: false,
            },
        ),
    };
    let (gyro_scale, accel_scale) = super::scale::end_triads(last, s).unzip();
    let (nis, whiteness, rejected_by) = tests(c, s);
    let alignment = alignment_record(c);
    let mut warnings: Vec<String> = c.outside_log.warning().into_iter().collect();
    if !attitude.yaw_identifiable {
        warnings.push(format!(
            "the yaw is not determined beyond the alignment's course: its σ at the end, {:.2}°, \
             is more than {IDENTIFIABLE_SIGMA_RATIO} of the alignment's {:.2}° (the drive's turns \
             and speed changes, if any, did not tell the heading better than the gyros' noise \
             lets it drift)",
            attitude.sigma_yaw,
            c.alignment.covariance[(8, 8)].sqrt().to_degrees()
        ));
    }
    warnings.extend(super::scale::warnings(
        gyro_scale.as_ref(),
        accel_scale.as_ref(),
    ));
    if c.missing_velocity[2] > 0 {
        warnings.push(format!(
            "{} of {} fixes have no vertical velocity: only their position and horizontal \
             velocity are used",
            c.missing_velocity[2], c.fixes
        ));
    }
    Summary {
        model: "ins",
        imu_file: imu_file.to_string(),
        gnss_file: c.gnss_file.clone(),
        imu_layout: c.layout,
        imu_rows: c.span.rows,
        imu_rate_hz: 1.0 / c.span.median_step_s,
        fixes: c.fixes,
        fixes_used: c.records.iter().filter(|r| r.accepted).count(),
        fixes_outside_log: FixesOutsideLog {
            before: c.outside_log.before,
            after: c.outside_log.after,
        },
        alignment,
        gyro_bias_rad_s: gyro,
        accel_bias_m_s2: accel,
        gyro_scale_factor_ppm: gyro_scale,
        accel_scale_factor_ppm: accel_scale,
        attitude_deg: attitude,
        intervals_conditional: !rejected_by.is_empty(),
        nis,
        gate: super::gate::record(&c.records, s),
        whiteness,
        rejected_by,
        warnings,
        assumptions: *s,
        noise_estimate: None,
    }
}

/// The NIS test, each component's whiteness, and the tests that reject the model.
fn tests<const N: usize>(
    c: &Calibrated<N>,
    s: &Settings,
) -> (NisTest, Vec<ComponentWhiteness>, Vec<String>) {
    let taken = || c.records.iter().filter(|r| r.accepted);
    let nis: Vec<f64> = taken().map(|r| r.nis).collect();
    let rows: Vec<usize> = taken().map(|r| r.rows).collect();
    let nis = nis_test_rows(&nis, &rows, s.false_alarm_rate);
    let whiteness: Vec<ComponentWhiteness> = (0..6)
        .filter_map(|i| {
            let u: Vec<f64> = taken()
                .filter(|r| r.innovation[i].is_finite())
                .map(|r| r.innovation[i] / r.innovation_sigma[i])
                .collect();
            (!u.is_empty()).then(|| ComponentWhiteness {
                component: COMPONENTS[i],
                fixes: u.len(),
                test: whiteness(&u, s.false_alarm_rate),
            })
        })
        .collect();
    let mut rejected_by = Vec::new();
    if nis.verdict == "fail" {
        rejected_by.push("nis".to_string());
    }
    for w in &whiteness {
        if w.test.verdict == "fail" {
            rejected_by.push(format!("whiteness_{}", w.component));
        }
    }
    (nis, whiteness, rejected_by)
}

/// The alignment as the summary tells it.
fn alignment_record<const N: usize>(c: &Calibrated<N>) -> AlignmentRecord {
    let a = &c.alignment;
    let deg = f64::to_degrees;
    let p = &a.covariance;
    let sig = |i: usize| deg(p[(6 + i, 6 + i)].sqrt());
    AlignmentRecord {
        t_s: c.start_s,
        window_start_s: c.start_s - a.window_s,
        speed_m_s: a.speed_m_s,
        roll_deg: deg(a.euler_rad[0]),
        pitch_deg: deg(a.euler_rad[1]),
        yaw_deg: deg(a.euler_rad[2]),
        sigma_roll_deg: sig(0),
        sigma_pitch_deg: sig(1),
        sigma_yaw_deg: sig(2),
        rows_before: 0,
    }
}

/// The biases and the attitude of the last record `r`.
fn end_estimates<const N: usize>(
    r: &FixRecord<N>,
    c: &Calibrated<N>,
    s: &Settings,
    t: f64,
) -> (Triad, Triad, Attitude) {
    let (sg, sa) = bias_sigmas(&r.covariance);
    let pg = prior_sigma(
        s.gyro_bias_sigma_rad_s,
        s.gyro_bias_random_walk_rad_s_per_sqrt_s,
        s.gyro_bias_correlation_time_s,
        t,
    );
    let pa = prior_sigma(
        s.accel_bias_sigma_m_s2,
        s.accel_bias_random_walk_m_s2_per_sqrt_s,
        s.accel_bias_correlation_time_s,
        t,
    );
    let (roll, pitch, yaw) = euler_of(&r.pva.attitude);
    let [s_roll, s_pitch, s_yaw] = euler_sigmas(&r.pva, &r.covariance);
    // The yaw is determined beyond the course the alignment took it from when its σ at the end
    // is at most half the alignment's.
    let yaw_prior = c.alignment.covariance[(8, 8)].sqrt();
    let deg = f64::to_degrees;
    (
        triad(r.gyro_bias_rad_s.into(), sg, [pg; 3]),
        triad(r.accel_bias_m_s2.into(), sa, [pa; 3]),
        Attitude {
            roll: deg(roll),
            pitch: deg(pitch),
            yaw: deg(yaw),
            sigma_roll: deg(s_roll),
            sigma_pitch: deg(s_pitch),
            sigma_yaw: deg(s_yaw),
            yaw_identifiable: s_yaw <= IDENTIFIABLE_SIGMA_RATIO * yaw_prior,
        },
    )
}

/// The header of `estimates.csv`.
pub const ESTIMATES_HEADER: &str = "t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s,roll_deg,\
pitch_deg,yaw_deg,bgx_rad_s,bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2,sigma_n_m,sigma_e_m,\
sigma_d_m,sigma_vn_m_s,sigma_ve_m_s,sigma_vd_m_s,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,\
sigma_bgx_rad_s,sigma_bgy_rad_s,sigma_bgz_rad_s,sigma_bax_m_s2,sigma_bay_m_s2,sigma_baz_m_s2,\
nu_n_m,nu_e_m,nu_d_m,nu_vn_m_s,nu_ve_m_s,nu_vd_m_s,sqrt_s_n_m,sqrt_s_e_m,sqrt_s_d_m,\
sqrt_s_vn_m_s,sqrt_s_ve_m_s,sqrt_s_vd_m_s,nis,nis_dof,smoothed_roll_deg,smoothed_pitch_deg,\
smoothed_yaw_deg,smoothed_bgx_rad_s,smoothed_bgy_rad_s,smoothed_bgz_rad_s,smoothed_bax_m_s2,\
smoothed_bay_m_s2,smoothed_baz_m_s2,smoothed_sigma_roll_deg,smoothed_sigma_pitch_deg,\
smoothed_sigma_yaw_deg,smoothed_sigma_bgx_rad_s,smoothed_sigma_bgy_rad_s,smoothed_sigma_bgz_rad_s,\
smoothed_sigma_bax_m_s2,smoothed_sigma_bay_m_s2,smoothed_sigma_baz_m_s2";

/// `estimates.csv`: one row per fix (the filtered estimates after its update, their σ's, the
/// innovation, √S and the NIS, `nan` where a component was not measured; then the smoothed
/// attitude and biases with their σ's).
///
/// # Errors
/// The writer's.
pub fn write_estimates<const N: usize>(
    c: &Calibrated<N>,
    smoothed: &[Smoothed<N>],
    out: &mut impl Write,
) -> io::Result<()> {
    writeln!(out, "{ESTIMATES_HEADER}{}", super::scale::header::<N>())?;
    for (r, sm) in c.records.iter().zip(smoothed) {
        let p = &r.pva.position;
        let v = r.pva.velocity_ned_m_s;
        let (roll, pitch, yaw) = euler_of(&r.pva.attitude);
        let [sr, sp, sy] = euler_sigmas(&r.pva, &r.covariance);
        let (sg, sa) = bias_sigmas(&r.covariance);
        let cov = &r.covariance;
        let mut row = vec![
            r.t_s,
            p.lat_rad.to_degrees(),
            p.lon_rad.to_degrees(),
            p.height_m,
            v.x,
            v.y,
            v.z,
            roll.to_degrees(),
            pitch.to_degrees(),
            yaw.to_degrees(),
        ];
        row.extend(r.gyro_bias_rad_s.iter());
        row.extend(r.accel_bias_m_s2.iter());
        row.extend((0..6).map(|i| cov[(i, i)].max(0.0).sqrt()));
        row.extend([sr, sp, sy].map(f64::to_degrees));
        row.extend(sg);
        row.extend(sa);
        row.extend(r.innovation);
        row.extend(r.innovation_sigma);
        row.push(r.nis);
        row.push(r.rows as f64);
        let (roll, pitch, yaw) = euler_of(&sm.pva.attitude);
        row.extend([roll, pitch, yaw].map(f64::to_degrees));
        row.extend(sm.gyro_bias_rad_s.iter());
        row.extend(sm.accel_bias_m_s2.iter());
        let [sr, sp, sy] = euler_sigmas(&sm.pva, &sm.covariance);
        row.extend([sr, sp, sy].map(f64::to_degrees));
        let (sg, sa) = bias_sigmas(&sm.covariance);
        row.extend(sg);
        row.extend(sa);
        super::scale::extend_row(&mut row, sm);
        let mut line = String::new();
        crate::input::csv::text::push_row(&mut line, &row);
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}
