//! Hostile and unusual inputs of the three-axis surfaces: six-axis values beyond any sensor's
//! range, an accelerometer that measures nothing, rows refused early in the log, longitudes
//! past the antimeridian (in the fixes, at the simulated drive's start) and configuration
//! files run without `--model`. Each run must end with exit code 0 and the right numbers, or
//! with exit code 2 and a message naming the file, the line and the field.

mod common;

use std::path::Path;

use common::{Ended, assert_refused, run_limited};

/// The shipped comma2k19 three-axis log `name`, its rows up to `seconds` (all with `None`).
fn shipped(name: &str, seconds: Option<f64>) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19_3d")
        .join(name);
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        let t: f64 = line.split(',').next().unwrap().parse().unwrap_or(0.0);
        if k == 0 || seconds.is_none_or(|s| t <= s) {
            out += line;
            out.push('\n');
        }
    }
    out
}

/// `text` (a CSV log) with field `column` of the data rows `rows` (1 = the first) set by `f`
/// from its value.
fn edited(
    text: &str,
    column: &str,
    rows: std::ops::Range<usize>,
    f: impl Fn(f64) -> String,
) -> String {
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let j = header.split(',').position(|c| c == column).unwrap();
    let mut out = format!("{header}\n");
    for (k, line) in lines.enumerate() {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        if rows.contains(&(k + 1)) {
            fields[j] = f(fields[j].parse().unwrap_or(f64::NAN));
        }
        out += &fields.join(",");
        out.push('\n');
    }
    out
}

/// The rates log `text` as increments: each row's rates times its step.
fn increments(text: &str) -> String {
    let mut lines = text.lines();
    lines.next();
    let mut out = String::from("t_s,dvx_m_s,dvy_m_s,dvz_m_s,dthx_rad,dthy_rad,dthz_rad\n");
    let mut previous: Option<f64> = None;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let dt = previous.map_or(0.01, |p| v[0] - p);
        previous = Some(v[0]);
        let row: Vec<String> = std::iter::once(v[0].to_string())
            .chain(v[1..].iter().map(|x| (x * dt).to_string()))
            .collect();
        out += &row.join(",");
        out.push('\n');
    }
    out
}

/// `calibrate --imu imu.csv --gnss gnss.csv` in `dir` with the two logs written there.
fn calibrate(dir: &Path, imu: &str, gnss: &str) -> Ended {
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("gnss.csv"), gnss).unwrap();
    let args = [
        "calibrate",
        "--imu",
        "imu.csv",
        "--gnss",
        "gnss.csv",
        "--out",
        "cal",
    ];
    run_limited(dir, &args, 60)
}

#[test]
fn six_axis_values_beyond_any_sensor_are_refused_on_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (imu, gnss) = (
        shipped("imu.csv", Some(4.0)),
        shipped("gnss.csv", Some(4.0)),
    );
    // The control: the untouched four seconds calibrate.
    let ended = calibrate(d, &imu, &gnss);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    for (column, value) in [
        ("ay_m_s2", "1e308"),
        ("az_m_s2", "-1e308"),
        ("ay_m_s2", "1e200"),
    ] {
        let bad = edited(&imu, column, 1..300, |_| value.to_string());
        let what = format!("{column} = {value}");
        let expect = ["imu.csv, line 3", column, "accepted range", "1e6 m/s²"];
        assert_refused(&calibrate(d, &bad, &gnss), &expect, &what);
    }
    let gyro = edited(&imu, "gz_rad_s", 5..6, |_| "-2e4".to_string());
    let expect = ["imu.csv, line 6", "gz_rad_s", "1e4 rad/s"];
    assert_refused(&calibrate(d, &gyro, &gnss), &expect, "gz_rad_s = -2e4");
    let inc = increments(&imu);
    let ended = calibrate(d, &inc, &gnss);
    assert_eq!(ended.code, Some(0), "increments: {}", ended.stderr);
    for column in ["dvy_m_s", "dvz_m_s"] {
        let bad = edited(&inc, column, 1..300, |_| "1e308".to_string());
        let expect = ["imu.csv, line 3", column, "times the step"];
        assert_refused(&calibrate(d, &bad, &gnss), &expect, column);
    }
}

