//! `accelcal allan`: the noise terms of a static accelerometer log (`--accel`), or of every
//! channel of a static IMU log (`--imu`).

use std::io::{IsTerminal, Write as _};

use anyhow::{Context, Result};

use crate::cli::AllanArgs;
use accelcal::allan::imu::stream::StreamError;
use accelcal::allan::imu::{self, ImuAnalysis};
use accelcal::allan::{self, Term, export};
use accelcal::format::{count, interval_digits, sig};
use accelcal::input::container::{Container, Kind, copy_stream};
use accelcal::input::csv::piped::PipedLog;
use accelcal::input::csv::read::LogFile;
use accelcal::input::csv::static_log::read_static_log;
use accelcal::input::imu_channels_csv::CsvRecords;
use accelcal::input::recording;
use accelcal::input::records::{Channel, ImuRecords, Sensor};
use accelcal::output::StagedFiles;
use accelcal::report::allan as page;
use accelcal::report::allan_imu as imu_page;

const JSON_FILE: &str = "allan.json";
const TOML_FILE: &str = "noise.toml";
const YAML_FILE: &str = "imu.yaml";
const PAGE_FILE: &str = "index.html";

pub(super) fn run_allan(args: &AllanArgs) -> Result<()> {
    if !(args.confidence > 0.0 && args.confidence < 1.0) {
        return Err(allan::AllanError::Confidence(args.confidence).into());
    }
    let note = |text: &str| {
        if !args.quiet && std::io::stderr().is_terminal() {
            eprintln!("{text}");
        }
    };
    let accel = match (&args.accel, &args.imu) {
        (_, Some(path)) => return run_imu(args, path),
        (Some(path), None) => path,
        // clap requires one of the two.
        (None, None) => anyhow::bail!("allan needs --accel FILE or --imu FILE"),
    };
    // An output that cannot be written is refused before the log is read.
    accelcal::output::check_directory(&args.out, &[JSON_FILE, TOML_FILE, YAML_FILE, PAGE_FILE])?;
    let source = LogFile::new(accel);
    // The reader names its columns with static strings; one name per run is leaked on purpose.
    let column: &'static str = Box::leak(args.column.clone().into_boxed_str());
    note("reading the log…");
    let log = read_static_log(&source, column)?;
    note("computing the Allan deviation and fitting the noise terms…");
    let a = allan::analyse(&log.values, log.sample_period_s, args.confidence)
        .with_context(|| format!("{} (column {column})", accel.display()))?;
    let name = format!("{} (column {column})", accel.display());
    let html = page::render(&a, &name, &command(args, accel))?;
    let files: [(&str, String); 4] = [
        (JSON_FILE, export::allan_json(&a)),
        (TOML_FILE, export::noise_toml(&a, &name)),
        (YAML_FILE, export::imu_yaml(&a, &name)),
        (PAGE_FILE, html),
    ];
    let names: Vec<&str> = files.iter().map(|f| f.0).collect();
    let mut staged = StagedFiles::create(&args.out, &names)?;
    for (file, text) in &files {
        staged
            .writer(file)
            .write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", args.out.join(file).display()))?;
    }
    staged.commit()?;
    super::say(&format!("{}\n", summary(&a, &args.out)))?;
    Ok(())
}

/// A term as the printed line gives it: the estimate with its interval, or its bound.
fn term_text(a: &allan::Analysis, t: Term, unit: &str) -> String {
    match a.term(t) {
        Some(e) => match (e.value, e.lower) {
            (Some(v), Some(lo)) => {
                let d = interval_digits(v, lo, e.upper, 3);
                let (lo, hi) = (sig(lo, d), sig(e.upper, d));
                format!("{} [{lo}, {hi}] {unit}", sig(v, d.max(4)))
            }
            _ => format!("unresolved (≤ {} {unit})", sig(e.upper, 3)),
        },
        None => "not fitted".to_string(),
    }
}

