//! `accelcal allan --imu` end to end on a simulated six-channel static log: each channel's record
//! in allan.json is `allan --accel FILE --column COLUMN`'s allan.json bit for bit (a gyro's under
//! its own names); imu.yaml read back by a YAML parser holds the largest term across axes in the
//! units its keys promise; noise.toml is a three-axis configuration the study accepts; bad input
//! exits with 2 naming the file, the line and the field.

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};

use accelcal::allan::simulate::StaticLog;
use accelcal::input::csv::text::{header, push_row};
use serde_json::Value;

const COLUMNS: [&str; 6] = [
    "ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s",
];
const TAU0_S: f64 = 0.01;
const SAMPLES: usize = 200_000;

/// The channel's log: accelerometers N = 2·10⁻³ m/s/√s, K = 10⁻³ m/s²/√s on gravity or zero;
/// gyros N = 10⁻⁴ rad/√s (0.34 °/√h), K = 5·10⁻⁵ rad/s/√s on a 0.01 rad/s bias; each axis a
/// little apart so that the largest is one axis's.
fn channel_log(k: usize) -> StaticLog {
    let spread = 1.0 + 0.1 * (k % 3) as f64;
    if k < 3 {
        StaticLog {
            sample_period_s: TAU0_S,
            velocity_random_walk_m_s_per_sqrt_s: 2e-3 * spread,
            acceleration_random_walk_m_s2_per_sqrt_s: 1e-3 * spread,
            offset_m_s2: if k == 2 { -9.80665 } else { 0.0 },
        }
    } else {
        StaticLog {
            sample_period_s: TAU0_S,
            velocity_random_walk_m_s_per_sqrt_s: 1e-4 * spread,
            acceleration_random_walk_m_s2_per_sqrt_s: 5e-5 * spread,
            offset_m_s2: 0.01,
        }
    }
}

/// A six-channel static log's text (time stamps with the rounding a logger leaves).
fn imu_text() -> String {
    let channels: Vec<Vec<f64>> = (0..6)
        .map(|k| channel_log(k).samples(SAMPLES, 100 + k as u64))
        .collect();
    let mut columns = vec!["t_s"];
    columns.extend(COLUMNS);
    let mut text = header(&columns);
    for i in 0..SAMPLES {
        let mut row = vec![i as f64 * TAU0_S];
        row.extend(channels.iter().map(|c| c[i]));
        push_row(&mut text, &row);
    }
    text
}

