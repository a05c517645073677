//! `accelcal intrinsics`: an IMU calibrated on a table from a few static poses.

use std::io::{IsTerminal, Write as _};

use anyhow::{Context, Result};

use crate::cli::IntrinsicsArgs;
use accelcal::format::sig;
use accelcal::input::csv::read::LogFile;
use accelcal::input::imu_channels_csv::read_imu_log;
use accelcal::input::recording;
use accelcal::input::records::Geodetic;
use accelcal::ins::earth::normal_gravity_m_s2;
use accelcal::intrinsics::accel::Estimate;
use accelcal::intrinsics::detect::DetectorSettings;
use accelcal::intrinsics::{self, Intrinsics, IntrinsicsError, Settings, SixAxisLog};
use accelcal::output::StagedFiles;

const JSON_FILE: &str = "intrinsics.json";
const PAGE_FILE: &str = "index.html";

/// The settings the command line gives.
fn settings(args: &IntrinsicsArgs) -> Result<Settings, IntrinsicsError> {
    let gravity = match (args.gravity, args.latitude) {
        (Some(g), _) => g,
        (None, Some(lat)) => {
            if !(-90.0..=90.0).contains(&lat) {
                return Err(IntrinsicsError::Setting {
                    name: "--latitude",
                    value: lat,
                    expected: "−90° ≤ latitude ≤ 90°",
                });
            }
            if !(-500.0..=9000.0).contains(&args.height) {
                return Err(IntrinsicsError::Setting {
                    name: "--height",
                    value: args.height,
                    expected: "−500 m ≤ height ≤ 9000 m",
                });
            }
            normal_gravity_m_s2(&Geodetic {
                lat_rad: lat.to_radians(),
                lon_rad: 0.0,
                height_m: args.height,
            })
        }
        (None, None) => unreachable!("clap requires one of --latitude and --gravity"),
    };
    let s = Settings {
        gravity_m_s2: gravity,
        latitude_rad: args.latitude.map(f64::to_radians),
        detector: DetectorSettings {
            window_s: args.window,
            min_static_s: args.min_static,
            false_alarm: args.false_alarm,
        },
        confidence: args.confidence,
        alpha: args.alpha,
    };
    s.validate()?;
    Ok(s)
}

/// Runs `intrinsics`.
pub(super) fn run(args: &IntrinsicsArgs) -> Result<()> {
    let settings = settings(args)?;
    accelcal::output::check_directory(&args.out, &[JSON_FILE, PAGE_FILE])?;
    let path = &args.imu;
    let name = path.display().to_string();
    if !args.quiet && std::io::stderr().is_terminal() {
        eprintln!("reading the log and finding its static poses…");
    }
    let samples = if recording::is_recording(path) {
        recording::read_recording(path, args.topic.as_deref())?
    } else {
        if args.topic.is_some() {
            return Err(super::logs::UsageError(format!(
                "--topic names a topic of an MCAP file or a ROS bag; {name} is read as CSV"
            ))
            .into());
        }
        read_imu_log(&LogFile::new(path))?
    };
    let log = SixAxisLog::from_samples(&samples).with_context(|| name.clone())?;
    let x = intrinsics::calibrate(&log, &settings).with_context(|| name.clone())?;
    let json = intrinsics::export::intrinsics_json(&x, &name);
    let command = format!(
        "accelcal intrinsics --imu {name} {} --window {} --min-static {} --false-alarm {} --confidence {} --alpha {} --out {}",
        match (args.gravity, args.latitude) {
            (Some(g), _) => format!("--gravity {g}"),
            (None, Some(l)) => format!("--latitude {l} --height {}", args.height),
            (None, None) => String::new(),
        },
        args.window,
        args.min_static,
        args.false_alarm,
        args.confidence,
        args.alpha,
        args.out.display()
    );
    let page = accelcal::report::intrinsics::render(&x, &name, &command)?;
    let mut staged = StagedFiles::create(&args.out, &[JSON_FILE, PAGE_FILE])?;
    for (file, text) in [(JSON_FILE, &json), (PAGE_FILE, &page)] {
        staged
            .writer(file)
            .write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", args.out.join(file).display()))?;
    }
    staged.commit()?;
    super::say(&summary(&x, &args.out))
}

/// `value ± sigma` at 4 significant digits, or "not determined".
fn shown(e: &Estimate, scale: f64, unit: &str) -> String {
    if e.determined {
        format!(
            "{} ± {} {unit}",
            sig(e.value * scale, 4),
            sig(e.sigma * scale, 2)
        )
    } else {
        "not determined".to_string()
    }
}