fn summary(a: &allan::Analysis, out: &std::path::Path) -> String {
    let term = |t: Term, unit: &str| term_text(a, t, unit);
    let ramp = a
        .term(Term::RateRamp)
        .filter(|t| t.value.is_some())
        .map_or(String::new(), |_| {
            format!(", R = {}", term(Term::RateRamp, "m/s³"))
        });
    format!(
        "{} samples, τ₀ = {} s: N = {}, B = {}, K = {}{ramp} ({} % intervals); {}; written to {}",
        count(a.samples as u64),
        sig(a.sample_period_s, 6),
        term(Term::VelocityRandomWalk, "m/s/√s"),
        term(Term::BiasInstability, "m/s²"),
        term(Term::AccelerationRandomWalk, "m/s²/√s"),
        sig(100.0 * a.confidence, 3),
        page::verdict_sentence(a),
        out.display()
    )
}

/// The command line that reproduces the analysis.
fn command(args: &AllanArgs, accel: &std::path::Path) -> String {
    format!(
        "accelcal allan --accel {} --column {} --confidence {} --out {}",
        accel.display(),
        args.column,
        args.confidence,
        args.out.display()
    )
}

/// `allan --imu`: every channel of the log, the files of the IMU and one line per channel.
fn run_imu(args: &AllanArgs, path: &std::path::Path) -> Result<()> {
    let note = |text: &str| {
        if !args.quiet && std::io::stderr().is_terminal() {
            eprintln!("{text}");
        }
    };
    let axis_files: Vec<String> = Channel::ALL
        .into_iter()
        .filter(|c| c.sensor() == Sensor::Accelerometer)
        .map(imu::export::axis_toml_file)
        .collect();
    let mut all: Vec<&str> = vec![JSON_FILE, TOML_FILE, YAML_FILE, PAGE_FILE];
    all.extend(axis_files.iter().map(String::as_str));
    accelcal::output::check_directory(&args.out, &all)?;
    note("reading the log and computing every channel's Allan deviation…");
    let a = analyse_imu_log(args, path)?;
    let name = path.display().to_string();
    let command = format!(
        "accelcal allan --imu {} --confidence {} --out {}",
        name,
        args.confidence,
        args.out.display()
    );
    let mut files: Vec<(String, String)> = vec![
        (JSON_FILE.to_string(), imu::export::allan_json(&a)),
        (TOML_FILE.to_string(), imu::export::noise_toml(&a, &name)),
        (YAML_FILE.to_string(), imu::export::imu_yaml(&a, &name)),
        (
            PAGE_FILE.to_string(),
            imu_page::render(&a, &name, &command)?,
        ),
    ];
    for c in a.of(Sensor::Accelerometer) {
        let axis = format!("{name} (column {})", c.channel.column());
        files.push((
            imu::export::axis_toml_file(c.channel),
            export::noise_toml(&c.analysis, &axis),
        ));
    }
    let names: Vec<&str> = files.iter().map(|f| f.0.as_str()).collect();
    let mut staged = StagedFiles::create(&args.out, &names)?;
    for (file, text) in &files {
        staged
            .writer(file)
            .write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", args.out.join(file).display()))?;
    }
    staged.commit()?;
    super::say(&imu_summary(&a, &args.out))?;
    Ok(())
}

