//! A real drive in three axes: the minute of comma2k19 shipped in `examples/comma2k19_3d/` (six
//! raw IMU channels, the u-blox fixes), calibrated as `calibrate --imu --gnss` calibrates it
//! with no configuration, then with noise statistics estimated from the drive; the attitude of
//! each against comma's own pose (`reference.csv`) at every fix.
//!
//! The files are compiled into the program, so the report's numbers always come from running
//! the calibration on the shipped files, wherever the program runs.

use thiserror::Error;

use crate::calibrate::imu::noise::{self, ImuKey};
use crate::calibrate::imu::run::{Calibrated, ImuCalibrateError, calibrate_held, euler_sigmas};
use crate::calibrate::imu::smoother::{Smoothed, smooth};
use crate::calibrate::imu::summary::{Summary, summary};
use crate::calibrate::imu::triad::CONFIDENCE;
use crate::calibrate::imu::{CONSUMER, Settings};
use crate::input::LogError;
use crate::input::csv::read::LogText;
use crate::input::gnss_csv::read_gnss;
use crate::input::imu_csv::read_steps;
use crate::ins::error_state::Matrix15;
use crate::ins::euler_of;
use crate::ins::mech::Pva;

/// The shipped IMU log (`t_s` and the six rates, forward-right-down).
pub const IMU: &[u8] = include_bytes!("../../examples/comma2k19_3d/imu.csv");
/// The shipped GNSS log.
pub const GNSS: &[u8] = include_bytes!("../../examples/comma2k19_3d/gnss.csv");
/// comma's pose at 20 Hz: `t_s,…,roll_deg,pitch_deg,yaw_deg`.
pub const REFERENCE: &[u8] = include_bytes!("../../examples/comma2k19_3d/reference.csv");
/// Android's own gyro bias estimate over the segment, one row `gx_rad_s,gy_rad_s,gz_rad_s`.
pub const ANDROID_GYRO_BIAS: &[u8] =
    include_bytes!("../../examples/comma2k19_3d/android_gyro_bias.csv");
/// The directory the files are shipped in, as the report names it.
pub const DRIVE_DIR: &str = "examples/comma2k19_3d";

/// The keys the report estimates from the drive: the command's default, [`ImuKey::DEFAULT`].
pub const REPORT_KEYS: &[ImuKey] = &ImuKey::DEFAULT;

/// Why the shipped minute could not be calibrated (not for the shipped files).
#[derive(Debug, Error)]
pub enum Drive3dError {
    /// The calibration failed.
    #[error(transparent)]
    Calibrate(#[from] ImuCalibrateError),
    /// A log could not be read.
    #[error(transparent)]
    Log(#[from] LogError),
    /// A shipped reference file is malformed.
    #[error("{file}, line {line}: {reason}")]
    Shipped {
        /// The file.
        file: &'static str,
        /// Its line, from 1.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The likelihood is not finite at the consumer defaults.
    #[error("the likelihood of the shipped minute is not finite at the consumer defaults")]
    Likelihood,
}

/// comma's attitude at one instant, °.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Time, s (the IMU log's time base).
    pub t_s: f64,
    /// Roll, pitch and yaw (ZYX Euler angles of body FRD against NED), °.
    pub euler_deg: [f64; 3],
}

/// The filter's attitude against the reference at every fix the reference spans.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AttitudeComparison {
    /// The fixes' times, s.
    pub t_s: Vec<f64>,
    /// Filtered roll, pitch, yaw minus the reference's, ° (the yaw's difference within ±180°).
    pub filtered: Vec<[f64; 3]>,
    /// The filter's σ of each, °.
    pub filtered_sigma: Vec<[f64; 3]>,
    /// Smoothed minus the reference, °.
    pub smoothed: Vec<[f64; 3]>,
    /// The smoothed σ of each, °.
    pub smoothed_sigma: Vec<[f64; 3]>,
    /// The reference at the last compared fix, °.
    pub reference_end_deg: [f64; 3],
}

/// One calibration of the minute.
#[derive(Clone, Debug)]
pub struct Run3d {
    /// The filter's records and the alignment.
    pub calibrated: Calibrated,
    /// `summary.json` (with the noise estimate when one was made).
    pub summary: Summary,
    /// The smoothed solution at every fix.
    pub smoothed: Vec<Smoothed>,
    /// The attitude against comma's pose.
    pub attitude: AttitudeComparison,
}

/// The section's calibrations of the minute and the references they are read against.
#[derive(Clone, Debug)]
pub struct RealDrive3d {
    /// With no configuration (the consumer defaults, [`CONSUMER`]).
    pub plain: Run3d,
    /// With [`REPORT_KEYS`] estimated by maximum likelihood, the rest as `plain`.
    pub estimated: Run3d,
    /// comma's pose.
    pub reference: Vec<Pose>,
    /// Android's gyro bias estimate, rad/s.
    pub android_gyro_bias_rad_s: [f64; 3],
}

/// `x` wrapped into (−180°, 180°].
fn wrapped_deg(x: f64) -> f64 {
    let y = x - 360.0 * (x / 360.0).round();
    if y <= -180.0 { y + 360.0 } else { y }
}

/// The numbers of a CSV text's data rows (after the header), each row's `columns` cells.
fn rows(text: &[u8], file: &'static str, columns: usize) -> Result<Vec<Vec<f64>>, Drive3dError> {
    let bad = |line: usize, reason: String| Drive3dError::Shipped { file, line, reason };
    let text = std::str::from_utf8(text).map_err(|e| bad(1, e.to_string()))?;
    text.lines()
        .enumerate()
        .skip(1)
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let cells: Vec<f64> = l
                .split(',')
                .map(|c| c.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| bad(i + 1, e.to_string()))?;
            if cells.len() == columns {
                Ok(cells)
            } else {
                Err(bad(
                    i + 1,
                    format!("{} cells, {columns} expected", cells.len()),
                ))
            }
        })
        .collect()
}