fn allan(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .arg("allan")
        .args(args)
        .output()
        .unwrap()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The one-column allan.json's keys as a gyro's record names them (written out here, not taken
/// from the program).
fn as_gyro(mut v: Value) -> Value {
    let renames = [
        ("adev_m_s2", "adev_rad_s"),
        ("adev_lower_m_s2", "adev_lower_rad_s"),
        ("adev_upper_m_s2", "adev_upper_rad_s"),
        ("fit_adev_m_s2", "fit_adev_rad_s"),
    ];
    let fit_renames = [
        (
            "velocity_random_walk_m_s_per_sqrt_s",
            "angle_random_walk_rad_per_sqrt_s",
        ),
        ("bias_instability_m_s2", "bias_instability_rad_s"),
        (
            "acceleration_random_walk_m_s2_per_sqrt_s",
            "rate_random_walk_rad_s_per_sqrt_s",
        ),
        ("rate_ramp_m_s3", "rate_ramp_rad_s2"),
        ("quantization_m_s", "quantization_rad"),
    ];
    let o = v.as_object_mut().unwrap();
    for (from, to) in renames {
        let x = o.remove(from).unwrap();
        o.insert(to.to_string(), x);
    }
    let fit = o.get_mut("fit").unwrap().as_object_mut().unwrap();
    for (from, to) in fit_renames {
        let x = fit.remove(from).unwrap();
        fit.insert(to.to_string(), x);
        // The selected model names its terms by the same keys.
        for key in fit["model"].as_array_mut().unwrap() {
            if key == from {
                *key = serde_json::Value::from(to);
            }
        }
    }
    v
}

#[test]
fn each_channel_is_the_one_column_analysis_and_the_files_hold_its_terms() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("imu.csv");
    std::fs::write(&csv, imu_text()).unwrap();
    let out = dir.path().join("imu");
    let o = allan(&[
        "--imu",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed = String::from_utf8_lossy(&o.stdout);
    assert!(
        printed.contains("samples per channel, τ₀ = 0.01000000 s"),
        "{printed}"
    );
    let imu = json(&out.join("allan.json"));
    for (k, column) in COLUMNS.iter().enumerate() {
        let one = dir.path().join(column);
        let o = allan(&[
            "--accel",
            csv.to_str().unwrap(),
            "--column",
            column,
            "--out",
            one.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let single = json(&one.join("allan.json"));
        let want = if k < 3 { single } else { as_gyro(single) };
        // serde_json compares numbers as f64 with ==: bit for bit for every finite number.
        assert_eq!(imu["channels"][column], want, "{column}");
        if k < 3 {
            // The axis's one-axis configuration is the one-column form's noise.toml, byte for byte.
            assert_eq!(
                std::fs::read(out.join(format!("noise_{column}.toml"))).unwrap(),
                std::fs::read(one.join("noise.toml")).unwrap(),
                "{column}"
            );
        }
    }
    check_yaml(&imu, &out);
    check_noise_toml(&out);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert_eq!(page.matches("<svg").count(), 6);
    assert!(page.contains("°/√h") && page.contains("µg/√Hz") && page.contains("°/h"));
}

/// The largest of the three axes' term (value, else upper bound), computed from allan.json's
/// channel records.
fn largest(imu: &Value, columns: &[&str], term: &str) -> f64 {
    columns
        .iter()
        .map(|c| {
            let t = &imu["channels"][c]["fit"][term];
            t["value"]
                .as_f64()
                .unwrap_or_else(|| t["upper"].as_f64().unwrap())
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

fn check_yaml(imu: &Value, out: &Path) {
    let text = std::fs::read_to_string(out.join("imu.yaml")).unwrap();
    let docs =
        yaml_rust2::YamlLoader::load_from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let y = &docs[0];
    let real = |key: &str| {
        y[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} missing or not a number:\n{text}"))
    };
    let (acc, gyr) = (&COLUMNS[..3], &COLUMNS[3..]);
    // Continuous-time SI: m/s²/√Hz = m/s/√s, m/s³/√Hz = m/s²/√s, rad/s/√Hz = rad/√s,
    // rad/s²/√Hz = rad/s/√s: the fit's N and K as they are, the largest of the axes.
    let keys = [
        (
            "accelerometer_noise_density",
            largest(imu, acc, "velocity_random_walk_m_s_per_sqrt_s"),
            2.4e-3,
        ),
        (
            "accelerometer_random_walk",
            largest(imu, acc, "acceleration_random_walk_m_s2_per_sqrt_s"),
            1.2e-3,
        ),
        (
            "gyroscope_noise_density",
            largest(imu, gyr, "angle_random_walk_rad_per_sqrt_s"),
            1.2e-4,
        ),
        (
            "gyroscope_random_walk",
            largest(imu, gyr, "rate_random_walk_rad_s_per_sqrt_s"),
            6e-5,
        ),
    ];
    for (key, want, truth) in keys {
        assert_eq!(real(key), want, "{key}");
        // The largest simulated axis's value, to the scatter of 200 000 samples.
        assert!(
            (want / truth - 1.0).abs() < 0.25,
            "{key} = {want}, simulated {truth}"
        );
    }
    assert_eq!(real("update_rate"), 100.0);
    assert!(text.contains("discrete"), "{text}");
    // KF-GINS: arw °/√h = rad/√s·(180/π)·60 per gyro axis, vrw m/s/√h = m/s/√s·60.
    let kf = &y["imunoise"];
    for (i, c) in gyr.iter().enumerate() {
        let n = imu["channels"][c]["fit"]["angle_random_walk_rad_per_sqrt_s"]["value"]
            .as_f64()
            .unwrap();
        let arw = kf["arw"][i].as_f64().unwrap();
        assert!((arw / (n * 180.0 / std::f64::consts::PI * 60.0) - 1.0).abs() < 1e-12);
    }
    for (i, c) in acc.iter().enumerate() {
        let n = imu["channels"][c]["fit"]["velocity_random_walk_m_s_per_sqrt_s"]["value"]
            .as_f64()
            .unwrap();
        let vrw = kf["vrw"][i].as_f64().unwrap();
        assert!((vrw / (n * 60.0) - 1.0).abs() < 1e-12);
    }
    assert!(kf["corrtime"].as_f64().unwrap() > 0.0);
}

fn check_noise_toml(out: &Path) {
    let text = std::fs::read_to_string(out.join("noise.toml")).unwrap();
    let c = accelcal::config::ins::InsConfig::from_toml_str(&text)
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    c.validate().unwrap_or_else(|e| panic!("{e}\n{text}"));
    let yaml = yaml_rust2::YamlLoader::load_from_str(
        &std::fs::read_to_string(out.join("imu.yaml")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        Some(c.imu.gyro_arw_rad_per_sqrt_s),
        yaml[0]["gyroscope_noise_density"].as_f64()
    );
    assert_eq!(
        Some(c.imu.accel_vrw_m_s_per_sqrt_s),
        yaml[0]["accelerometer_noise_density"].as_f64()
    );
    assert_eq!(
        Some(c.imu.gyro_bias_random_walk_rad_s_per_sqrt_s),
        yaml[0]["gyroscope_random_walk"].as_f64()
    );
}

/// A short log with one problem put in at `line` (the header is line 1).
fn broken(problem: &str) -> String {
    let mut text = String::from("t_s,ax_m_s2,gy_rad_s\n");
    for i in 0..40 {
        let line = i + 2;
        let row = match (problem, line) {
            ("nan", 5) => format!("{},0.1,nan\n", i as f64 * 0.01),
            ("back", 7) => "0.02,0.1,0.2\n".to_string(),
            _ => format!("{},0.1,0.2\n", i as f64 * 0.01),
        };
        text.push_str(&row);
    }
    text
}

#[test]
fn bad_input_exits_2_naming_the_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "t_s,wx,wy\n0,1,2\n".to_string(),
            vec!["bad.csv", "line 1", "t_s and any of ax_m_s2"],
        ),
        (
            "time,ax_m_s2\n0,1\n".to_string(),
            vec!["bad.csv", "line 1", "`t_s`"],
        ),
        (
            broken("nan"),
            vec!["bad.csv", "line 5", "`gy_rad_s` = `nan`"],
        ),
        (broken("back"), vec!["bad.csv", "line 7", "not after"]),
    ];
    for (text, words) in cases {
        let csv = dir.path().join("bad.csv");
        std::fs::write(&csv, &text).unwrap();
        let o = allan(&[
            "--imu",
            csv.to_str().unwrap(),
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        for w in words {
            assert!(err.contains(w), "{w:?} not in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
        assert!(!dir.path().join("o").exists());
    }
    // --column belongs to --accel.
    let o = allan(&["--imu", "x.csv", "--column", "ax_m_s2"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_pipe_and_gzip_are_read_as_the_file_is() {
    let dir = tempfile::tempdir().unwrap();
    let text: String = imu_text()
        .lines()
        .take(20_001)
        .map(|l| format!("{l}\n"))
        .collect();
    let plain = dir.path().join("imu.csv");
    std::fs::write(&plain, &text).unwrap();
    let o = allan(&[
        "--imu",
        plain.to_str().unwrap(),
        "--out",
        dir.path().join("a").to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let gz = dir.path().join("imu.csv.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(text.as_bytes()).unwrap();
    std::fs::write(&gz, e.finish().unwrap()).unwrap();
    let o = allan(&[
        "--imu",
        gz.to_str().unwrap(),
        "--out",
        dir.path().join("b").to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut child = Command::new(env!("CARGO_BIN_EXE_accelcal"))
        .args(["allan", "--imu", "/dev/stdin", "--out"])
        .arg(dir.path().join("c"))
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    assert!(child.wait().unwrap().success());
    let channels = |d: &str| json(&dir.path().join(d).join("allan.json"))["channels"].clone();
    assert_eq!(channels("a"), channels("b"));
    assert_eq!(channels("a"), channels("c"));
}
