//! The commands of sensor logs: simulate a realization (its CSV, its logs) and calibrate from
//! recorded logs.

use std::io::IsTerminal;
use std::path::Path;

use std::io::Write as _;

use super::{load_model, write};
use crate::cli::calibrate::EstimateKey;
use crate::cli::{CalibrateArgs, SimulateArgs};
use accelcal::calibrate::CalibrateError;
use accelcal::calibrate::{self, Settings};
use accelcal::config::{Config, ConfigText};
use accelcal::error::ConfigError;
use accelcal::filter::FilterSchedule;
use accelcal::format::{count, interval, interval_digits, sig};
use accelcal::input::csv::read::{LogFile, LogSource};
use accelcal::input::{LogError, LogProblem};
use accelcal::likelihood::{NoiseEstimate, Request};
use accelcal::logs::write::LogWriter;
use accelcal::logs::{ACCEL_FILE, GPS_FILE, TRUTH_FILE};
use accelcal::model::Model;
use accelcal::output::{StagedFiles, check_directory, check_file};
use accelcal::{export, realization, report, simulation};
use anyhow::{Context, Result};

pub(super) fn run_simulate(args: &SimulateArgs) -> Result<()> {
    if args
        .kind
        .is_some_and(|k| k != crate::cli::ModelKind::Accelerometer)
    {
        return super::ins::run_simulate(args);
    }
    let model = load_model(&args.model, &args.case, None)?;
    super::check_memory(&model, accelcal::model::Work::Simulate, &args.model)?;
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    let seed = model.config.ensemble.seed;
    // Both destinations checked before either is written: a bad --csv does not leave new logs.
    if let Some(dir) = &args.logs {
        check_directory(dir, &[ACCEL_FILE, GPS_FILE, TRUTH_FILE])?;
    }
    if let Some(path) = &args.csv {
        check_file(path)?;
    }
    if let Some(dir) = &args.logs {
        write_logs(&model, &schedule, args.realization, dir)?;
    }
    let Some(csv_path) = &args.csv else {
        return Ok(());
    };
    let r = realization::record(&model, &schedule, seed, args.realization);
    let csv = export::realization_csv(&r, &model.timeline.fix_times_s());
    write(csv_path, csv.as_bytes())?;
    if let Some(last) = r.fixes.last() {
        super::say(&format!(
            "realization {} ({}): b = {:.6} m/s², estimate at {:.1} s = {:.6} ± {:.6} m/s²; {} samples written to {}\n",
            args.realization,
            model.case(),
            r.bias_m_s2,
            last.t_s,
            last.post[2],
            last.sigma_post[2],
            r.samples.len(),
            csv_path.display()
        ))?;
    }
    Ok(())
}

/// Runs realization `index` once more, streaming its sensor logs into `dir`.
fn write_logs(model: &Model, schedule: &FilterSchedule, index: u64, dir: &Path) -> Result<()> {
    let mut staged = StagedFiles::create(dir, &[ACCEL_FILE, GPS_FILE, TRUTH_FILE])?;
    let (samples, fixes, draws) = {
        let [accel, gps, truth]: [_; 3] = staged
            .writers()
            .try_into()
            .map_err(|_| anyhow::anyhow!("three staged log files"))?;
        let mut writer = LogWriter::new(&model.timeline, accel, gps, truth)
            .with_context(|| format!("cannot write the logs into {}", dir.display()))?;
        let draws = simulation::run_realization(
            model,
            schedule,
            model.config.ensemble.seed,
            index,
            &mut writer,
        );
        let (samples, fixes) = writer
            .finish()
            .with_context(|| format!("cannot write the logs into {}", dir.display()))?;
        (samples, fixes, draws)
    };
    staged.commit()?;
    super::say(&format!(
        "realization {index} ({}): b = {:.6} m/s²; logs of {samples} samples and {fixes} fixes \
         written to {} ({ACCEL_FILE}, {GPS_FILE}, {TRUTH_FILE})\n",
        model.case(),
        draws.bias_m_s2,
        dir.display()
    ))?;
    Ok(())
}

/// The files `calibrate` writes.
const ESTIMATES_FILE: &str = "estimates.csv";
const SUMMARY_FILE: &str = "summary.json";
const PAGE_FILE: &str = "index.html";

