//! `calibrate --imu FILE --gnss FILE`: a whole IMU calibrated from a raw recording.

use std::io::{IsTerminal, Write};
use std::path::Path;

use anyhow::{Context, Result};

use crate::cli::CalibrateArgs;
use crate::cli::calibrate::EstimateKey;
use accelcal::calibrate::imu::config::settings_of;
use accelcal::calibrate::imu::noise::{self, ImuKey};
use accelcal::calibrate::imu::run::{Calibrated, ImuCalibrateError, calibrate_held, calibrate_of};
use accelcal::calibrate::imu::smoother::smooth;
use accelcal::calibrate::imu::summary::{Summary, summary, write_estimates};
use accelcal::calibrate::imu::{CONSUMER, Settings};
use accelcal::config::ConfigText;
use accelcal::error::ConfigError;
use accelcal::input::csv::read::{LogFile, LogSource};
use accelcal::input::gnss_csv::read_gnss;
use accelcal::input::imu_csv::read_steps;
use accelcal::output::{StagedFiles, check_directory};
use accelcal::with_layout;

/// The files the three-axis calibration writes.
const ESTIMATES_FILE: &str = "estimates.csv";
const SUMMARY_FILE: &str = "summary.json";
const PAGE_FILE: &str = "index.html";
/// Every file the calibration writes.
const FILES: [&str; 3] = [ESTIMATES_FILE, SUMMARY_FILE, PAGE_FILE];

/// The options of the one-axis calibration that the three-axis one does not take yet.
fn refuse_one_axis_options(args: &CalibrateArgs) -> Result<(), ConfigError> {
    let given = [("--every-sample", args.every_sample)];
    match given.iter().find(|(_, g)| *g) {
        Some((name, _)) => Err(ConfigError::invalid(
            name,
            "given with --imu",
            "an option of the one-axis calibration (--accel/--gps); the three-axis calibration \
             writes one row per fix",
        )),
        None => Ok(()),
    }
}

pub(super) fn run(args: &CalibrateArgs, imu: &Path, gnss: &Path) -> Result<()> {
    refuse_one_axis_options(args)?;
    let settings: Settings = match &args.config {
        Some(path) => settings_of(&ConfigText::read(path)?)?,
        None => CONSUMER,
    };
    if args.estimate_noise {
        noise::check_estimable(&settings)?;
    }
    check_directory(&args.out, &FILES)?;
    if !args.quiet && std::io::stderr().is_terminal() {
        eprintln!("checking the logs, aligning and running the filter…");
    }
    with_layout!(settings.layout(), N => run_with::<N>(args, (imu, gnss), &settings))
}

/// The calibration with a filter of `N` error states, its outputs written.
fn run_with<const N: usize>(
    args: &CalibrateArgs,
    (imu, gnss): (&Path, &Path),
    settings: &Settings,
) -> Result<()> {
    let (imu_log, gnss_log) = (LogFile::new(imu), LogFile::new(gnss));
    let (c, s) = if args.estimate_noise {
        with_noise::<N>(args, &imu_log, &gnss_log, settings)?
    } else {
        let c = calibrate_of::<N>(&imu_log, &gnss_log, settings).map_err(anyhow_of)?;
        let s = summary(&c, settings, &imu.display().to_string());
        (c, s)
    };
    write_outputs(args, (imu, gnss), &c, &s)
}

/// `estimates.csv`, `summary.json` and `index.html` of the calibration `c` summarized as `s`,
/// written together into `--out`, and the result's lines.
fn write_outputs<const N: usize>(
    args: &CalibrateArgs,
    (imu, gnss): (&Path, &Path),
    c: &Calibrated<N>,
    s: &Summary,
) -> Result<()> {
    let mut staged = StagedFiles::create(&args.out, &FILES)?;
    let into = |name: &str| format!("cannot write {}", args.out.join(name).display());
    let smoothed = smooth(&c.records);
    write_estimates(c, &smoothed, staged.writer(ESTIMATES_FILE))
        .with_context(|| into(ESTIMATES_FILE))?;
    let json = serde_json::to_string_pretty(s).expect("the summary serializes") + "\n";
    staged
        .writer(SUMMARY_FILE)
        .write_all(json.as_bytes())
        .with_context(|| into(SUMMARY_FILE))?;
    let page =
        accelcal::report::calibration_imu::render(c, s, &smoothed, &command(args, imu, gnss))?;
    staged
        .writer(PAGE_FILE)
        .write_all(page.as_bytes())
        .with_context(|| into(PAGE_FILE))?;
    staged.commit()?;
    print_result(s)
}

