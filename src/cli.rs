//! Command-line definitions, and nothing else.

use std::path::PathBuf;

use clap::builder::{EnumValueParser, TypedValueParser};
use clap::{ArgGroup, Args, Parser, Subcommand, ValueEnum};

use accelcal::config::{AccelerometerOutput, TruthModel};
use accelcal::ensemble::Engine;

pub mod calibrate;
pub use calibrate::CalibrateArgs;

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
    /// Run every case's ensemble and one realization, and write index.html, data.json and view.json.
    Report(ReportArgs),
    /// Run one ensemble and write its statistics and verdicts as JSON.
    Ensemble(EnsembleArgs),
    /// Run one realization: write it at every accelerometer sample as CSV, and/or its sensor logs.
    Simulate(SimulateArgs),
    /// Merge the partial files of every shard of one ensemble into its JSON summary.
    Merge(MergeArgs),
    /// Vary each statistic the filter assumes: exact actual accuracy, predicted and measured
    /// detection by the checks.
    Sensitivity(SensitivityArgs),
    /// Calibrate the bias from an accelerometer log and a GPS log: filter, smoother, NIS test.
    Calibrate(CalibrateArgs),
    /// Measure the accelerometer's noise terms from a static log: Allan deviation with
    /// intervals, N, B and K, and noise.toml for calibrate.
    Allan(AllanArgs),
    /// Calibrate an IMU on a table: bias, scale factors and non-orthogonality from a few static
    /// poses turned by hand, each with its interval, written to intrinsics.json.
    Intrinsics(IntrinsicsArgs),
    /// Print the default configuration file.
    Config(ConfigArgs),
}

/// Options of `config`.
#[derive(Debug, Args)]
pub struct ConfigArgs {
    /// Which model's file: the one-axis study of the accelerometer's bias, or the three-axis
    /// INS/GNSS study.
    #[arg(long, value_enum, default_value_t = ModelKind::Accelerometer)]
    pub model: ModelKind,
}

/// Which study a configuration file describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelKind {
    /// The one-axis accelerometer and GPS study (the default).
    #[value(name = "accelerometer")]
    Accelerometer,
    /// The three-axis strapdown INS/GNSS study.
    #[value(name = "ins")]
    Ins,
    /// The three-axis study with the IMU in a car: its mounting, the non-holonomic constraint.
    #[value(name = "car")]
    Car,
}

/// Options shared by every command that runs the model.
#[derive(Debug, Args, Default, Clone)]
pub struct ModelArgs {
    /// Configuration file (TOML); missing fields take their defaults (see `accelcal config`).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Seed of the random streams, overriding ensemble.seed.
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Silence the progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The simulated case, for commands that run one.
#[derive(Debug, Args, Default, Clone)]
pub struct CaseArgs {
    /// Truth model, overriding ensemble.truth.
    #[arg(long, value_name = "MODEL", value_parser = truth_parser())]
    pub truth: Option<TruthModel>,
    /// What the accelerometer reports, overriding accelerometer.output.
    #[arg(long, value_name = "OUTPUT", value_parser = output_parser())]
    pub accelerometer_output: Option<AccelerometerOutput>,
}

/// Options of `report`: it runs every case of the study (euler truth with point samples, the
/// closed-form truth with point samples and with interval means).
#[derive(Debug, Args)]
pub struct ReportArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Number of realizations of each ensemble, overriding ensemble.realizations.
    #[arg(long, value_name = "N")]
    pub realizations: Option<u64>,
    /// Directory that receives index.html, data.json and view.json.
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
    /// Which study: the one-axis accelerometer or the three-axis INS/GNSS filter (default: the
    /// configuration file's `model`, the one-axis study without one).
    #[arg(long = "model", value_enum)]
    pub kind: Option<ModelKind>,
    #[command(flatten)]
    pub case: CaseArgs,
    /// Number of realizations, overriding ensemble.realizations.
    #[arg(long, value_name = "N")]
    pub realizations: Option<u64>,
    /// Write the JSON here instead of to standard output.
    #[arg(long, value_name = "FILE", conflicts_with = "shard")]
    pub json: Option<PathBuf>,
    /// Run only shard K of M (K counted from 1) and write its sums to --partial.
    #[arg(long, value_name = "K/M", requires = "partial")]
    pub shard: Option<String>,
    /// Where a shard writes its partial sums (see `accelcal merge`).
    #[arg(long, value_name = "FILE", requires = "shard")]
    pub partial: Option<PathBuf>,
    /// How realizations are simulated: `sample` draws and integrates every accelerometer
    /// sample; `epoch` draws the noise's exact effect once per GPS interval (same distribution
    /// at the fixes, several times faster). Default: sample; the one-axis model's option only.
    #[arg(long, value_parser = engine_parser())]
    pub engine: Option<Engine>,
}

