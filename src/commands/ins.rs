//! The three-axis study's commands: `simulate --model ins --logs DIR`, `ensemble --model ins`
//! (whole, or one shard of it), and the merge of its shards.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::cli::{EnsembleArgs, MergeArgs, ModelArgs, ModelKind, SimulateArgs};
use accelcal::checks::{Budget, evaluate};
use accelcal::config::ConfigText;
use accelcal::config::ins::InsConfig;
use accelcal::ensemble::Engine;
use accelcal::ensemble::partial::PartialError;
use accelcal::error::ConfigError;
use accelcal::export;
use accelcal::ins::blocks;
use accelcal::ins::ensemble::{self as ins_ensemble, InsSums, Track};
use accelcal::ins::partial::{self, InsPartialHeader};
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::write_realization;
use accelcal::output::{AtomicFile, ScratchFile, StagedFiles, check_directory};
use accelcal::study::Progress;
use accelcal::with_layout;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The most memory a three-axis ensemble may hold.
const MAX_ENSEMBLE_BYTES: f64 = 2.0 * GIB;

/// The three-axis logs a simulation writes.
const IMU_FILE: &str = "imu.csv";
const GNSS_FILE: &str = "gnss.csv";
const TRUTH_FILE: &str = "truth.csv";

/// The three-axis scenario named by `args` (`--config`, `--seed`), validated.
pub(super) fn load_scenario(args: &ModelArgs, kind: ModelKind) -> Result<Scenario, ConfigError> {
    load(args, kind, None).map(|(_, s)| s)
}

