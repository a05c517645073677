//! What each command does: load and validate the configuration once, run the library, write.
//! The only place that knows about terminals (the progress bar) and exit codes. `monte_carlo` holds
//! the commands of the Monte Carlo study (report, ensemble and its shards, merge, sensitivity),
//! `logs` those of sensor logs (simulate, calibrate).

mod allan;
mod calibrate_imu;
mod ins;
mod intrinsics;
mod logs;
mod monte_carlo;
mod shards;

use std::io::IsTerminal;
use std::path::Path;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::cli::{CaseArgs, Cli, Command, ModelArgs, ModelKind, ReportArgs};
use accelcal::calibrate::CalibrateError;
use accelcal::checks::{Untestable, Verdict, Verdicts};
use accelcal::config::show;
use accelcal::config::{Config, ConfigText, DEFAULT_TOML};
use accelcal::ensemble::{EnsembleRun, partial};
use accelcal::error::{ConfigError, FilterError};
use accelcal::format::{count, sig};
use accelcal::input::LogError;
use accelcal::model::{Model, Work};
use accelcal::output::write_atomic;
use accelcal::study::Progress;

/// Exit code for `err`: 2 for what the user can fix — bad input (configuration, filter
/// statistics, logs, partials), an output that cannot be written (a path that is a directory,
/// in a missing or read-only directory, a full device) and standard output refusing what is
/// printed; 1 otherwise (a fault of the program or the machine).
///
/// Results are written only through [`accelcal::output`], so an operating system's error that
/// reaches here is one of an output's.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    let bad_input = err.chain().any(|e| {
        e.is::<ConfigError>()
            || e.is::<FilterError>()
            || e.is::<LogError>()
            || e.is::<partial::PartialError>()
            || e.is::<accelcal::allan::AllanError>()
            || e.is::<accelcal::allan::imu::ImuError>()
            || e.is::<accelcal::intrinsics::IntrinsicsError>()
            || e.is::<logs::UsageError>()
            || e.downcast_ref::<CalibrateError>()
                .is_some_and(CalibrateError::is_bad_input)
    });
    let output = err.chain().any(|e| {
        e.is::<StdoutError>() || e.is::<accelcal::output::OutputError>() || e.is::<std::io::Error>()
    });
    if bad_input || output { 2 } else { 1 }
}

/// Ends the process as the signal `signal` (SIGINT, SIGTERM, SIGHUP) would have, once the
/// output layer removed the temporaries: killed by it, so that a shell shows 128 + `signal`
/// (130 after Ctrl-C, 143 after SIGTERM); exit code 128 + `signal` should that fail.
pub fn end_as_signal(signal: i32) {
    let _ = signal_hook::low_level::emulate_default_handler(signal);
    std::process::exit(128 + signal);
}

/// One line on standard error for each temporary left by a run that no longer runs (killed by
/// SIGKILL) that this run's output layer removed, with its size: the user sees where the space
/// came back from.
pub fn tell_stale_temporaries_removed() {
    for t in accelcal::output::take_removed_stale_temporaries() {
        let size = match t.bytes {
            b if b >= 1_000_000 => format!("{:.1} MB", b as f64 / 1e6),
            b if b >= 1_000 => format!("{:.1} kB", b as f64 / 1e3),
            1 => "1 byte".to_string(),
            b => format!("{b} bytes"),
        };
        eprintln!(
            "removed {} ({size}), a temporary left by process {}, which no longer runs",
            t.path.display(),
            t.pid
        );
    }
}

/// Standard output could not take what a command printed (`/dev/full`, a closed pipe).
#[derive(Debug, thiserror::Error)]
#[error("cannot write to standard output: {0}")]
pub(crate) struct StdoutError(std::io::Error);

/// Writes `text` to standard output; an error is returned, not a panic as `print!` would.
pub(crate) fn say(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| StdoutError(e).into())
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => monte_carlo::run_report(&ReportArgs::default()),
        Some(Command::Report(args)) => monte_carlo::run_report(&args),
        Some(Command::Ensemble(mut args)) => {
            args.kind = Some(model_kind(args.kind, &args.model)?);
            monte_carlo::run_ensemble(&args)
        }
        Some(Command::Simulate(mut args)) => {
            args.kind = Some(model_kind(args.kind, &args.model)?);
            logs::run_simulate(&args)
        }
        Some(Command::Sensitivity(args)) => monte_carlo::run_sensitivity(&args),
        Some(Command::Merge(args)) => monte_carlo::run_merge(&args),
        Some(Command::Calibrate(args)) => match (&args.imu, &args.gnss) {
            (Some(imu), Some(gnss)) => calibrate_imu::run(&args, imu, gnss),
            _ => logs::run_calibrate(&args),
        },
        Some(Command::Allan(args)) => allan::run_allan(&args),
        Some(Command::Intrinsics(args)) => intrinsics::run(&args),
        Some(Command::Config(args)) => say(&match args.model {
            ModelKind::Accelerometer => DEFAULT_TOML.to_string(),
            ModelKind::Ins => accelcal::config::ins::DEFAULT_INS_TOML.to_string(),
            ModelKind::Car => accelcal::config::ins::default_car_toml(),
        }),
    }
}

