//! Command-line definitions, and nothing else.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::config::TruthModel;

/// Calibrates an accelerometer's bias with GPS through a Kalman filter, checks the filter with a
/// Monte Carlo ensemble, and writes the study as a self-contained HTML report.
///
/// Without a subcommand, runs `report` with the default configuration.
#[derive(Debug, Parser)]
#[command(name = "accelcal", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one realization and the ensembles, and write index.html and data.json.
    Report(ReportArgs),
    /// Run one ensemble and write its statistics and verdicts as JSON.
    Ensemble(EnsembleArgs),
    /// Run one realization and write it at every accelerometer sample as CSV.
    Simulate(SimulateArgs),
    /// Print the default configuration file.
    Config,
}

/// Options shared by every command that runs the model.
#[derive(Debug, Args, Default, Clone)]
pub struct ModelArgs {
    /// Configuration file (TOML); missing fields take their defaults (see `accelcal config`).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Truth model, overriding ensemble.truth.
    #[arg(long, value_enum, value_name = "MODEL")]
    pub truth: Option<TruthModel>,
    /// Seed of the random streams, overriding ensemble.seed.
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Silence the progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Number of realizations of each ensemble, overriding ensemble.realizations.
    #[arg(long, value_name = "N")]
    pub realizations: Option<u64>,
    /// Directory that receives index.html and data.json.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_REPORT_DIR)]
    pub out: PathBuf,
}

/// Where the report goes unless `--out` says otherwise.
pub const DEFAULT_REPORT_DIR: &str = "report";

/// The arguments of a bare `accelcal`: the default report into [`DEFAULT_REPORT_DIR`].
impl Default for ReportArgs {
    fn default() -> Self {
        Self {
            model: ModelArgs::default(),
            realizations: None,
            out: PathBuf::from(DEFAULT_REPORT_DIR),
        }
    }
}

#[derive(Debug, Args)]
pub struct EnsembleArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Number of realizations, overriding ensemble.realizations.
    #[arg(long, value_name = "N")]
    pub realizations: Option<u64>,
    /// Write the JSON here instead of to standard output.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Index of the realization to simulate (its random stream is (seed, index)).
    #[arg(long, value_name = "L", default_value_t = 0)]
    pub realization: u64,
    /// Write the CSV here.
    #[arg(long, value_name = "FILE")]
    pub csv: PathBuf,
}