#[derive(Debug, Args)]
pub struct SensitivityArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Factors on the assumed standard deviations (a variance is scaled by the square),
    /// overriding sensitivity.factors (default 0.25,0.5,2,4).
    #[arg(
        long,
        value_name = "F,…",
        value_delimiter = ',',
        num_args = 1,
        allow_negative_numbers = true
    )]
    pub factors: Option<Vec<f64>>,
    /// The [filter] statistics to vary (default: all six).
    #[arg(long, value_name = "KEY,…", value_delimiter = ',')]
    pub parameters: Vec<String>,
    /// Realizations per Monte Carlo ensemble, overriding ensemble.realizations.
    #[arg(long, value_name = "N")]
    pub realizations: Option<u64>,
    /// Independent Monte Carlo ensembles per statistic and factor (0: no Monte Carlo),
    /// overriding sensitivity.ensembles.
    #[arg(long, value_name = "K")]
    pub ensembles: Option<u64>,
    /// Sampled ensembles per statistic and factor that predict the detection probabilities
    /// (0: no prediction), overriding sensitivity.draws.
    #[arg(long, value_name = "D")]
    pub draws: Option<u64>,
    /// How the Monte Carlo ensembles simulate their realizations (see `ensemble --engine`).
    #[arg(long, value_parser = engine_parser(), default_value_t = Engine::Epoch)]
    pub engine: Engine,
    /// Write the JSON here instead of to standard output.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The partial files, one per shard, in any order.
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// Write the JSON here instead of to standard output.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("output").required(true).multiple(true).args(["csv", "logs"])))]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub case: CaseArgs,
    /// Index of the realization to simulate (its random stream is (seed, index)).
    #[arg(long, value_name = "L", default_value_t = 0)]
    pub realization: u64,
    /// Write the realization at every sample (truth, integration, estimate, covariance) here.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write the sensor logs into this directory: accelerometer.csv, gps.csv and truth.csv
    /// (with --model ins: imu.csv, gnss.csv and truth.csv).
    #[arg(long, value_name = "DIR")]
    pub logs: Option<PathBuf>,
    /// Which study: the one-axis accelerometer, or the three-axis INS/GNSS drive (its logs only;
    /// default: the configuration file's `model`, the one-axis study without one).
    #[arg(long = "model", value_enum)]
    pub kind: Option<ModelKind>,
}

/// The values `--truth` accepts, each with its help; parsed into a [`TruthModel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TruthArg {
    /// Closed-form integral of the acceleration profile, eq. (1) of the problem statement.
    Analytic,
    /// The true acceleration integrated with the accelerometer's Euler formula, eq. (4): the error
    /// dynamics of eq. (5) are then exact.
    Euler,
}

impl From<TruthArg> for TruthModel {
    fn from(arg: TruthArg) -> Self {
        match arg {
            TruthArg::Analytic => TruthModel::Analytic,
            TruthArg::Euler => TruthModel::Euler,
        }
    }
}