/// The configuration and scenario named by `args`, `realizations` overriding the file's.
fn load(
    args: &ModelArgs,
    kind: ModelKind,
    realizations: Option<u64>,
) -> Result<(InsConfig, Scenario), ConfigError> {
    let text = args.config.as_deref().map(ConfigText::read).transpose()?;
    let locate = |e: ConfigError| match &text {
        Some(t) => t.locate(e),
        None => e,
    };
    let mut config = match &text {
        Some(t) => InsConfig::from_toml_str(&t.text).map_err(locate)?,
        None => InsConfig::default(),
    };
    // `--model car` makes a file without a model key a car's; a file that says "ins" is not one.
    if kind == ModelKind::Car {
        match config.model.as_deref() {
            None => config.model = Some("car".into()),
            Some("car") => {}
            Some(m) => {
                return Err(locate(ConfigError::invalid(
                    "model",
                    m,
                    "\"car\" (or left out) with --model car",
                )));
            }
        }
    }
    // The output's copy of the configuration shows the vehicle it ran.
    if config.is_car() && config.vehicle.is_none() {
        config.vehicle = Some(Default::default());
    }
    if let Some(s) = args.seed {
        config.ensemble.seed = s;
    }
    if let Some(n) = realizations {
        config.ensemble.realizations = n;
    }
    // A value set on the command line is not the file's: its error points at no line.
    let scenario = Scenario::from_config(&config).map_err(|e| match &e {
        ConfigError::Invalid { field, .. }
            if *field == "ensemble.realizations" && realizations.is_some() =>
        {
            e
        }
        _ => locate(e),
    })?;
    Ok((config, scenario))
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
    // Given explicitly as its default, it changes nothing; any other engine would be ignored.
    if let Some(engine) = args.engine.filter(|e| *e != Engine::default()) {
        return Err(ConfigError::invalid(
            "--engine",
            engine,
            "an option of the one-axis model only (the three-axis ensemble runs its own filter)",
        )
        .into());
    }
    let kind = args.kind.unwrap_or(ModelKind::Ins);
    let (config, scenario) = load(&args.model, kind, args.realizations)?;
    let bytes = ins_ensemble::memory_bytes(&scenario);
    if bytes > MAX_ENSEMBLE_BYTES {
        let fixes = scenario.duration_s * scenario.imu_rate_hz / scenario.imu_steps_per_fix as f64;
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
    if let (Some(shard), Some(path)) = (&args.shard, &args.partial) {
        let quiet = args.model.quiet;
        return with_layout!(scenario.layout(), N => {
            run_shard::<N>(&config, &scenario, shard, path, quiet)
        });
    }
    if let Some(path) = &args.json {
        accelcal::output::check_file(path)?;
    }
    with_layout!(scenario.layout(), N => run_whole::<N>(args, &config, &scenario))
}

/// The whole ensemble of `scenario` with an error state of `N`, in one process, and its JSON.
fn run_whole<const N: usize>(
    args: &EnsembleArgs,
    config: &InsConfig,
    scenario: &Scenario,
) -> Result<()> {
    let start = std::time::Instant::now();
    let track = Track::of(scenario);
    let n = scenario.realizations;
    let mut bar = super::Bar::new(args.model.quiet);
    bar.start("ins", n);
    let sums = ins_ensemble::sums::<N>(scenario, &track, n, |done| bar.advance(done))?;
    bar.finish();
    let elapsed_s = start.elapsed().as_secs_f64();
    write_document(
        config,
        scenario,
        &sums,
        elapsed_s,
        args.json.as_deref(),
        Some("three axes"),
    )
}

/// The JSON of the ensemble whose sums are `sums` to `json` (standard output when `None`), and
/// its checks' lines, labelled `label` (none when `None`), when it goes to a file.
fn write_document<const N: usize>(
    config: &InsConfig,
    scenario: &Scenario,
    sums: &InsSums<N>,
    elapsed_s: f64,
    json: Option<&Path>,
    label: Option<&str>,
) -> Result<()> {
    let outcome = sums.outcome(scenario);
    let verdicts = evaluate(&outcome.stats, &Budget::study(scenario.false_alarm_rate));
    let doc = export::ins::document(config, &outcome, &verdicts, elapsed_s);
    super::write_json(json, |w| {
        serde_json::to_writer_pretty(w, &doc).map_err(std::io::Error::from)
    })?;
    if let (Some(_), Some(label)) = (json, label) {
        let n = scenario.realizations;
        let mut lines = super::check_lines(label, n, n as f64 / elapsed_s, &verdicts);
        for c in &doc.summary.checks {
            if let Some(first) = &c.first_failure_member {
                lines.push_str(&format!("  {} fails from {first}\n", c.id.name()));
            }
        }
        super::say(&lines)?;
    }
    Ok(())
}

/// `ensemble --model ins --shard K/M --partial FILE`: the blocks of shard K of M, their sums
/// written to `path` (see docs/CLUSTER.md).
fn run_shard<const N: usize>(
    config: &InsConfig,
    scenario: &Scenario,
    shard: &str,
    path: &Path,
    quiet: bool,
) -> Result<()> {
    let blocks = blocks::partition(scenario.realizations);
    let shard = super::shards::parse_shard(shard, blocks.blocks, blocks.realizations)?;
    let range = blocks.shard_blocks(shard);
    let realizations = range
        .clone()
        .map(|b| blocks.block_realizations(b).count() as u64)
        .sum();
    let (k, m) = (shard.index, shard.of);
    // Both files are made before the run: a destination that cannot be written is refused at
    // once, and neither is left behind by a failure (or by SIGINT or SIGTERM).
    let mut file = AtomicFile::create(path)?;
    // The header carries the run time, so blocks wait in a scratch file until the run ends.
    let (spool, spool_file) = ScratchFile::beside(path, "blocks")?;
    let mut spool_w = std::io::BufWriter::new(spool_file);
    let start = std::time::Instant::now();
    let track = Track::of(scenario);
    let mut bar = super::Bar::new(quiet);
    bar.start(&format!("ins shard {k}/{m}"), realizations);
    let mut written = Ok(());
    ins_ensemble::run_blocks::<N>(
        scenario,
        &track,
        &blocks,
        range.clone(),
        |done| bar.advance(done),
        |b, sums| {
            if written.is_ok() {
                written = spool_w.write_all(&partial::encode_block(b, sums));
            }
        },
    )?;
    bar.finish();
    let empty = ins_ensemble::empty_sums::<N>(scenario, &track);
    let elapsed_s = start.elapsed().as_secs_f64();
    let header = InsPartialHeader::new(config, &empty, shard, range.clone(), elapsed_s);
    written
        .and_then(|()| spool_w.flush())
        .map_err(|e| spool.error(e))?;
    drop(spool_w);
    let mut blocks_read = std::io::BufReader::new(spool.open()?);
    partial::write_partial(file.writer(), &header, &mut blocks_read).map_err(|e| file.error(e))?;
    file.commit()?;
    if !quiet {
        super::say(&format!(
            "three axes, shard {k}/{m}: blocks {}..{} ({realizations} realizations) written to \
             {}\n",
            range.start,
            range.end,
            path.display()
        ))?;
    }
    Ok(())
}

/// Whether the partial files `paths` are of the three-axis ensemble (all of them) or of the
/// one-axis one (all of them).
///
/// # Errors
/// [`PartialError`] naming a file that cannot be read or whose header is damaged, or the first
/// file of another model than the first file's.
pub(super) fn is_ins_merge(paths: &[PathBuf]) -> Result<bool, PartialError> {
    let mut first: Option<(String, String)> = None;
    for (name, mut r) in super::shards::open_partials(paths)? {
        let (json, _) = accelcal::ensemble::partial::read_header_line(&mut r, &name)?;
        let model = accelcal::ensemble::partial::header_model(&json);
        match &first {
            None => first = Some((name, model)),
            Some((first_name, first_model)) if *first_model != model => {
                return Err(PartialError::Mismatch {
                    file: name,
                    why: format!(
                        "a partial of the {model} model, {first_name} of the {first_model} \
                         model: the files of one ensemble only"
                    ),
                });
            }
            Some(_) => {}
        }
    }
    Ok(first.is_some_and(|(_, model)| model == partial::MODEL))
}

/// `merge` of three-axis partial files: the JSON one `ensemble --model ins` run writes.
pub(super) fn run_merge(args: &MergeArgs) -> Result<()> {
    if let Some(path) = &args.json {
        accelcal::output::check_file(path)?;
    }
    let shards = partial::open(super::shards::open_partials(&args.files)?)?;
    let label = format!("three axes (merged from {} shards)", args.files.len());
    let label = (!args.quiet).then_some(label.as_str());
    let json = args.json.as_deref();
    with_layout!(shards.layout(), N => {
        let m = shards.merge::<N>()?;
        write_document(&m.config, &m.scenario, &m.sums, m.elapsed_s, json, label)
    })
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
    let scenario = load_scenario(&args.model, args.kind.unwrap_or(ModelKind::Ins))?;
    let names = [IMU_FILE, GNSS_FILE, TRUTH_FILE];
    check_directory(dir, &names)?;
    let mut staged = StagedFiles::create(dir, &names)?;
    let written = {
        let [imu, gnss, truth]: [_; 3] = staged
            .writers()
            .try_into()
            .map_err(|_| anyhow::anyhow!("three staged log files"))?;
        write_realization(&scenario, args.realization, imu, gnss, truth)?
    };
    staged.commit()?;
    let deg_h = |x: f64| (x * 3600.0).to_degrees();
    let (g, a) = (written.gyro_bias_rad_s, written.accel_bias_m_s2);
    let mounted = written.mounting_rpy_deg.map_or(String::new(), |[r, p, y]| {
        format!(", mounted at roll {r:.2}°, pitch {p:.2}°, yaw {y:.2}° in the car")
    });
    super::say(&format!(
        "realization {} (three axes, {} s at {} Hz): gyro biases {:.2}, {:.2}, {:.2} °/h, \
         accelerometer biases {:.3}, {:.3}, {:.3} mg at the start{mounted}; {} IMU samples and \
         {} fixes written to {} ({IMU_FILE}, {GNSS_FILE}, {TRUTH_FILE})\n",
        args.realization,
        scenario.duration_s,
        scenario.imu_rate_hz,
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