/// The analysis of every channel of the log `path`: a regular file or a recording read twice
/// from disk ([`imu::stream`]), a stream (a pipe, `/dev/stdin`) copied once to a temporary file
/// read twice, as CSV or as the recording its first bytes say it is. What the reading found
/// amiss but read past is printed as warnings.
fn analyse_imu_log(args: &AllanArgs, path: &std::path::Path) -> Result<ImuAnalysis> {
    let source = LogFile::new(path);
    let name = path.display().to_string();
    let regular_file = std::fs::metadata(path).is_ok_and(|m| m.is_file());
    let spill_dir = spill_directory(&args.out);
    let topic = args.topic.as_deref();
    let read_as_csv = || {
        if topic.is_some() {
            return Err(super::logs::UsageError(format!(
                "--topic names a topic of an MCAP file or a ROS bag; {name} is read as CSV"
            )));
        }
        Ok(())
    };
    let piped: PipedLog;
    let records: Box<dyn ImuRecords + '_> = if recording::is_recording(path) {
        recording::open_recording(path, topic)?
    } else if regular_file {
        read_as_csv()?;
        Box::new(CsvRecords::open(&source)?)
    } else {
        // A stream is read once, into a temporary file read twice.
        let expected = "a CSV log (UTF-8 text), an MCAP file or a ROS 1 bag";
        match copy_stream(path, &spill_dir, expected)? {
            (kind @ (Kind::Mcap | Kind::Ros1), file) => {
                recording::open_stream(Container::copy(&name, file), kind, topic)?
            }
            (_, file) => {
                read_as_csv()?;
                piped = PipedLog::from_copy(&name, file);
                Box::new(CsvRecords::open(&piped)?)
            }
        }
    };
    let analysis = imu::stream::analyse_records(
        records.as_ref(),
        args.confidence,
        &spill_dir,
        args.memory.saturating_mul(1 << 20),
    );
    // Warnings go to standard error even with --quiet: they are about the numbers.
    for w in records.warnings() {
        eprintln!("warning: {w}");
    }
    match analysis {
        Ok(a) => Ok(a),
        Err(StreamError::Log(e)) => Err(e.into()),
        Err(StreamError::Spill(e)) => Err(anyhow::Error::new(e).context(format!(
            "the temporary file of the phase in {}",
            spill_dir.display()
        ))),
        Err(StreamError::Channel(e)) => Err(anyhow::Error::new(e).context(name)),
    }
}

/// Where a long log's phase is kept while it is analysed: beside the output directory (on the
/// disk the results go to, where a temporary directory may be memory), else the system's
/// temporary directory.
fn spill_directory(out: &std::path::Path) -> std::path::PathBuf {
    let parent = match out.parent() {
        Some(p) if p.as_os_str().is_empty() => std::path::Path::new("."),
        Some(p) => p,
        None => out,
    };
    if parent.is_dir() {
        parent.to_path_buf()
    } else {
        std::env::temp_dir()
    }
}

/// The printed lines of `allan --imu`: the extent, one line per channel, each sensor's keys.
fn imu_summary(a: &ImuAnalysis, out: &std::path::Path) -> String {
    let mut s = format!(
        "{} samples per channel, τ₀ = {} s ({} % intervals):\n",
        count(a.samples as u64),
        sig(a.sample_period_s, 6),
        sig(100.0 * a.confidence, 3)
    );
    for c in &a.channels {
        let sensor = c.channel.sensor();
        let unit = |t| sensor.term_unit(t);
        let t = |term| term_text(&c.analysis, term, unit(term));
        s.push_str(&format!(
            "  {}: N = {}, B = {}, K = {}; {}\n",
            c.channel.column(),
            t(Term::VelocityRandomWalk),
            t(Term::BiasInstability),
            t(Term::AccelerationRandomWalk),
            page::verdict_sentence(&c.analysis)
        ));
    }
    for sensor in Sensor::ALL {
        let largest = |term| {
            a.largest(sensor, term).map_or(String::new(), |l| {
                let bound = if l.upper_bound { "≤ " } else { "" };
                format!(
                    "{bound}{} {} ({})",
                    sig(l.value, 4),
                    sensor.term_unit(term),
                    l.channel.column()
                )
            })
        };
        if a.of(sensor).next().is_some() {
            s.push_str(&format!(
                "imu.yaml {}: noise density {}, random walk {} (the largest of the axes)\n",
                sensor.key(),
                largest(Term::VelocityRandomWalk),
                largest(Term::AccelerationRandomWalk)
            ));
        }
    }
    s.push_str(&format!("written to {}\n", out.display()));
    s
}