/// comma's pose as shipped, in time order.
///
/// # Errors
/// [`Drive3dError::Shipped`] when a row is malformed.
pub fn reference() -> Result<Vec<Pose>, Drive3dError> {
    Ok(rows(REFERENCE, "reference.csv", 10)?
        .into_iter()
        .map(|r| Pose {
            t_s: r[0],
            euler_deg: [r[7], r[8], r[9]],
        })
        .collect())
}

/// Android's gyro bias estimate as shipped, rad/s.
///
/// # Errors
/// [`Drive3dError::Shipped`] when the file does not hold one row of three numbers.
pub fn android_gyro_bias() -> Result<[f64; 3], Drive3dError> {
    match rows(ANDROID_GYRO_BIAS, "android_gyro_bias.csv", 3)?.as_slice() {
        [r] => Ok([r[0], r[1], r[2]]),
        other => Err(Drive3dError::Shipped {
            file: "android_gyro_bias.csv",
            line: 2,
            reason: format!("{} rows, one expected", other.len()),
        }),
    }
}

/// The reference's attitude at `t_s`, linear between its two neighbours (the yaw along the
/// shorter arc); `None` outside its span.
pub fn reference_at(reference: &[Pose], t_s: f64) -> Option<[f64; 3]> {
    let i = reference.partition_point(|p| p.t_s <= t_s);
    if i == 0 || i == reference.len() && reference[i - 1].t_s < t_s {
        return None;
    }
    let a = &reference[i - 1];
    let Some(b) = reference.get(i) else {
        return Some(a.euler_deg);
    };
    let w = (t_s - a.t_s) / (b.t_s - a.t_s);
    Some([0, 1, 2].map(|k| {
        let step = if k == 2 {
            wrapped_deg(b.euler_deg[k] - a.euler_deg[k])
        } else {
            b.euler_deg[k] - a.euler_deg[k]
        };
        a.euler_deg[k] + w * step
    }))
}

/// Roll, pitch and yaw of `pva` with their σ's from `p`, °.
fn euler_deg(pva: &Pva, p: &Matrix15) -> ([f64; 3], [f64; 3]) {
    let (r, q, y) = euler_of(&pva.attitude);
    (
        [r, q, y].map(f64::to_degrees),
        euler_sigmas(pva, p).map(f64::to_degrees),
    )
}

/// The filtered and smoothed attitude of `c` against `reference` at every fix it spans.
pub fn compare(c: &Calibrated, smoothed: &[Smoothed], reference: &[Pose]) -> AttitudeComparison {
    let mut out = AttitudeComparison::default();
    for (f, s) in c.records.iter().zip(smoothed) {
        let Some(r) = reference_at(reference, f.t_s) else {
            continue;
        };
        let minus = |x: [f64; 3]| [0, 1, 2].map(|k| wrapped_deg(x[k] - r[k]));
        let (fe, fs) = euler_deg(&f.pva, &f.covariance);
        let (se, ss) = euler_deg(&s.pva, &s.covariance);
        out.t_s.push(f.t_s);
        out.filtered.push(minus(fe));
        out.filtered_sigma.push(fs);
        out.smoothed.push(minus(se));
        out.smoothed_sigma.push(ss);
        out.reference_end_deg = r;
    }
    out
}

/// The calibration of the held logs with `s`, its summary, smoothed solution and comparison.
fn run_with(
    held: (&[crate::input::records::GnssRow], &Held),
    s: &Settings,
    reference: &[Pose],
    estimate: Option<noise::NoiseEstimate>,
) -> Result<Run3d, Drive3dError> {
    let (rows, (steps, span, layout)) = held;
    let gnss = format!("{DRIVE_DIR}/gnss.csv");
    let calibrated = calibrate_held(rows, (steps, *span, *layout), s, &gnss)?;
    let mut summary = summary(&calibrated, s, &format!("{DRIVE_DIR}/imu.csv"));
    summary.noise_estimate = estimate;
    let smoothed = smooth(&calibrated.records);
    let attitude = compare(&calibrated, &smoothed, reference);
    Ok(Run3d {
        calibrated,
        summary,
        smoothed,
        attitude,
    })
}

type Held = (
    Vec<crate::input::records::ImuStep>,
    crate::input::imu_csv::ImuSpan,
    crate::input::imu_csv::ImuLayout,
);

/// The minute calibrated with no configuration and with [`REPORT_KEYS`] estimated.
///
/// # Errors
/// [`Drive3dError`] only if the shipped files did not calibrate.
pub fn run() -> Result<RealDrive3d, Drive3dError> {
    let imu = LogText::new(&format!("{DRIVE_DIR}/imu.csv"), IMU);
    let gnss = LogText::new(&format!("{DRIVE_DIR}/gnss.csv"), GNSS);
    let rows = read_gnss(&gnss)?;
    let held: Held = read_steps(&imu, CONSUMER.axes)?;
    let reference = reference()?;
    let plain = run_with((&rows, &held), &CONSUMER, &reference, None)?;
    let found = noise::estimate(&rows, &held.0, &held.1, &CONSUMER, REPORT_KEYS, CONFIDENCE)
        .ok_or(Drive3dError::Likelihood)?;
    let settings = found.settings;
    let estimated = run_with((&rows, &held), &settings, &reference, Some(found))?;
    Ok(RealDrive3d {
        plain,
        estimated,
        reference,
        android_gyro_bias_rad_s: android_gyro_bias()?,
    })
}