/// The printed lines: the poses, the accelerometers', the gyros', the tests.
fn summary(x: &Intrinsics, out: &std::path::Path) -> String {
    let d = &x.detection;
    let mut s = format!(
        "{} static poses found ({} samples, τ₀ = {} s, window {} s, false alarm {}):\n",
        d.intervals.len(),
        d.samples,
        sig(d.sample_period_s, 4),
        sig(d.settings.window_s, 3),
        sig(d.settings.false_alarm, 2)
    );
    for (i, p) in d.intervals.iter().enumerate() {
        let f = p.mean_specific_force;
        s += &format!(
            "  {:>2}. {:>8} – {:>8} s   f = ({}, {}, {}) m/s²\n",
            i + 1,
            sig(p.first as f64 * d.sample_period_s, 5),
            sig(p.last as f64 * d.sample_period_s, 5),
            sig(f[0], 5),
            sig(f[1], 5),
            sig(f[2], 5)
        );
    }
    s += &accel_lines(x);
    s += &gyro_lines(x);
    s += &format!(
        "{} intervals at {} % confidence in {}, the page in {}\n",
        JSON_FILE,
        sig(100.0 * x.settings.confidence, 3),
        out.join(JSON_FILE).display(),
        out.join(PAGE_FILE).display()
    );
    s
}

/// The axes' names.
const AXES: [&str; 3] = ["x", "y", "z"];

/// The accelerometers' lines.
fn accel_lines(x: &Intrinsics) -> String {
    let a = &x.accel;
    let mut s = "accelerometers:\n".to_string();
    for (i, axis) in AXES.iter().enumerate() {
        let bias = Estimate {
            value: a.params[i],
            sigma: a.covariance[(i, i)].sqrt(),
            lower: 0.0,
            upper: 0.0,
            determined: a.determined[i],
        };
        s += &format!(
            "  {axis}: bias {}, scale {}\n",
            shown(&bias, 1.0, "m/s²"),
            shown(&a.scale_ppm[i], 1.0, "ppm")
        );
    }
    for (e, pair) in a.misalignment_rad.iter().zip(["xy", "xz", "yz"]) {
        s += &format!("  non-orthogonality {pair}: {}\n", shown(e, 1e3, "mrad"));
    }
    s += &goodness_line("", a.chi_squared, a.dof, a.p_value, x.settings.alpha);
    if a.p_value.is_some_and(|p| p < x.settings.alpha) {
        s += &format!(
            "  the poses' magnitudes scatter {}× more than the noise measured in them explains (a \
             drift such as a warm-up's, or a pose that moved): the intervals hold only if the model \
             does\n",
            sig((a.chi_squared / a.dof).sqrt(), 2)
        );
    }
    if let Some(up) = a.suggested_up {
        let free: Vec<&str> = accelcal::intrinsics::accel::PARAMETER_NAMES
            .iter()
            .zip(a.determined)
            .filter(|(_, d)| !d)
            .map(|(n, _)| *n)
            .collect();
        s += &format!(
            "  the poses leave {} free: add a pose with the sensor's ({}, {}, {}) pointing up\n",
            free.join(", "),
            sig(up[0], 2),
            sig(up[1], 2),
            sig(up[2], 2)
        );
    }
    s
}

/// The gyros' lines.
fn gyro_lines(x: &Intrinsics) -> String {
    let mut s = "gyros:\n".to_string();
    let Some(m) = &x.gyro_matrix else {
        for (axis, bias) in AXES.iter().zip(&x.gyro.bias) {
            s += &format!(
                "  {axis}: bias {} (no turn: matrix not determined)\n",
                shown(bias, 1.0, "rad/s")
            );
        }
        return s;
    };
    for (i, axis) in AXES.iter().enumerate() {
        s += &format!(
            "  {axis}: bias {}, scale {}\n",
            shown(&m.bias[i], 1.0, "rad/s"),
            shown(&m.scale_ppm[i], 1.0, "ppm")
        );
    }
    let leans: Vec<String> = m
        .misalignment_rad
        .iter()
        .zip(accelcal::intrinsics::gyro_matrix::MISALIGNMENT_NAMES)
        .map(|(e, n)| format!("{n} {}", shown(e, 1e3, "mrad")))
        .collect();
    s += &format!("  misalignment: {}\n", leans.join(", "));
    s += &goodness_line(
        &format!(" of {} turns and the poses' magnitudes together", m.turns),
        m.chi_squared,
        m.dof,
        m.p_value,
        x.settings.alpha,
    );
    s
}

/// A goodness test's line: χ², its degrees of freedom, p and the verdict at `alpha`.
fn goodness_line(what: &str, chi: f64, dof: f64, p: Option<f64>, alpha: f64) -> String {
    match p {
        Some(p) => format!(
            "  goodness{what}: χ² = {} on {} degrees of freedom, p = {} ({} at α = {})\n",
            sig(chi, 4),
            sig(dof, 3),
            sig(p, 3),
            if p < alpha {
                "rejected"
            } else {
                "not rejected"
            },
            sig(alpha, 2)
        ),
        None => "  goodness: not testable (no degree of freedom left)\n".to_string(),
    }
}
