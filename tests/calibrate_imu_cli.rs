//! `accelcal calibrate --imu --gnss` as a user runs it: the shipped comma2k19 minute against
//! what is known of it independently, a pipe, `--config`, and bad recordings refused with file,
//! line and field, exit code 2, and nothing the user has clobbered.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use common::{bin, run_in};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19_3d")
        .join(name)
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("written")).expect("JSON")
}

fn calibrate(dir: &Path, imu: &Path, gnss: &Path, extra: &[&str]) -> std::process::Output {
    let (i, g) = (imu.to_str().unwrap(), gnss.to_str().unwrap());
    let mut args = vec!["calibrate", "--imu", i, "--gnss", g, "--out", "out"];
    args.extend(extra);
    run_in(dir, &args, None)
}

/// Android's own gyro bias estimate over the segment, rad/s (examples/comma2k19_3d/README.md).
const ANDROID_GYRO_BIAS: [f64; 3] = [-0.0097809, -0.0351105, 0.0683594];

/// The shipped minute with no configuration: the gyro biases within 2·10⁻³ rad/s (0.11 °/s) of
/// Android's estimate, roll and pitch at the end within 0.5° of comma's pose, the yaw and the
/// horizontal accelerometer biases said to be undetermined, and the intervals said to rest on
/// a rejected model.
#[test]
fn the_shipped_minute_calibrates_as_known() {
    let dir = tempfile::tempdir().unwrap();
    let out = calibrate(dir.path(), &example("imu.csv"), &example("gnss.csv"), &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = read_json(&dir.path().join("out/summary.json"));
    assert_eq!(s["model"], "ins");
    for (k, android) in ANDROID_GYRO_BIAS.iter().enumerate() {
        let v = s["gyro_bias_rad_s"]["value"][k].as_f64().unwrap();
        assert!(
            (v - android).abs() < 2e-3,
            "gyro {k}: {v} against {android}"
        );
        assert_eq!(s["gyro_bias_rad_s"]["identifiable"][k], true);
    }
    assert_eq!(s["accel_bias_m_s2"]["identifiable"][0], false);
    assert_eq!(s["attitude_deg"]["yaw_identifiable"], false);
    let reference = std::fs::read_to_string(example("reference.csv")).unwrap();
    let last: Vec<f64> = reference
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|f| f.parse().unwrap())
        .collect();
    for (key, col) in [("roll", 7), ("pitch", 8)] {
        let v = s["attitude_deg"][key].as_f64().unwrap();
        assert!(
            (v - last[col]).abs() < 0.5,
            "{key}: {v} against {}",
            last[col]
        );
    }
    assert_eq!(s["intervals_conditional"], true);
    assert!(s["rejected_by"].as_array().unwrap().contains(&"nis".into()));
    let estimates = std::fs::read_to_string(dir.path().join("out/estimates.csv")).unwrap();
    assert_eq!(
        estimates.lines().count() - 1,
        s["fixes_used"].as_u64().unwrap() as usize
    );
}

/// The IMU log through a pipe gives the file's summary.
#[test]
fn a_pipe_gives_the_files_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let file = calibrate(dir.path(), &example("imu.csv"), &example("gnss.csv"), &[]);
    assert!(file.status.success());
    let mut expected = read_json(&dir.path().join("out/summary.json"));
    let gnss = example("gnss.csv");
    let piped = Command::new(bin())
        .args(["calibrate", "--imu", "/dev/stdin", "--gnss"])
        .arg(&gnss)
        .args(["--out", "piped"])
        .current_dir(dir.path())
        .stdin(Stdio::from(
            std::fs::File::open(example("imu.csv")).unwrap(),
        ))
        .output()
        .unwrap();
    assert!(
        piped.status.success(),
        "{}",
        String::from_utf8_lossy(&piped.stderr)
    );
    let mut got = read_json(&dir.path().join("piped/summary.json"));
    for v in [&mut expected, &mut got] {
        v["imu_file"] = serde_json::Value::Null;
    }
    assert_eq!(expected, got);
}

