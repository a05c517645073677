//! The commands of the Monte Carlo study: the report, one ensemble or one shard of it, the merge
//! of shards, and the sensitivity study.

use std::io::Write;
use std::path::Path;

use super::{Bar, check_memory, load_model, say, verdict_lines, write_json};
use crate::cli::{CaseArgs, EnsembleArgs, MergeArgs, ReportArgs, SensitivityArgs};
use accelcal::config::{Config, SensitivityConfig};
use accelcal::ensemble::{Engine, Ensemble, EnsembleRun, EnsembleStats, partial};
use accelcal::error::ConfigError;
use accelcal::filter::FilterSchedule;
use accelcal::model::{Model, Work};
use accelcal::output::{AtomicFile, ScratchFile, check_directory, check_file, write_all_atomic};
use accelcal::sensitivity::{self, AssumedStatistic, Plan};
use accelcal::study::{self, Progress, Study};
use accelcal::{export, report};
use anyhow::Result;

/// The files `report` writes into its directory.
const REPORT_FILES: [&str; 3] = ["index.html", "data.json", "view.json"];

pub(super) fn run_report(args: &ReportArgs) -> Result<()> {
    let model = load_model(&args.model, &CaseArgs::default(), args.realizations)?;
    check_directory(&args.out, &REPORT_FILES)?;
    check_memory(&model, Work::Report, &args.model)?;
    let mut bar = Bar::new(args.model.quiet);
    let study = Study::run(&model, &mut bar)?
        .with_sensitivity(&mut bar)?
        .with_drift(&mut bar)?
        .with_ins(&mut bar)?
        .with_noise(study::noise::NOISE_DRIVES, &mut bar)?
        .with_real_drive()?
        .with_real_drive_3d()?;
    let static_noise = accelcal::allan::section::report_coverage()?;
    let command = reproduce_command(args);
    let input = report::ReportInput {
        study: &study,
        command: &command,
        threads: rayon::current_num_threads(),
        static_noise: Some(&static_noise),
    };
    let page = report::render(&input)?;
    let data = report::data_json(&input);
    write_all_atomic(
        &args.out,
        &[
            (REPORT_FILES[0], page.html.as_bytes()),
            (REPORT_FILES[1], data.as_bytes()),
            (REPORT_FILES[2], page.view_json.as_bytes()),
        ],
    )?;
    for o in &study.cases {
        say(&verdict_lines(&o.case.to_string(), &o.run, &o.verdicts))?;
    }
    say(&format!(
        "report written to {}\n",
        args.out.join("index.html").display()
    ))
}

/// The command line that reproduces a report.
fn reproduce_command(args: &ReportArgs) -> String {
    let mut s = String::from("accelcal report");
    if let Some(c) = &args.model.config {
        s.push_str(&format!(" --config {}", c.display()));
    }
    if let Some(seed) = args.model.seed {
        s.push_str(&format!(" --seed {seed}"));
    }
    if let Some(n) = args.realizations {
        s.push_str(&format!(" --realizations {n}"));
    }
    s
}

pub(super) fn run_ensemble(args: &EnsembleArgs) -> Result<()> {
    if args
        .kind
        .is_some_and(|k| k != crate::cli::ModelKind::Accelerometer)
    {
        return super::ins::run_ensemble(args);
    }
    let model = load_model(&args.model, &args.case, args.realizations)?;
    check_memory(&model, Work::Ensemble, &args.model)?;
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    if let Some(path) = &args.json {
        check_file(path)?;
    }
    if let (Some(shard), Some(path)) = (&args.shard, &args.partial) {
        return run_shard(
            &model,
            &schedule,
            args.engine.unwrap_or_default(),
            shard,
            path,
            args.model.quiet,
        );
    }
    let outcome = study::run_case(
        &Ensemble::new(&model, &schedule).with_engine(args.engine.unwrap_or_default()),
        &mut Bar::new(args.model.quiet),
    );
    let doc = export::ensemble_doc(&model.config, &schedule, &outcome);
    write_json(args.json.as_deref(), |w| {
        export::write_ensemble_json(w, &model.config, &doc)
    })?;
    if args.json.is_some() {
        let label = model.case().to_string();
        say(&verdict_lines(&label, &outcome.run, &outcome.verdicts))?;
    }
    Ok(())
}

/// The sensitivity plan of `args` on `config`, or the option that is out of range.
fn sensitivity_plan(args: &SensitivityArgs, config: &Config) -> Result<Plan, ConfigError> {
    let sizes = SensitivityConfig {
        factors: args
            .factors
            .clone()
            .unwrap_or_else(|| config.sensitivity.factors.clone()),
        ensembles: args.ensembles.unwrap_or(config.sensitivity.ensembles),
        draws: args.draws.unwrap_or(config.sensitivity.draws),
    };
    sizes.check(["--factors", "--ensembles", "--draws"])?;
    let parameters = if args.parameters.is_empty() {
        AssumedStatistic::of(config)
    } else {
        args.parameters
            .iter()
            .map(|p| {
                AssumedStatistic::from_name(p).ok_or_else(|| {
                    ConfigError::invalid(
                        "--parameters",
                        p,
                        format!(
                            "must be keys of [filter]: {}",
                            AssumedStatistic::ALL.map(|s| s.name()).join(", ")
                        ),
                    )
                })
            })
            .collect::<Result<_, _>>()?
    };
    Ok(Plan {
        parameters,
        factors: sizes.factors,
        realizations: config.ensemble.realizations,
        ensembles: sizes.ensembles,
        draws: sizes.draws,
        engine: args.engine,
    })
}