/// The keys `--estimate` names for the three-axis path, or its default ones.
fn imu_keys(args: &CalibrateArgs) -> Result<Vec<ImuKey>> {
    if args.estimate.is_empty() {
        return Ok(ImuKey::DEFAULT.to_vec());
    }
    args.estimate
        .iter()
        .map(|k| match k {
            EstimateKey::ThreeAxis(k) => Ok(*k),
            EstimateKey::OneAxis(k) => Err(anyhow::Error::new(super::logs::UsageError(format!(
                "--estimate {}: a statistic of the one-axis calibration (--accel/--gps); with \
                 --imu the keys are {}",
                k.name(),
                ImuKey::ALL.map(ImuKey::name).join(", ")
            )))),
        })
        .collect()
}

/// `--estimate-noise`: the logs held, the keys estimated, the recording calibrated with them.
fn with_noise<const N: usize>(
    args: &CalibrateArgs,
    imu: &LogFile,
    gnss: &LogFile,
    settings: &Settings,
) -> Result<(Calibrated<N>, Summary)> {
    let keys = imu_keys(args)?;
    let rows = read_gnss(gnss)?;
    let (steps, span, layout) = read_steps(imu, settings.axes)?;
    if !args.quiet && std::io::stderr().is_terminal() {
        eprintln!(
            "estimating {} by maximum likelihood…",
            keys.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
        );
    }
    let estimate = noise::estimate(&rows, &steps, &span, settings, &keys, args.confidence)
        .ok_or_else(|| {
            anyhow::Error::new(super::logs::UsageError(
                "the likelihood of the drive is not finite at the configured statistics: the \
                 filter cannot start from them"
                    .to_string(),
            ))
        })?;
    let c = calibrate_held(
        &rows,
        (&steps, span, layout),
        &estimate.settings,
        gnss.name(),
    )
    .map_err(anyhow_of)?;
    let mut s = summary(&c, &estimate.settings, imu.name());
    s.noise_estimate = Some(estimate);
    Ok((c, s))
}

/// The command line that reproduces the calibration.
fn command(args: &CalibrateArgs, imu: &Path, gnss: &Path) -> String {
    let config = args
        .config
        .as_ref()
        .map_or(String::new(), |c| format!(" --config {}", c.display()));
    let mut noise = String::new();
    if args.estimate_noise {
        noise.push_str(" --estimate-noise");
        if !args.estimate.is_empty() {
            let keys: Vec<&str> = args.estimate.iter().map(|k| k.name()).collect();
            noise.push_str(&format!(" --estimate {}", keys.join(",")));
        }
    }
    format!(
        "accelcal calibrate --imu {} --gnss {}{config}{noise} --out {}",
        imu.display(),
        gnss.display(),
        args.out.display()
    )
}

/// The error as the exit code reads it: a bad log or a recording that cannot be aligned is
/// the user's to fix.
fn anyhow_of(e: ImuCalibrateError) -> anyhow::Error {
    match e {
        ImuCalibrateError::Log(l) => l.into(),
        other => anyhow::Error::new(super::logs::UsageError(other.to_string())),
    }
}

/// The result on standard output, the warnings on standard error.
fn print_result(s: &Summary) -> Result<()> {
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    let triad = |name: &str, t: &accelcal::calibrate::imu::triad::Triad, unit: &str| {
        let parts: Vec<String> = (0..3)
            .map(|i| {
                let id = if t.identifiable[i] {
                    ""
                } else {
                    " (not determined)"
                };
                format!(
                    "{} {:+.5} ± {:.5}{id}",
                    ["x", "y", "z"][i],
                    t.value[i],
                    t.sigma[i]
                )
            })
            .collect();
        format!("{name} ({unit}): {}\n", parts.join(", "))
    };
    let a = &s.attitude_deg;
    let mut out = triad("gyro bias", &s.gyro_bias_rad_s, "rad/s");
    out += &triad("accelerometer bias", &s.accel_bias_m_s2, "m/s²");
    out += &format!(
        "attitude at the end: roll {:.2}° ± {:.2}, pitch {:.2}° ± {:.2}, yaw {:.2}° ± {:.2}{}\n",
        a.roll,
        a.sigma_roll,
        a.pitch,
        a.sigma_pitch,
        a.yaw,
        a.sigma_yaw,
        if a.yaw_identifiable {
            ""
        } else {
            " (yaw not determined beyond the course)"
        }
    );
    out += &format!(
        "NIS: sum {:.1} over {} fixes, band [{:.1}, {:.1}] at α = {}: {}\n",
        s.nis.sum, s.nis.fixes, s.nis.lower, s.nis.upper, s.nis.false_alarm_rate, s.nis.verdict
    );
    if s.intervals_conditional {
        out += &format!(
            "the σ's assume a model that {} reject(s)\n",
            s.rejected_by.join(", ")
        );
    }
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(out.as_bytes())
        .map_err(|e| anyhow::Error::new(super::StdoutError(e)))
}