/// `--config` sets the keys it names and leaves the rest at the consumer defaults; a bad key
/// or value is refused with its line.
#[test]
fn config_sets_the_keys_it_names() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(
        &config,
        "model = \"ins\"\n[gnss]\ngnss_position_sigma_m = [0.5, 0.5, 1.0]\n",
    )
    .unwrap();
    let c = config.to_str().unwrap();
    let out = calibrate(
        dir.path(),
        &example("imu.csv"),
        &example("gnss.csv"),
        &["--config", c],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = read_json(&dir.path().join("out/summary.json"));
    assert_eq!(s["assumptions"]["gnss_position_sigma_m"][2], 1.0);
    assert_eq!(s["assumptions"]["gnss_velocity_sigma_m_s"], 0.1);
    for (text, words) in [
        ("[gnss]\ngnss_velocity_sigma_m_s = -1.0\n", "c.toml:2:"),
        ("[imu]\nimu_rate_hz = 100.0\n", "imu_rate_hz"),
        (
            "[alignment]\nheading_offset_sigma_deg = 45\n",
            "heading_offset_sigma_deg",
        ),
    ] {
        std::fs::write(&config, text).unwrap();
        let out = calibrate(
            dir.path(),
            &example("imu.csv"),
            &example("gnss.csv"),
            &["--config", c],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{text}: {err}");
        assert!(
            err.contains(words) && err.contains("c.toml"),
            "{text}: {err}"
        );
    }
}

/// A receiver that starts before the IMU log and runs on after it: those fixes are left out with
/// a warning and counted, and the calibration is the one without them.
#[test]
fn fixes_outside_the_imu_log_are_left_out_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let gnss = std::fs::read_to_string(example("gnss.csv")).unwrap();
    let mut lines: Vec<&str> = gnss.lines().collect();
    let (first, last) = (lines[1].to_string(), lines[lines.len() - 1].to_string());
    let moved = |line: &str, t: &str| line.replacen(line.split(',').next().unwrap(), t, 1);
    let (early, late) = (moved(&first, "-3.4"), moved(&last, "75.0"));
    lines.insert(1, &early);
    lines.push(&late);
    let extended = lines.join("\n") + "\n";
    std::fs::write(dir.path().join("gnss.csv"), extended).unwrap();
    let out = calibrate(
        dir.path(),
        &example("imu.csv"),
        &dir.path().join("gnss.csv"),
        &[],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("warning: fixes outside the IMU log are left out: 1 before")
            && err.contains("1 after"),
        "{err}"
    );
    let with = read_json(&dir.path().join("out/summary.json"));
    assert_eq!(with["fixes_outside_log"]["before"], 1);
    assert_eq!(with["fixes_outside_log"]["after"], 1);
    let plain = tempfile::tempdir().unwrap();
    let out = calibrate(plain.path(), &example("imu.csv"), &example("gnss.csv"), &[]);
    assert_eq!(out.status.code(), Some(0));
    let without = read_json(&plain.path().join("out/summary.json"));
    assert_eq!(without["fixes_outside_log"]["before"], 0);
    assert_eq!(with["fixes"], without["fixes"].as_u64().unwrap() + 2);
    for key in [
        "gyro_bias_rad_s",
        "accel_bias_m_s2",
        "attitude_deg",
        "nis",
        "fixes_used",
    ] {
        assert_eq!(with[key], without[key], "{key}");
    }
}

/// Bad recordings: each refused with exit code 2 naming the file, the line and the field, and
/// the summary.json already in the output directory left as it was.
#[test]
fn bad_recordings_are_refused_with_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let imu = std::fs::read_to_string(example("imu.csv")).unwrap();
    let gnss = std::fs::read_to_string(example("gnss.csv")).unwrap();
    let edit = |text: &str, line: usize, f: &dyn Fn(&str) -> String| -> String {
        text.lines()
            .enumerate()
            .map(|(k, l)| if k + 1 == line { f(l) } else { l.to_string() } + "\n")
            .collect()
    };
    let set_field = |col: usize, value: &'static str| {
        move |l: &str| {
            let mut f: Vec<&str> = l.split(',').collect();
            f[col] = value;
            f.join(",")
        }
    };
    let drop_gz: String = imu
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    let both = edit(&imu, 1, &|l| l.replace("ax_m_s2", "dvx_m_s"));
    let cases: Vec<(&str, String, String, &str)> = vec![
        ("imu.csv", drop_gz, gnss.clone(), "gz_rad_s"),
        ("imu.csv", both, gnss.clone(), "dvx_m_s"),
        (
            "gnss.csv",
            imu.clone(),
            edit(&gnss, 5, &set_field(1, "nan")),
            "lat_deg",
        ),
        (
            "gnss.csv",
            imu.clone(),
            edit(&gnss, 7, &set_field(1, "95.0")),
            "lat_deg",
        ),
        (
            "imu.csv",
            edit(&imu, 9, &set_field(0, "0.001")),
            gnss.clone(),
            "not after",
        ),
    ];
    let out_dir = dir.path().join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::write(out_dir.join("summary.json"), "kept").unwrap();
    for (blamed, i, g, words) in cases {
        std::fs::write(dir.path().join("imu.csv"), &i).unwrap();
        std::fs::write(dir.path().join("gnss.csv"), &g).unwrap();
        let out = calibrate(
            dir.path(),
            &dir.path().join("imu.csv"),
            &dir.path().join("gnss.csv"),
            &[],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{words}: {err}");
        assert!(
            err.contains(blamed) && err.contains(words),
            "{words}: {err}"
        );
        assert!(err.contains("line"), "{words}: no line in {err}");
        assert!(!err.contains("panicked"), "{err}");
        let kept = std::fs::read_to_string(out_dir.join("summary.json")).unwrap();
        assert_eq!(kept, "kept");
    }
}