#[test]
fn an_accelerometer_that_measures_nothing_gives_no_level() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut imu = shipped("imu.csv", Some(4.0));
    for column in ["ax_m_s2", "ay_m_s2", "az_m_s2"] {
        imu = edited(&imu, column, 1..1000, |_| "0".to_string());
    }
    let expect = ["gnss.csv", "mean specific force", "roll and pitch"];
    let ended = calibrate(d, &imu, &shipped("gnss.csv", Some(4.0)));
    assert_refused(&ended, &expect, "zero specific force");
}

#[test]
fn a_row_refused_early_is_named_by_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (imu, gnss) = (
        shipped("imu.csv", Some(4.0)),
        shipped("gnss.csv", Some(4.0)),
    );
    for row in 1..=4 {
        let bad = edited(&imu, "ay_m_s2", row..row + 1, |_| "abc".to_string());
        let line = format!("imu.csv, line {}", row + 1);
        let expect = [line.as_str(), "`ay_m_s2` = `abc` is not a number"];
        assert_refused(&calibrate(d, &bad, &gnss), &expect, &format!("row {row}"));
    }
    let back = edited(&imu, "t_s", 3..4, |_| "0.001".to_string());
    let expect = ["imu.csv, line 4", "time stamp 0.001 s is not after"];
    assert_refused(&calibrate(d, &back, &gnss), &expect, "time on line 4");
}

/// The summary's `key` values (an attitude's roll, pitch and yaw) from `dir/cal/summary.json`.
fn values(dir: &Path, key: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("cal/summary.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    match json[key]["value"].as_array() {
        Some(v) => v.iter().map(|v| v.as_f64().unwrap()).collect(),
        None => ["roll", "pitch", "yaw"]
            .iter()
            .map(|a| json[key][a].as_f64().unwrap())
            .collect(),
    }
}

/// The largest |a − b| over |b| (b's largest magnitude) of two estimates.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

#[test]
fn a_longitude_is_the_same_meridian_however_it_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (imu, gnss) = (shipped("imu.csv", None), shipped("gnss.csv", None));
    let ended = calibrate(d, &imu, &gnss);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let keys = ["gyro_bias_rad_s", "accel_bias_m_s2", "attitude_deg"];
    let reference: Vec<Vec<f64>> = keys.iter().map(|k| values(d, k)).collect();
    // In [0, 360): the documented range's upper half. Across the antimeridian: the drive
    // (500 m east-west) moved so that its middle sits on 180°, written in (−180, 180].
    let middle = -122.4720602;
    let variants = [
        (
            "east of 180",
            edited(&gnss, "lon_deg", 1..usize::MAX, |x| {
                format!("{:.10}", x + 360.0)
            }),
        ),
        (
            "across 180",
            edited(&gnss, "lon_deg", 1..usize::MAX, |x| {
                let y = x - middle + 180.0;
                format!("{:.10}", if y > 180.0 { y - 360.0 } else { y })
            }),
        ),
    ];
    for (what, moved) in variants {
        assert!(
            what != "across 180" || moved.contains(",-179.9999"),
            "{what}"
        );
        let ended = calibrate(d, &imu, &moved);
        assert_eq!(ended.code, Some(0), "{what}: {}", ended.stderr);
        for (key, want) in keys.iter().zip(&reference) {
            let got = values(d, key);
            // Earth rate and gravity depend on latitude only: the same numbers up to the
            // rounding of the moved longitudes (10⁻¹⁰°, 10 µm).
            let r = relative(&got, want);
            assert!(r < 1e-6, "{what}: {key} {got:?} against {want:?} ({r:.1e})");
        }
    }
}

