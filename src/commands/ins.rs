//! The three-axis study's commands: `simulate --model ins --logs DIR` and `ensemble --model ins`.

use anyhow::Result;

use crate::cli::{EnsembleArgs, ModelArgs, SimulateArgs};
use accelcal::checks::{Budget, evaluate};
use accelcal::config::ConfigText;
use accelcal::config::ins::InsConfig;
use accelcal::error::ConfigError;
use accelcal::export;
use accelcal::ins::ensemble::{self as ins_ensemble, Track};
use accelcal::ins::logs::write_realization;
use accelcal::ins::setup::Study;
use accelcal::output::{StagedFiles, check_directory};
use accelcal::study::Progress;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The most memory a three-axis ensemble may hold.
const MAX_ENSEMBLE_BYTES: f64 = 2.0 * GIB;

/// The three-axis logs a simulation writes.
const IMU_FILE: &str = "imu.csv";
const GNSS_FILE: &str = "gnss.csv";
const TRUTH_FILE: &str = "truth.csv";

/// The three-axis study named by `args` (`--config`, `--seed`), validated.
pub(super) fn load_study(args: &ModelArgs) -> Result<Study, ConfigError> {
    load(args, None).map(|(_, s)| s)
}

/// The configuration and study named by `args`, `realizations` overriding the file's.
fn load(args: &ModelArgs, realizations: Option<u64>) -> Result<(InsConfig, Study), ConfigError> {
    let text = args.config.as_deref().map(ConfigText::read).transpose()?;
    let locate = |e: ConfigError| match &text {
        Some(t) => t.locate(e),
        None => e,
    };
    let mut config = match &text {
        Some(t) => InsConfig::from_toml_str(&t.text).map_err(locate)?,
        None => InsConfig::default(),
    };
    if let Some(s) = args.seed {
        config.ensemble.seed = s;
    }
    if let Some(n) = realizations {
        config.ensemble.realizations = n;
    }
    // A value set on the command line is not the file's: its error points at no line.
    let study = Study::from_config(&config).map_err(|e| match &e {
        ConfigError::Invalid { field, .. }
            if *field == "ensemble.realizations" && realizations.is_some() =>
        {
            e
        }
        _ => locate(e),
    })?;
    Ok((config, study))
}

/// `ensemble --model ins`: N realizations of the drive, the check catalogue on each
/// realization's own covariances, the JSON.
pub(super) fn run_ensemble(args: &EnsembleArgs) -> Result<()> {
    if args.case.truth.is_some() || args.case.accelerometer_output.is_some() {
        return Err(ConfigError::invalid(
            "--truth/--accelerometer-output",
            "given",
            "options of the one-axis model only",
        )
        .into());
    }
    if args.shard.is_some() {
        return Err(ConfigError::invalid(
            "--shard",
            args.shard.as_deref().unwrap_or_default(),
            "an option of the one-axis model only (the three-axis ensemble runs whole)",
        )
        .into());
    }
    let (config, study) = load(&args.model, args.realizations)?;
    let bytes = ins_ensemble::memory_bytes(&study);
    if bytes > MAX_ENSEMBLE_BYTES {
        let fixes = study.duration_s * study.imu_rate_hz / study.imu_steps_per_fix as f64;
        return Err(ConfigError::invalid(
            "gnss.gnss_rate_hz",
            config.gnss.gnss_rate_hz,
            format!(
                "{fixes:.0} fixes would hold {:.1} GiB in the ensemble's sums (at most {:.0} GiB): \
                 a lower GNSS rate, a shorter drive, or checks.residual_max_lag",
                bytes / GIB,
                MAX_ENSEMBLE_BYTES / GIB
            ),
        )
        .into());
    }
    if let Some(path) = &args.json {
        accelcal::output::check_file(path)?;
    }
    let start = std::time::Instant::now();
    let track = Track::of(&study);
    let n = study.realizations;
    let mut bar = super::Bar::new(args.model.quiet);
    bar.start("ins", n);
    let sums = ins_ensemble::sums(&study, &track, 0..n, |done| bar.advance(done))?;
    bar.finish();
    let outcome = sums.outcome(&study);
    let verdicts = evaluate(&outcome.stats, &Budget::study(study.false_alarm_rate));
    let elapsed_s = start.elapsed().as_secs_f64();
    let doc = export::ins::document(&config, &outcome, &verdicts, elapsed_s);
    super::write_json(args.json.as_deref(), |w| {
        serde_json::to_writer_pretty(w, &doc).map_err(std::io::Error::from)
    })?;
    if args.json.is_some() {
        let mut lines = super::check_lines("three axes", n, n as f64 / elapsed_s, &verdicts);
        for c in &doc.summary.checks {
            if let Some(first) = &c.first_failure_member {
                lines.push_str(&format!("  {} fails from {first}\n", c.id.name()));
            }
        }
        super::say(&lines)?;
    }
    Ok(())
}

/// `simulate --model ins`: one realization's IMU and GNSS logs and its truth.
pub(super) fn run_simulate(args: &SimulateArgs) -> Result<()> {
    if let Some(csv) = &args.csv {
        return Err(ConfigError::invalid(
            "--csv",
            csv.display(),
            "the one-axis model's per-sample file; with --model ins, --logs DIR",
        )
        .into());
    }
    if args.case.truth.is_some() || args.case.accelerometer_output.is_some() {
        return Err(ConfigError::invalid(
            "--truth/--accelerometer-output",
            "given",
            "options of the one-axis model only",
        )
        .into());
    }
    let Some(dir) = &args.logs else {
        return Err(ConfigError::invalid(
            "--logs",
            "(none)",
            "a directory for imu.csv, gnss.csv and truth.csv",
        )
        .into());
    };
    let study = load_study(&args.model)?;
    let names = [IMU_FILE, GNSS_FILE, TRUTH_FILE];
    check_directory(dir, &names)?;
    let mut staged = StagedFiles::create(dir, &names)?;
    let written = {
        let [imu, gnss, truth]: [_; 3] = staged
            .writers()
            .try_into()
            .map_err(|_| anyhow::anyhow!("three staged log files"))?;
        write_realization(&study, args.realization, imu, gnss, truth)?
    };
    staged.commit()?;
    let deg_h = |x: f64| (x * 3600.0).to_degrees();
    let (g, a) = (written.gyro_bias_rad_s, written.accel_bias_m_s2);
    super::say(&format!(
        "realization {} (three axes, {} s at {} Hz): gyro biases {:.2}, {:.2}, {:.2} °/h, \
         accelerometer biases {:.3}, {:.3}, {:.3} mg at the start; {} IMU samples and {} fixes \
         written to {} ({IMU_FILE}, {GNSS_FILE}, {TRUTH_FILE})\n",
        args.realization,
        study.duration_s,
        study.imu_rate_hz,
        deg_h(g.x),
        deg_h(g.y),
        deg_h(g.z),
        a.x / 9.80665e-3,
        a.y / 9.80665e-3,
        a.z / 9.80665e-3,
        written.samples,
        written.fixes,
        dir.display()
    ))
}