pub(super) fn run_sensitivity(args: &SensitivityArgs) -> Result<()> {
    let model = load_model(&args.model, &CaseArgs::default(), args.realizations)?;
    check_memory(&model, Work::Sensitivity, &args.model)?;
    let plan = sensitivity_plan(args, &model.config)?;
    if let Some(path) = &args.json {
        check_file(path)?;
    }
    let result = sensitivity::run(&model.config, &plan, &mut Bar::new(args.model.quiet))?;
    write_json(args.json.as_deref(), |w| {
        export::sensitivity::write_sensitivity_json(w, &result)
    })?;
    if let Some(path) = &args.json {
        say(&format!(
            "{} cases written to {}\n",
            result.cases.len(),
            path.display()
        ))?;
    }
    Ok(())
}

fn run_shard(
    model: &Model,
    schedule: &FilterSchedule,
    engine: Engine,
    shard: &str,
    path: &Path,
    quiet: bool,
) -> Result<()> {
    let ensemble = Ensemble::new(model, schedule).with_engine(engine);
    let partition = ensemble.partition();
    let shard = super::shards::parse_shard(shard, partition.blocks, partition.realizations)?;
    let ensemble = ensemble.with_shard(shard);
    let blocks = ensemble.block_range();
    let realizations = partition.realizations_in(&blocks);
    let (k, m) = (shard.index, shard.of);
    // Both files are made before the run: a destination that cannot be written is refused at
    // once, and neither is left behind by a failure (or by SIGINT or SIGTERM).
    let mut file = AtomicFile::create(path)?;
    // The header carries the run time, so blocks wait in a scratch file until the run ends.
    let (spool, spool_file) = ScratchFile::beside(path, "blocks")?;
    let mut spool_w = std::io::BufWriter::new(spool_file);
    let mut bar = Bar::new(quiet);
    bar.start(&format!("shard {k}/{m}"), realizations);
    let start = std::time::Instant::now();
    let mut written = Ok(());
    ensemble.blocks(
        |done| bar.advance(done),
        |index, acc| {
            if written.is_ok() {
                written = spool_w.write_all(&partial::encode_block(index, acc));
            }
        },
    );
    bar.finish();
    let layout = ensemble.layout();
    let header = partial::PartialHeader {
        accelcal_version: env!("CARGO_PKG_VERSION").to_string(),
        config: model.config.clone(),
        shard: k,
        shards: m,
        blocks: [blocks.start, blocks.end],
        fixes: layout.fixes(),
        max_lag: layout.max_lag(),
        pair: model.residual_pair,
        elapsed_s: start.elapsed().as_secs_f64(),
        engine,
    };
    written
        .and_then(|()| spool_w.flush())
        .map_err(|e| spool.error(e))?;
    drop(spool_w);
    let mut blocks_read = std::io::BufReader::new(spool.open()?);
    partial::write_partial(file.writer(), &header, &mut blocks_read).map_err(|e| file.error(e))?;
    file.commit()?;
    if !quiet {
        say(&format!(
            "shard {k}/{m}: blocks {}..{} ({realizations} realizations) written to {}\n",
            blocks.start,
            blocks.end,
            path.display()
        ))?;
    }
    Ok(())
}

pub(super) fn run_merge(args: &MergeArgs) -> Result<()> {
    if let Some(path) = &args.json {
        check_file(path)?;
    }
    if super::ins::is_ins_merge(&args.files)? {
        return super::ins::run_merge(args);
    }
    let merged = partial::merge(super::shards::open_partials(&args.files)?)?;
    let model = Model::new(&merged.config)?;
    let schedule = FilterSchedule::new(&model.timeline, &model.filter_stats)?;
    let run = EnsembleRun {
        stats: EnsembleStats::from_sums(&merged.sums, &schedule),
        elapsed_s: merged.elapsed_s,
        engine: merged.engine,
    };
    let outcome = study::judge_case(&model, &schedule, run);
    let doc = export::ensemble_doc(&model.config, &schedule, &outcome);
    write_json(args.json.as_deref(), |w| {
        export::write_ensemble_json(w, &model.config, &doc)
    })?;
    if args.json.is_some() && !args.quiet {
        let label = format!("{} (merged from {} shards)", model.case(), args.files.len());
        say(&verdict_lines(&label, &outcome.run, &outcome.verdicts))?;
    }
    Ok(())
}
