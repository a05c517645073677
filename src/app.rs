//! What each command does: load and validate the configuration once, run, write.

use std::io::IsTerminal;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::checks::{self, Verdicts};
use crate::cli::{Cli, Command, EnsembleArgs, ModelArgs, ReportArgs, SimulateArgs};
use crate::config::{Config, DEFAULT_TOML, TruthModel};
use crate::ensemble::{self, EnsembleRun};
use crate::error::{ConfigError, FilterError};
use crate::export;
use crate::filter::FilterSchedule;
use crate::model::Model;
use crate::output::write_atomic;
use crate::realization;

/// Exit code for `err`: 2 for bad input (configuration, command line), 1 otherwise.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    // The filter's covariance depends on the configuration alone: when it fails, the
    // configured statistics are to blame.
    if err
        .chain()
        .any(|e| e.is::<ConfigError>() || e.is::<FilterError>())
    {
        2
    } else {
        1
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => crate::report::run(&ReportArgs::default()),
        Some(Command::Report(args)) => crate::report::run(&args),
        Some(Command::Ensemble(args)) => run_ensemble_command(&args),
        Some(Command::Simulate(args)) => run_simulate_command(&args),
        Some(Command::Config) => {
            print!("{DEFAULT_TOML}");
            Ok(())
        }
    }
}

/// The configuration named by `args` with its command-line overrides, validated into a model.
pub fn load_model(args: &ModelArgs, realizations: Option<u64>) -> Result<Model> {
    let mut config = match &args.config {
        Some(path) => Config::from_file(path)?,
        None => Config::default(),
    };
    if let Some(t) = args.truth {
        config.ensemble.truth = t;
    }
    if let Some(s) = args.seed {
        config.ensemble.seed = s;
    }
    if let Some(n) = realizations {
        config.ensemble.realizations = n;
    }
    Ok(Model::new(&config)?)
}

/// The filter schedule of `model`.
pub fn schedule_of(model: &Model) -> Result<FilterSchedule> {
    FilterSchedule::new(&model.timeline, &model.filter_stats).context(
        "the filter's covariance recursion failed: check the [filter] statistics \
             (accel_noise_var_m2_s4, bias_var_m2_s4, gps_position_sigma_m, gps_velocity_sigma_m_s, \
             initial_position_sigma_m, initial_velocity_sigma_m_s)",
    )
}

/// A progress bar on standard error when it is a terminal and not silenced, hidden otherwise.
pub fn progress_bar(len: u64, label: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix:>9} [{bar:40}] {pos}/{len} realizations, {elapsed} elapsed, eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    bar
}

/// Runs the ensemble of `model` with a progress bar and evaluates its checks.
pub fn ensemble_with_verdicts(
    model: &Model,
    schedule: &FilterSchedule,
    quiet: bool,
) -> (EnsembleRun, Verdicts) {
    let n = model.config.ensemble.realizations;
    let bar = progress_bar(n, model.truth.name(), quiet);
    let run = ensemble::run_model(model, schedule, |done| bar.set_position(done));
    bar.finish_and_clear();
    let c = &model.config.checks;
    let verdicts = checks::evaluate(
        &run.stats,
        &model.timeline,
        c.false_alarm_rate,
        model.residual_pair_s,
    );
    (run, verdicts)
}

/// One line per check: id, verdict, worst against bound.
pub fn verdict_lines(truth: TruthModel, run: &EnsembleRun, v: &Verdicts) -> String {
    let mut s = format!(
        "{truth} truth, N = {}: {} ({:.0} realizations/s)\n",
        run.stats.realizations,
        if v.all_passed() {
            "every check passed"
        } else {
            "some checks failed"
        },
        run.realizations_per_s()
    );
    for c in &v.checks {
        s.push_str(&format!(
            "  {:<22} {}  worst {:>10}  bound {:>10}  ({} of {} members outside)\n",
            c.id,
            if c.passed { "pass" } else { "FAIL" },
            crate::report::format::sig(c.worst, 5),
            crate::report::format::sig(c.bound, 5),
            c.failures,
            c.members
        ));
    }
    s
}

fn run_ensemble_command(args: &EnsembleArgs) -> Result<()> {
    let model = load_model(&args.model, args.realizations)?;
    let schedule = schedule_of(&model)?;
    let (run, verdicts) = ensemble_with_verdicts(&model, &schedule, args.model.quiet);
    let doc = export::ensemble_doc(&model.config, model.truth, &schedule, &run, &verdicts);
    let json = export::ensemble_json(&model.config, &doc);
    match &args.json {
        Some(path) => {
            write_atomic(path, json.as_bytes())?;
            print!("{}", verdict_lines(model.truth, &run, &verdicts));
        }
        None => println!("{json}"),
    }
    Ok(())
}

fn run_simulate_command(args: &SimulateArgs) -> Result<()> {
    let model = load_model(&args.model, None)?;
    let schedule = schedule_of(&model)?;
    let r = realization::record(
        &model,
        &schedule,
        model.config.ensemble.seed,
        args.realization,
    );
    let csv = export::realization_csv(&r, &model.timeline.fix_times_s());
    write_atomic(&args.csv, csv.as_bytes())?;
    if let Some(last) = r.fixes.last() {
        println!(
            "realization {} ({} truth): b = {:.6} m/s², estimate at {:.1} s = {:.6} ± {:.6} m/s²; {} samples written to {}",
            args.realization,
            model.truth,
            r.bias_m_s2,
            last.t_s,
            last.post[2],
            last.sigma_post[2],
            r.samples.len(),
            args.csv.display()
        );
    }
    Ok(())
}
