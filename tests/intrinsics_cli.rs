//! `accelcal intrinsics` as a user runs it: on the shipped real session beside imucal's own
//! calibration of it, on a simulated session written as CSV, and refusing bad input with exit 2
//! without touching what the output directory held.

mod common;

use std::path::{Path, PathBuf};

use accelcal::intrinsics::simulate::{Session, draw_intrinsics, random_poses, simulate};
use accelcal::random::Stream;
use common::run_in;

fn ferraris() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/imucal_ferraris/imu.csv")
}

/// imucal 2.6.0's Ferraris calibration of the same session (examples/imucal_ferraris/README.md).
const IMUCAL_ACCEL_BIAS: [f64; 3] = [0.537_117_42, -0.616_202_99, 0.398_867_34];
const IMUCAL_GYRO_BIAS: [f64; 3] = [-0.010_466_19, -0.006_454_98, 0.001_025_80];

fn json(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("out/intrinsics.json")).expect("written");
    serde_json::from_str(&text).expect("JSON")
}

fn values(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

#[test]
fn the_ferraris_session_beside_imucal() {
    let dir = tempfile::tempdir().unwrap();
    let imu = ferraris();
    let out = run_in(
        dir.path(),
        &[
            "intrinsics",
            "--imu",
            imu.to_str().unwrap(),
            "--latitude",
            "49.6",
            "--height",
            "280",
            "--out",
            "out",
        ],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(dir.path());
    // Every one of the six poses (each axis up and down) is found.
    let ups: Vec<Vec<f64>> = v["static_intervals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| values(&i["mean_specific_force_m_s2"]))
        .collect();
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            assert!(
                ups.iter().any(|f| sign * f[axis] > 9.0),
                "no pose with axis {axis} {sign} up: {ups:?}"
            );
        }
    }
    // The biases agree with imucal's to a few mm/s² (imucal's sections are shorter and its
    // method takes the poses to be exactly axis-aligned), the gyros' to 5·10⁻⁵ rad/s.
    let b = values(&v["accel"]["bias"]["value"]);
    for i in 0..3 {
        assert!(
            (b[i] - IMUCAL_ACCEL_BIAS[i]).abs() < 0.01,
            "accel bias {i}: {b:?}"
        );
    }
    let g = values(&v["gyro"]["bias"]["value"]);
    for i in 0..3 {
        assert!(
            (g[i] - IMUCAL_GYRO_BIAS[i]).abs() < 5e-5,
            "gyro bias {i}: {g:?}"
        );
    }
    // Six axis-aligned poses cannot tell a scale factor from a tilt: named, not given.
    for e in v["accel"]["scale_ppm"].as_array().unwrap() {
        assert_eq!(e["determined"], false, "{e}");
        assert!(e["value"].is_null(), "{e}");
    }
    assert!(v["accel"]["suggested_pose_up"].is_array());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("not determined"), "{text}");
    // The page: both figures, the tables, nothing outside itself.
    let page = std::fs::read_to_string(dir.path().join("out/index.html")).expect("the page");
    for id in [
        "intrinsics-poses",
        "intrinsics-residuals",
        "accel-table",
        "gyro-table",
    ] {
        assert!(page.contains(&format!("id=\"{id}\"")), "{id}");
    }
    assert!(page.contains("not determined"));
    assert!(!page.contains("http://") && !page.contains("https://") && !page.contains("src="));
    assert!(text.contains("add a pose"), "{text}");
}

/// Writes a simulated session as the CSV the command reads.
fn write_session(path: &Path, poses: usize, seed: u64) {
    let mut rng = Stream::new(0x01a7c3, seed);
    let truth = draw_intrinsics(&mut rng);
    let s = Session::consumer(random_poses(poses, &mut rng));
    let log = simulate(&truth, &s, &mut rng);
    let mut text = String::from("t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s\n");
    for k in 0..log.len() {
        let (f, w) = (log.specific_force[k], log.angular_rate[k]);
        text += &format!(
            "{},{},{},{},{},{},{}\n",
            k as f64 * 0.01,
            f.x,
            f.y,
            f.z,
            w.x,
            w.y,
            w.z
        );
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_simulated_session_through_the_command() {
    let dir = tempfile::tempdir().unwrap();
    write_session(&dir.path().join("imu.csv"), 14, 0);
    let out = run_in(
        dir.path(),
        &[
            "intrinsics",
            "--imu",
            "imu.csv",
            "--gravity",
            "9.80665",
            "--out",
            "out",
            "-q",
        ],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(dir.path());
    assert_eq!(v["static_intervals"].as_array().unwrap().len(), 14);
    assert_eq!(v["accel"]["undetermined"].as_array().unwrap().len(), 0);
    assert!(v["accel"]["matrix"]["value"][2][1].is_f64());
    assert!(v["latitude_deg"].is_null());
}

#[test]
fn bad_input_is_refused_and_the_output_kept() {
    let dir = tempfile::tempdir().unwrap();
    write_session(&dir.path().join("imu.csv"), 10, 1);
    std::fs::create_dir(dir.path().join("out")).unwrap();
    std::fs::write(dir.path().join("out/intrinsics.json"), "earlier").unwrap();
    let text = std::fs::read_to_string(dir.path().join("imu.csv")).unwrap();
    let without_gz: String = text
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    std::fs::write(dir.path().join("five.csv"), without_gz).unwrap();
    // Noise only, far above any still sensor's: no static pose.
    let mut rng = Stream::new(7, 0);
    let mut moving = String::from("t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s\n");
    for k in 0..2000 {
        let phase = k as f64 * 0.05;
        moving += &format!(
            "{},{},{},{},{},{},{}\n",
            k as f64 * 0.01,
            9.8 * phase.cos() + rng.normal(),
            9.8 * phase.sin(),
            0.1 * rng.normal(),
            rng.normal(),
            rng.normal(),
            5.0
        );
    }
    std::fs::write(dir.path().join("moving.csv"), moving).unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["--imu", "imu.csv", "--latitude", "95"], "--latitude"),
        (&["--imu", "imu.csv", "--gravity", "1.6"], "--gravity"),
        (
            &["--imu", "imu.csv", "--gravity", "9.8", "--false-alarm", "2"],
            "--false-alarm",
        ),
        (&["--imu", "five.csv", "--gravity", "9.8"], "gz_rad_s"),
        (
            &["--imu", "moving.csv", "--gravity", "9.8"],
            "no static interval",
        ),
        (&["--imu", "missing.csv", "--gravity", "9.8"], "missing.csv"),
    ];
    for (args, expect) in cases {
        let mut all = vec!["intrinsics"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", "out"]);
        let out = run_in(dir.path(), &all, None);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        let kept = std::fs::read_to_string(dir.path().join("out/intrinsics.json")).unwrap();
        assert_eq!(kept, "earlier", "{args:?}");
    }
}