/// The calibration's settings from `--config`, when given: only the keys a calibration uses are
/// read and checked; without the file, or where it is silent, the log decides (the rate, the
/// prior).
fn calibrate_settings(args: &CalibrateArgs) -> Result<Settings, ConfigError> {
    let text = args.config.as_deref().map(ConfigText::read).transpose()?;
    let config = match &text {
        Some(t) => t.parse()?,
        None => Config::default(),
    };
    Settings::from_config_text(&config, text.as_ref())
}

pub(super) fn run_calibrate(args: &CalibrateArgs) -> Result<()> {
    let settings = calibrate_settings(args)?;
    check_directory(&args.out, &[ESTIMATES_FILE, SUMMARY_FILE, PAGE_FILE])?;
    let note = |text: &str| {
        if !args.quiet && std::io::stderr().is_terminal() {
            eprintln!("{text}");
        }
    };
    let (Some(accel), Some(gps)) = (&args.accel, &args.gps) else {
        unreachable!("clap requires --accel and --gps without --imu and --gnss")
    };
    let (accel, gps) = (LogFile::new(accel), LogFile::new(gps));
    if args.every_sample && !accel.rereadable() {
        return Err(CalibrateError::Log(LogError::of_file(
            accel.name(),
            LogProblem::Unreadable {
                message: "--every-sample reads the accelerometer log twice, and this is a pipe \
                          or a device that reads once: give it as a file, or leave out \
                          --every-sample for one row per GPS fix"
                    .to_string(),
            },
        ))
        .into());
    }
    let request = noise_request(args, &settings)?;
    note(if request.is_some() {
        "checking the logs, estimating the noise statistics, running the filter and the smoother…"
    } else {
        "checking the logs and running the filter and the smoother…"
    });
    let mut prepared = calibrate::prepare_with(&accel, &gps, &settings, request.as_ref())?;
    if args.every_sample {
        prepared.per_sample()?;
    }
    let cal = prepared.calibration();
    let page = report::calibration::render(&cal, &calibrate_command(args), args.every_sample)?;
    note("writing the estimates…");
    let mut staged = StagedFiles::create(&args.out, &[ESTIMATES_FILE, SUMMARY_FILE, PAGE_FILE])?;
    let into = |name: &str| format!("cannot write {}", args.out.join(name).display());
    let estimates = staged.writer(ESTIMATES_FILE);
    if args.every_sample {
        prepared.write_estimates(estimates)
    } else {
        prepared.write_fix_estimates(estimates)
    }
    .with_context(|| into(ESTIMATES_FILE))?;
    staged
        .writer(SUMMARY_FILE)
        .write_all(cal.summary.to_json().as_bytes())
        .with_context(|| into(SUMMARY_FILE))?;
    staged
        .writer(PAGE_FILE)
        .write_all(page.as_bytes())
        .with_context(|| into(PAGE_FILE))?;
    staged.commit()?;
    print_result(args, &cal.summary, prepared.noise_estimate())
}

/// The printed result of a calibration: its warnings on standard error, the noise estimate's
/// lines and the bias with the NIS test on standard output.
fn print_result(
    args: &CalibrateArgs,
    s: &calibrate::summary::Summary,
    noise: Option<&NoiseEstimate>,
) -> Result<()> {
    // Warnings go to standard error even with --quiet: they are about the numbers, not progress.
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    // A drifting bias is named: its estimate holds at the end of the log only.
    let model = match s.filter.bias_model {
        "constant" => String::new(),
        name => format!(", bias model {name}"),
    };
    if let Some(e) = noise {
        super::say(&noise_lines(e))?;
    }
    let z = accelcal::stats::normal_bound(1.0 - calibrate::robust::CONFIDENCE);
    let (b, h) = (s.bias_m_s2, z * s.bias_sigma_m_s2);
    let d = interval_digits(b, b - h, b + h, 3);
    let conditional = match calibrate::robust::conditional_words(&s.rejected_by) {
        w if w.is_empty() => w,
        w => format!(", which {w}"),
    };
    super::say(&format!(
        "bias {} ± {} m/s² (95 % interval [{}, {}]{conditional}) at t = {} s ({} samples, {} \
         fixes, Δt mode {}{model}); NIS test {} (sum {} {} [{}, {}]); written to {}\n",
        sig(b, d.max(6)),
        sig(s.bias_sigma_m_s2, 3),
        sig(b - h, d),
        sig(b + h, d),
        s.end_s,
        count(s.samples),
        count(s.fixes as u64),
        s.dt_mode.name(),
        s.nis.verdict,
        sig(s.nis.sum, 5),
        nis_place(s.nis.sum, s.nis.lower, s.nis.upper),
        sig(s.nis.lower, 5),
        sig(s.nis.upper, 5),
        args.out.join(PAGE_FILE).display()
    ))?;
    if s.intervals_conditional {
        super::say(&format!(
            "bias without white innovations: {}\n",
            s.bias_robust.words(&s.rejected_by)
        ))?;
    }
    super::say(&format!("diagnosis: {}\n", s.diagnostics.headline()))?;
    Ok(())
}