/// The study `--model` names (`flag`), or without it the one the configuration file's
/// top-level `model` key names ("ins", "car"; the one-axis study's file has none).
///
/// # Errors
/// [`ConfigError::Invalid`] for a `model` that names no study, or a three-axis file run with
/// `--model accelerometer`. A file that is not a regular file (a pipe, read once) or not
/// TOML is not looked into here: its reader says what is wrong.
fn model_kind(flag: Option<ModelKind>, args: &ModelArgs) -> Result<ModelKind, ConfigError> {
    let Some(path) = args.config.as_deref().filter(|p| p.is_file()) else {
        return Ok(flag.unwrap_or(ModelKind::Accelerometer));
    };
    let text = ConfigText::read(path)?;
    let Some(model) = text
        .text
        .parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("model").cloned())
    else {
        return Ok(flag.unwrap_or(ModelKind::Accelerometer));
    };
    let named = match model.as_str() {
        Some("ins") => Some(ModelKind::Ins),
        Some("car") => Some(ModelKind::Car),
        _ => None,
    };
    let invalid = |expected: &str| {
        let value = model
            .as_str()
            .map_or_else(|| model.to_string(), |s| format!("\"{s}\""));
        Err(text.locate(ConfigError::invalid("model", value, expected)))
    };
    match (flag, named) {
        (_, None) => {
            invalid("\"ins\" or \"car\" (a three-axis file), or left out (the one-axis file)")
        }
        (Some(ModelKind::Accelerometer), Some(_)) => invalid(
            "left out with --model accelerometer (the one-axis file has no `model`); leave \
             --model out to run the file's own",
        ),
        (Some(kind), Some(_)) => Ok(kind),
        (None, Some(kind)) => Ok(kind),
    }
}

/// The configuration named by `args` with its command-line overrides, validated into a model.
pub(crate) fn load_model(
    args: &ModelArgs,
    case: &CaseArgs,
    realizations: Option<u64>,
) -> Result<Model, ConfigError> {
    let text = args.config.as_deref().map(ConfigText::read).transpose()?;
    let mut config = match &text {
        Some(t) => t.parse()?,
        None => Config::default(),
    };
    if let Some(t) = case.truth {
        config.ensemble.truth = t;
    }
    if let Some(o) = case.accelerometer_output {
        config.accelerometer.output = o;
    }
    if let Some(s) = args.seed {
        config.ensemble.seed = s;
    }
    if let Some(n) = realizations {
        config.ensemble.realizations = n;
    }
    // A value set on the command line is not the file's: its error points at no line.
    let from_flags: Vec<&str> = [
        ("ensemble.truth", case.truth.is_some()),
        ("accelerometer.output", case.accelerometer_output.is_some()),
        ("ensemble.seed", args.seed.is_some()),
        ("ensemble.realizations", realizations.is_some()),
    ]
    .into_iter()
    .filter_map(|(field, set)| set.then_some(field))
    .collect();
    Model::new(&config).map_err(|e| match (&text, &e) {
        (Some(t), ConfigError::Invalid { field, .. }) if !from_flags.contains(field) => t.locate(e),
        _ => e,
    })
}

/// The memory this machine can give a run, bytes, and where the figure comes from:
/// `ACCELCAL_MEMORY_AVAILABLE` (bytes) when set, else `MemAvailable` of /proc/meminfo, lowered
/// to what the cgroup v2 limit leaves (memory.max − memory.current); `None` where neither is
/// known (the run is then not checked).
fn available_memory() -> Option<(f64, &'static str)> {
    if let Ok(v) = std::env::var("ACCELCAL_MEMORY_AVAILABLE") {
        return v
            .trim()
            .parse::<f64>()
            .ok()
            .map(|b| (b, "ACCELCAL_MEMORY_AVAILABLE"));
    }
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: f64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let read = |p: &str| -> Option<f64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    let cgroup = read("/sys/fs/cgroup/memory.max")
        .zip(read("/sys/fs/cgroup/memory.current"))
        .map(|(max, current)| max - current);
    match cgroup {
        Some(left) if left < kb * 1024.0 => Some((left, "the cgroup's memory.max")),
        _ => Some((kb * 1024.0, "MemAvailable")),
    }
}