/// The values `--accelerometer-output` accepts; parsed into an [`AccelerometerOutput`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum OutputArg {
    /// The acceleration at the sample time: a_c(t_j) = a(t_j) + b + w(t_j), eq. (2) of the
    /// problem statement.
    #[value(name = "sample")]
    Sample,
    /// The mean acceleration over the sample interval, as a strapdown IMU's delta-velocity
    /// output gives it: a_c(t_j) = (1/Δt)∫ a dt over [t_j, t_j + Δt] + b + w(t_j). The Euler
    /// velocity integration is then exact.
    #[value(name = "interval_mean")]
    IntervalMean,
}

impl From<OutputArg> for AccelerometerOutput {
    fn from(arg: OutputArg) -> Self {
        match arg {
            OutputArg::Sample => AccelerometerOutput::Sample,
            OutputArg::IntervalMean => AccelerometerOutput::IntervalMean,
        }
    }
}

/// The values `--engine` accepts; parsed into an [`Engine`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EngineArg {
    /// Every accelerometer sample drawn and integrated, as the problem statement describes it.
    Sample,
    /// One exact draw of the accelerometer noise's effect per GPS interval: the
    /// same distribution at the fixes with about a tenth of the random numbers.
    Epoch,
}

impl From<EngineArg> for Engine {
    fn from(arg: EngineArg) -> Self {
        match arg {
            EngineArg::Sample => Engine::Sample,
            EngineArg::Epoch => Engine::Epoch,
        }
    }
}

fn truth_parser() -> impl TypedValueParser<Value = TruthModel> {
    EnumValueParser::<TruthArg>::new().map(TruthModel::from)
}

fn output_parser() -> impl TypedValueParser<Value = AccelerometerOutput> {
    EnumValueParser::<OutputArg>::new().map(AccelerometerOutput::from)
}

fn engine_parser() -> impl TypedValueParser<Value = Engine> {
    EnumValueParser::<EngineArg>::new().map(Engine::from)
}

