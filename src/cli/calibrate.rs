//! The options of `calibrate`.

use std::path::PathBuf;

use clap::Args;
use clap::builder::TypedValueParser;

use accelcal::calibrate::imu::noise::ImuKey;
use accelcal::likelihood::Key;

/// Options of `calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// The accelerometer log: CSV with columns t_s,accel_m_s2.
    #[arg(
        long,
        value_name = "FILE",
        required_unless_present = "imu",
        requires = "gps",
        conflicts_with = "imu"
    )]
    pub accel: Option<PathBuf>,
    /// The GPS log: CSV with columns t_s,position_m,velocity_m_s.
    #[arg(long, value_name = "FILE", requires = "accel")]
    pub gps: Option<PathBuf>,
    /// A 6-axis IMU log instead: t_s and ax_m_s2…gz_rad_s (rates) or dvx_m_s…dthz_rad.
    #[arg(long, value_name = "FILE", requires = "gnss")]
    pub imu: Option<PathBuf>,
    /// Its GNSS log: t_s,lat_deg,lon_deg,height_m[,vn_m_s,ve_m_s,vd_m_s,sigma_n_m,…].
    #[arg(long, value_name = "FILE", requires = "imu")]
    pub gnss: Option<PathBuf>,
    /// Configuration file (TOML): prior means, [filter] statistics, the nominal rate and α.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Directory that receives estimates.csv, summary.json and index.html.
    #[arg(long, value_name = "DIR", default_value = "calibration")]
    pub out: PathBuf,
    /// Write estimates.csv with one row per accelerometer sample instead of one per GPS fix
    /// (reads the accelerometer log a second time: it must be a file, not a pipe).
    #[arg(long)]
    pub every_sample: bool,
    /// Estimate [filter] noise statistics from the drive by maximum likelihood of the GPS
    /// innovations (with profile-likelihood intervals), then calibrate with them.
    #[arg(long)]
    pub estimate_noise: bool,
    /// The statistics --estimate-noise searches [default: the two GPS σ's, and
    /// bias_random_walk_m_s2_per_sqrt_s when the filter's bias is a random walk; naming it makes
    /// a constant bias a random walk. With --imu: the GNSS σ's, the VRW and the time offset].
    #[arg(
        long,
        value_name = "KEY,…",
        value_delimiter = ',',
        requires = "estimate_noise",
        value_parser = estimate_keys()
    )]
    pub estimate: Vec<EstimateKey>,
    /// The confidence of --estimate-noise's intervals, in (0, 1).
    #[arg(long, value_name = "P", default_value_t = 0.95, value_parser = confidence,
          requires = "estimate_noise")]
    pub confidence: f64,
    /// Print nothing but the result.
    #[arg(long, short)]
    pub quiet: bool,
}

/// A statistic `--estimate` names: of the one-axis calibration or of the three-axis one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EstimateKey {
    /// A one-axis statistic (`--accel`/`--gps`).
    OneAxis(Key),
    /// A three-axis key (`--imu`/`--gnss`).
    ThreeAxis(ImuKey),
}

impl EstimateKey {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            EstimateKey::OneAxis(k) => k.name(),
            EstimateKey::ThreeAxis(k) => k.name(),
        }
    }
}

/// The statistics `--estimate` accepts, each named by its `[filter]` key: every searchable row of
/// the statistics' table ([`Key::ALL`]) and the three-axis keys ([`ImuKey::ALL`]), with their
/// words and unit as help.
fn estimate_keys() -> impl TypedValueParser<Value = EstimateKey> {
    let one = Key::ALL.map(|k| {
        let words = k.0.words;
        let mut help = words[..1].to_uppercase();
        help.push_str(&words[1..]);
        help.push_str(", ");
        help.push_str(k.unit());
        clap::builder::PossibleValue::new(k.name()).help(help)
    });
    let three = ImuKey::ALL.map(|k| {
        let help = format!("With --imu: {}", k.words());
        clap::builder::PossibleValue::new(k.name()).help(help)
    });
    clap::builder::PossibleValuesParser::new(one.into_iter().chain(three)).map(|name| {
        Key::parse(&name).map_or_else(
            || EstimateKey::ThreeAxis(ImuKey::parse(&name).expect("a possible value is a key")),
            EstimateKey::OneAxis,
        )
    })
}

/// A confidence strictly between 0 and 1.
fn confidence(text: &str) -> Result<f64, String> {
    let p: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number; accepted: 0 < P < 1"))?;
    if p > 0.0 && p < 1.0 {
        Ok(p)
    } else {
        Err(format!("{p} is outside the accepted range 0 < P < 1"))
    }
}