#[test]
fn a_drive_that_starts_on_the_antimeridian_is_simulated_and_filtered_as_any_other() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = common::run_in(d, &["config", "--model", "ins"], None);
    let text = String::from_utf8(out.stdout).unwrap();
    let start = text
        .lines()
        .find(|l| l.starts_with("start_lon_deg"))
        .unwrap();
    let at = |lon: &str| text.replace(start, &format!("start_lon_deg = {lon}"));
    std::fs::write(d.join("a.toml"), at("-180.0")).unwrap();
    std::fs::write(d.join("b.toml"), at("-122.1")).unwrap();
    let args = [
        "ensemble",
        "--config",
        "a.toml",
        "-q",
        "--realizations",
        "40",
    ];
    let ended = run_limited(d, &[&args[..], &["--json", "e.json"]].concat(), 300);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("e.json")).unwrap()).unwrap();
    assert_eq!(json["summary"]["all_passed"], true, "{}", json["summary"]);
    // The simulated fixes stay in (−180, 180] and calibrate as the same drive elsewhere does.
    let mut estimates = Vec::new();
    for name in ["a", "b"] {
        let args = [
            "simulate",
            "--config",
            &format!("{name}.toml"),
            "--logs",
            name,
        ];
        let ended = run_limited(d, &args, 120);
        assert_eq!(ended.code, Some(0), "{}", ended.stderr);
        let gnss = std::fs::read_to_string(d.join(name).join("gnss.csv")).unwrap();
        for line in gnss.lines().skip(1) {
            let lon: f64 = line.split(',').nth(2).unwrap().parse().unwrap();
            assert!(lon > -180.0 && lon <= 180.0, "{name}: {line}");
        }
        let imu = std::fs::read_to_string(d.join(name).join("imu.csv")).unwrap();
        let ended = calibrate(d, &imu, &gnss);
        assert_eq!(ended.code, Some(0), "{name}: {}", ended.stderr);
        estimates.push(values(d, "gyro_bias_rad_s"));
    }
    let r = relative(&estimates[0], &estimates[1]);
    assert!(r < 1e-6, "{estimates:?} ({r:.1e})");
}

#[test]
fn a_configuration_file_runs_as_the_model_it_names() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for model in ["ins", "car"] {
        let out = common::run_in(d, &["config", "--model", model], None);
        std::fs::write(d.join(format!("{model}.toml")), out.stdout).unwrap();
    }
    let args = [
        "ensemble",
        "--config",
        "ins.toml",
        "-q",
        "--realizations",
        "4",
    ];
    let ended = run_limited(d, &[&args[..], &["--json", "e.json"]].concat(), 120);
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    let json = std::fs::read_to_string(d.join("e.json")).unwrap();
    assert!(json.contains("\"model\": \"ins\""), "{}", &json[..200]);
    let ended = run_limited(
        d,
        &["simulate", "--config", "car.toml", "--logs", "car"],
        120,
    );
    assert_eq!(ended.code, Some(0), "{}", ended.stderr);
    assert!(d.join("car/imu.csv").exists() && d.join("car/gnss.csv").exists());
    // A model no study has, and a three-axis file run as the one-axis study.
    let text = std::fs::read_to_string(d.join("ins.toml")).unwrap();
    std::fs::write(
        d.join("x.toml"),
        text.replace("model = \"ins\"", "model = \"inss\""),
    )
    .unwrap();
    let ended = run_limited(d, &["ensemble", "--config", "x.toml"], 30);
    assert_refused(
        &ended,
        &["x.toml:", "`model` = \"inss\"", "\"ins\" or \"car\""],
        "inss",
    );
    let args = [
        "ensemble",
        "--config",
        "ins.toml",
        "--model",
        "accelerometer",
    ];
    let ended = run_limited(d, &args, 30);
    assert_refused(
        &ended,
        &["ins.toml:", "--model accelerometer"],
        "accelerometer",
    );
}