/// A command line that asks for what the filter cannot do.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct UsageError(pub String);

/// What `--estimate-noise` asks for, if it does.
fn noise_request(args: &CalibrateArgs, settings: &Settings) -> Result<Option<Request>> {
    if !args.estimate_noise {
        return Ok(None);
    }
    let mut keys = Vec::new();
    for k in &args.estimate {
        match k {
            EstimateKey::OneAxis(k) => keys.push(*k),
            EstimateKey::ThreeAxis(k) => {
                return Err(UsageError(format!(
                    "--estimate {}: a key of the three-axis calibration (--imu/--gnss)",
                    k.name()
                ))
                .into());
            }
        }
    }
    Request::new(&keys, args.confidence, &settings.filter_stats)
        .map(Some)
        .map_err(|e| UsageError(e.to_string()).into())
}

/// The printed lines of a noise estimate: each statistic with its interval, or what the drive
/// leaves open.
fn noise_lines(e: &NoiseEstimate) -> String {
    let pct = sig(100.0 * e.confidence, 3);
    let mut out = format!(
        "noise statistics by maximum likelihood (ℓ = {}, {} evaluations; {pct} % profile \
         intervals):\n",
        sig(e.log_likelihood, 8),
        count(e.evaluations)
    );
    for k in &e.keys {
        let unit = k.key.unit();
        let line = if k.identifiable {
            let (value, lower, upper) = interval(k.value, k.lower, k.upper.unwrap_or(f64::NAN), 4);
            format!(
                "  {} = {value} {unit}, interval [{lower}, {upper}]\n",
                k.key.name()
            )
        } else {
            let known = match (k.lower > 0.0, k.upper) {
                (false, Some(u)) => format!("only an upper bound is known: ≤ {} {unit}", sig(u, 4)),
                (true, None) => {
                    format!("only a lower bound is known: ≥ {} {unit}", sig(k.lower, 4))
                }
                _ => "the interval spans the whole search range".to_string(),
            };
            format!(
                "  {} not identifiable from this drive: {known} (search range [{}, {}]; the \
                 filter used {})\n",
                k.key.name(),
                sig(k.search_bounds[0], 3),
                sig(k.search_bounds[1], 3),
                sig(k.value, 4)
            )
        };
        out.push_str(&line);
    }
    out
}

/// Where the NIS sum lies against its band, in the printed line's words: "in", "below" or
/// "above" (a failing sum is never said to be in its band).
fn nis_place(sum: f64, lower: f64, upper: f64) -> &'static str {
    if (lower..=upper).contains(&sum) {
        "in"
    } else if sum < lower {
        "below"
    } else if sum > upper {
        "above"
    } else {
        "outside"
    }
}

/// The command line that reproduces a calibration.
fn calibrate_command(args: &CalibrateArgs) -> String {
    let mut s = format!(
        "accelcal calibrate --accel {} --gps {}",
        args.accel.clone().unwrap_or_default().display(),
        args.gps.clone().unwrap_or_default().display()
    );
    if let Some(c) = &args.config {
        s.push_str(&format!(" --config {}", c.display()));
    }
    s.push_str(&format!(" --out {}", args.out.display()));
    if args.every_sample {
        s.push_str(" --every-sample");
    }
    if args.estimate_noise {
        s.push_str(" --estimate-noise");
        if !args.estimate.is_empty() {
            let keys: Vec<&str> = args.estimate.iter().map(|k| k.name()).collect();
            s.push_str(&format!(" --estimate {}", keys.join(",")));
        }
        if args.confidence != 0.95 {
            s.push_str(&format!(" --confidence {}", args.confidence));
        }
    }
    s
}