/// Refuses a run of `work` on `model` predicted to need more memory than the machine has,
/// naming the figure and the key to change (at its line of the configuration named by `args`).
pub(crate) fn check_memory(model: &Model, work: Work, args: &ModelArgs) -> Result<(), ConfigError> {
    let Some((available, source)) = available_memory() else {
        return Ok(());
    };
    let estimate = model.peak_memory(work, rayon::current_num_threads());
    if estimate.bytes <= available {
        return Ok(());
    }
    let c = &model.config;
    let value = match estimate.key {
        "profile.duration_s" => show(c.profile.duration_s),
        "gps.sample_rate_hz" => show(c.gps.sample_rate_hz),
        _ => c
            .checks
            .residual_max_lag
            .map_or("its default".to_string(), |l| l.to_string()),
    };
    let gb = |b: f64| {
        if b < 1e9 {
            format!("{:.0} MB", b / 1e6)
        } else {
            format!("{:.2} GB", b / 1e9)
        }
    };
    let err = ConfigError::invalid(
        estimate.key,
        value,
        format!(
            "this {} run is predicted to need about {} of memory at its peak ({}), more \
             than the {} this machine has available ({source}): lower {} (or run on a larger \
             machine)",
            format!("{work:?}").to_lowercase(),
            gb(estimate.bytes),
            estimate.terms,
            gb(available),
            estimate.key
        ),
    );
    Err(match args.config.as_deref().map(ConfigText::read) {
        Some(Ok(text)) => text.locate(err),
        _ => err,
    })
}

/// A progress bar on standard error when it is a terminal and not silenced, hidden otherwise.
pub(crate) struct Bar {
    quiet: bool,
    bar: Option<ProgressBar>,
}

impl Bar {
    pub(crate) fn new(quiet: bool) -> Self {
        Self {
            quiet: quiet || !std::io::stderr().is_terminal(),
            bar: None,
        }
    }
}

impl Progress for Bar {
    fn start(&mut self, label: &str, total: u64) {
        self.start_in(label, total, "realizations");
    }

    fn start_in(&mut self, label: &str, total: u64, unit: &str) {
        if self.quiet {
            return;
        }
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>9} [{bar:40}] {pos}/{len} {msg}, {elapsed} elapsed, eta {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_prefix(label.to_string());
        // The clock moves while a long step (a case of the sensitivity study) reports nothing.
        bar.enable_steady_tick(std::time::Duration::from_millis(500));
        bar.set_message(unit.to_string());
        self.bar = Some(bar);
    }

    fn advance(&mut self, done: u64) {
        if let Some(bar) = &self.bar {
            bar.set_position(done);
        }
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// One line per check: id, verdict, worst against bound.
pub(crate) fn verdict_lines(label: &str, run: &EnsembleRun, v: &Verdicts) -> String {
    check_lines(label, run.stats.realizations, run.realizations_per_s(), v)
}

/// One line per check of `n` realizations run at `per_s` a second.
pub(crate) fn check_lines(label: &str, n: u64, per_s: f64, v: &Verdicts) -> String {
    let mut s = format!(
        "{label}, N = {n}: {} ({per_s:.0} realizations/s; study-wide false-alarm rate {})\n",
        if v.all_passed() {
            "every check passed"
        } else if v.failed().next().is_some() {
            "some checks failed"
        } else {
            "some checks are untestable"
        },
        sig(v.false_alarm_rate, 2)
    );
    for c in &v.checks {
        let verdict = match c.verdict {
            Verdict::Pass => "pass".to_string(),
            Verdict::Fail => "FAIL".to_string(),
            Verdict::Untestable(Untestable::TooFewRealizations { needs }) => {
                format!("untestable at N = {n}, needs N ≥ {needs}")
            }
            Verdict::Untestable(Untestable::NoMembers) => {
                "untestable: no member could be computed".to_string()
            }
        };
        let band = if c.is_normal() {
            format!("|z| ≤ {}", sig(c.upper, 5))
        } else {
            format!("[{}, {}]", sig(c.lower, 5), sig(c.upper, 5))
        };
        s.push_str(&format!(
            "  {:<22} {verdict}  worst {:>10}  band {:<22}  ({} of {} members outside)\n",
            c.id.name(),
            sig(c.worst_value(), 5),
            band,
            count(c.failures as u64),
            count(c.members as u64)
        ));
    }
    s
}

pub(crate) fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    Ok(write_atomic(path, bytes)?)
}

/// Writes a JSON document as `serialize` makes it: to the file `path` (atomically, or in place
/// when it is a device or a FIFO), else to standard output followed by a line end. The text is
/// never held whole: at 4·10⁵ fixes an ensemble's is 1.6 GB.
///
/// # Errors
/// [`accelcal::output::OutputError`] naming `path` (or [`StdoutError`]) with the operating
/// system's error when a write fails; a file's earlier content is then untouched and no
/// temporary is left.
pub(crate) fn write_json(
    path: Option<&Path>,
    serialize: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<()> {
    match path {
        Some(path) => {
            let mut file = accelcal::output::AtomicFile::create(path)?;
            serialize(file.writer()).map_err(|e| file.error(e))?;
            file.commit()?;
        }
        None => {
            let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
            serialize(&mut out)
                .and_then(|()| std::io::Write::write_all(&mut out, b"\n"))
                .and_then(|()| std::io::Write::flush(&mut out))
                .map_err(StdoutError)?;
        }
    }
    Ok(())
}