/// Options of `allan`.
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("log").required(true).args(["accel", "imu"])))]
pub struct AllanArgs {
    /// The static accelerometer log: CSV with a column t_s and the axis column.
    #[arg(long, value_name = "FILE")]
    pub accel: Option<PathBuf>,
    /// A static six-channel IMU log: CSV with t_s and any of ax_m_s2, ay_m_s2, az_m_s2,
    /// gx_rad_s, gy_rad_s, gz_rad_s; an MCAP file or a ROS 2 bag directory (storage mcap) of
    /// sensor_msgs/msg/Imu, or a ROS 1 bag of sensor_msgs/Imu. Every channel analysed.
    #[arg(long, value_name = "FILE", conflicts_with = "column")]
    pub imu: Option<PathBuf>,
    /// The IMU topic of an MCAP file or ROS 2 bag (with --imu; needed when it has several).
    #[arg(long, value_name = "NAME", requires = "imu")]
    pub topic: Option<String>,
    /// The axis column to analyse (with --accel).
    #[arg(long, value_name = "NAME", default_value = "accel_m_s2")]
    pub column: String,
    /// Directory that receives allan.json, noise.toml, imu.yaml and index.html (with --imu also
    /// noise_<column>.toml for each accelerometer axis).
    #[arg(long, value_name = "DIR", default_value = "allan")]
    pub out: PathBuf,
    /// Confidence of the two-sided intervals, in (0, 1).
    #[arg(long, value_name = "C", default_value_t = accelcal::allan::DEFAULT_CONFIDENCE)]
    pub confidence: f64,
    /// Memory the log may be held in, MB (with --imu; 64 bytes a six-channel row): a log that fits is
    /// read once; a longer one is read twice and streamed, in memory that does not grow with
    /// its length. The numbers are the same either way.
    #[arg(long, value_name = "MB", default_value_t = accelcal::allan::imu::stream::DEFAULT_HOLD_BYTES >> 20, requires = "imu")]
    pub memory: usize,
    /// Print nothing but the result.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Options of `intrinsics`.
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("local_gravity").required(true).args(["latitude", "gravity"])))]
pub struct IntrinsicsArgs {
    /// The six-axis log of the session: CSV with t_s, ax_m_s2, ay_m_s2, az_m_s2, gx_rad_s,
    /// gy_rad_s, gz_rad_s; an MCAP file or a ROS 2 bag directory (storage mcap) of
    /// sensor_msgs/msg/Imu, or a ROS 1 bag of sensor_msgs/Imu.
    #[arg(long, value_name = "FILE")]
    pub imu: PathBuf,
    /// The IMU topic of an MCAP file or a bag (needed when it has several).
    #[arg(long, value_name = "NAME")]
    pub topic: Option<String>,
    /// Geodetic latitude of the table, degrees: local gravity is then normal gravity there (with
    /// --height), and the Earth's rate is allowed for by its vertical and horizontal parts.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub latitude: Option<f64>,
    /// Height of the table above the ellipsoid, m (with --latitude).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 0.0,
        requires = "latitude",
        allow_negative_numbers = true
    )]
    pub height: f64,
    /// Local gravity's magnitude, m/s², when known better than normal gravity (instead of
    /// --latitude; the Earth's rate is then allowed for in any direction).
    #[arg(long, value_name = "M_S2", conflicts_with = "latitude")]
    pub gravity: Option<f64>,
    /// The static detector's window, s.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub window: f64,
    /// The shortest static interval kept, s.
    #[arg(long, value_name = "S", default_value_t = 2.0)]
    pub min_static: f64,
    /// Rate at which the detector calls a still window moving.
    #[arg(long, value_name = "P", default_value_t = 1e-3)]
    pub false_alarm: f64,
    /// Confidence of the two-sided intervals, in (0, 1).
    #[arg(long, value_name = "C", default_value_t = 0.95)]
    pub confidence: f64,
    /// Rate at which the goodness-of-fit tests reject a log drawn from the model, in (0, 1).
    #[arg(long, value_name = "P", default_value_t = 0.01)]
    pub alpha: f64,
    /// Directory that receives intrinsics.json.
    #[arg(long, value_name = "DIR", default_value = "intrinsics")]
    pub out: PathBuf,
    /// Print nothing but the result.
    #[arg(long, short)]
    pub quiet: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value the command line accepts parses into the domain value of the same name, and
    /// every domain value is reachable.
    fn names_agree<A: ValueEnum, D: PartialEq + std::fmt::Debug>(
        map: impl Fn(A) -> D,
        name: impl Fn(&D) -> &'static str,
        all: &[D],
    ) {
        let mapped: Vec<D> = A::value_variants()
            .iter()
            .map(|a| {
                let value = a.to_possible_value().expect("no value is skipped");
                let d = map(a.clone());
                assert_eq!(value.get_name(), name(&d));
                d
            })
            .collect();
        assert_eq!(mapped.len(), all.len());
        assert!(all.iter().all(|d| mapped.contains(d)), "{all:?}");
    }

    #[test]
    fn command_line_values_map_onto_the_domain_types() {
        names_agree(
            |a: TruthArg| TruthModel::from(a),
            |t| t.name(),
            &TruthModel::ALL,
        );
        names_agree(
            |a: OutputArg| AccelerometerOutput::from(a),
            |o| o.name(),
            &[
                AccelerometerOutput::Sample,
                AccelerometerOutput::IntervalMean,
            ],
        );
        names_agree(
            |a: EngineArg| Engine::from(a),
            |e| e.name(),
            &[Engine::Sample, Engine::Epoch],
        );
    }

    #[test]
    fn bare_command_and_report_subcommand_share_their_defaults() {
        let bare = Cli::parse_from(["accelcal"]);
        assert!(bare.command.is_none());
        let explicit = Cli::parse_from(["accelcal", "report"]);
        let Some(Command::Report(args)) = explicit.command else {
            panic!("report subcommand")
        };
        let default = ReportArgs::default();
        assert_eq!(args.out, default.out);
        assert_eq!(default.out, std::path::Path::new("report"));
    }
}
