//! `accelcal allan`: the noise terms of a static accelerometer log.

use std::io::{IsTerminal, Write as _};

use anyhow::{Context, Result};

use crate::cli::AllanArgs;
use accelcal::allan::{self, Term, export, log::read_static_log};
use accelcal::format::{count, interval_digits, sig};
use accelcal::logs::read::LogFile;
use accelcal::output::StagedFiles;
use accelcal::report::allan as page;

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
    // An output that cannot be written is refused before the log is read.
    accelcal::output::check_directory(&args.out, &[JSON_FILE, TOML_FILE, YAML_FILE, PAGE_FILE])?;
    let source = LogFile::new(&args.accel);
    // The reader names its columns with static strings; one name per run is leaked on purpose.
    let column: &'static str = Box::leak(args.column.clone().into_boxed_str());
    note("reading the log…");
    let log = read_static_log(&source, column)?;
    note("computing the Allan deviation and fitting the noise terms…");
    let a = allan::analyse(&log.values, log.sample_period_s, args.confidence)
        .with_context(|| format!("{} (column {column})", args.accel.display()))?;
    let name = format!("{} (column {column})", args.accel.display());
    let html = page::render(&a, &name, &command(args))?;
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

fn summary(a: &allan::Analysis, out: &std::path::Path) -> String {
    let term = |t: Term, unit: &str| match a.term(t) {
        Some(e) => match (e.value, e.lower) {
            (Some(v), Some(lo)) => {
                let d = interval_digits(v, lo, e.upper, 3);
                let (lo, hi) = (sig(lo, d), sig(e.upper, d));
                format!("{} [{lo}, {hi}] {unit}", sig(v, d.max(4)))
            }
            _ => format!("unresolved (≤ {} {unit})", sig(e.upper, 3)),
        },
        None => "not fitted".to_string(),
    };
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
fn command(args: &AllanArgs) -> String {
    format!(
        "accelcal allan --accel {} --column {} --confidence {} --out {}",
        args.accel.display(),
        args.column,
        args.confidence,
        args.out.display()
    )
}
