//! The shipped minute of a real drive (examples/comma2k19), calibrated as the report shows it:
//! the gravity-compensated axis passes the NIS test once the white noise W is estimated with the
//! GPS σ's and fails it with the GPS σ's alone; its bias is negative; the raw axis needs a
//! drifting bias. From the command line with no configuration, the same log as a file, gzip and
//! a pipe gives the same bits; a prior 900σ off warns; the first fix gives the bias's sign.

mod common;

use std::path::{Path, PathBuf};

use accelcal::study::drive::{self, Axis, RUNS};

#[test]
fn the_real_drive_calibrates_as_the_report_says() {
    let runs = drive::run().expect("the shipped files calibrate");
    assert_eq!(runs.len(), RUNS.len());
    let nis = |i: usize| &runs[i].calibration.summary.nis;
    // GPS σ's alone: the NIS sum lies above its band (the vibration is not in the model).
    assert_eq!(runs[0].axis, Axis::GravityCompensated);
    assert_eq!(nis(0).verdict, "fail", "{:?}", nis(0));
    assert!(nis(0).sum > nis(0).upper);
    // With W: the NIS test passes, W is identified near 0.4 (m/s²)², and the bias is negative
    // with its interval below zero.
    assert_eq!(nis(1).verdict, "pass", "{:?}", nis(1));
    let w = &runs[1].noise.keys[2];
    assert!(w.identifiable, "{w:?}");
    assert!(w.lower > 0.1 && w.upper.unwrap() < 2.0, "{w:?}");
    let s = &runs[1].calibration.summary;
    assert!(
        s.bias_m_s2 + 1.96 * s.bias_sigma_m_s2 < 0.0,
        "{} ± {}",
        s.bias_m_s2,
        s.bias_sigma_m_s2
    );
    // Every run's flag is the tests' verdicts, and the runs the NIS test rejects say so.
    for (i, r) in runs.iter().enumerate() {
        let s = &r.calibration.summary;
        let rejects = s.nis.verdict == "fail"
            || s.diagnostics.bias.verdict == "fail"
            || s.diagnostics
                .measurements
                .iter()
                .any(|m| m.whiteness.verdict == "fail");
        assert_eq!(
            s.intervals_conditional, rejects,
            "run {i}: {:?}",
            s.rejected_by
        );
        assert!(s.bias_robust.sigma >= s.bias_sigma_m_s2, "run {i}");
    }
    assert!(
        runs[0]
            .calibration
            .summary
            .rejected_by
            .contains(&"nis".to_string())
    );
    // The raw axis with a random walk: K is identified (gravity's share moves with the pitch).
    let k = &runs[3].noise.keys[3];
    assert!(k.identifiable, "{k:?}");
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19")
        .join(name)
}

/// Runs `calibrate` on the shipped GPS log and `accel` (a path or a shell word) through bash,
/// into `dir/out`; returns the printed output and the summary.
fn calibrate_sh(dir: &Path, accel: &str, more: &str, out: &str) -> (String, serde_json::Value) {
    let gps = example("gps.csv");
    let script = format!(
        "\"{}\" calibrate --accel {accel} --gps \"{}\" --out {out} -q {more}",
        common::bin(),
        gps.display()
    );
    let o = std::process::Command::new("bash")
        .arg("-c")
        .arg(&script)
        .current_dir(dir)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{script}: {text}");
    let summary = std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap();
    (text, serde_json::from_str(&summary).unwrap())
}

#[test]
fn the_shipped_drive_runs_without_configuration_from_a_file_gzip_and_a_pipe() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain = example("accel_gravcomp.csv");
    let text = std::fs::read(&plain).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut gz, &text).unwrap();
    std::fs::write(d.join("accel_gravcomp.csv.gz"), gz.finish().unwrap()).unwrap();
    let keys = "--estimate-noise --estimate \
                gps_position_sigma_m,gps_velocity_sigma_m_s,accel_noise_var_m2_s4";
    let (said, s) = calibrate_sh(d, &format!("\"{}\"", plain.display()), keys, "plain");
    assert!(said.contains("NIS test pass"), "{said}");
    assert!(said.contains("95 % interval"), "{said}");
    assert!(s["bias_m_s2"].as_f64().unwrap() < 0.0);
    let estimates = std::fs::read(d.join("plain/estimates.csv")).unwrap();
    for (accel, out) in [
        ("accel_gravcomp.csv.gz", "gz"),
        ("<(gzip -dc accel_gravcomp.csv.gz)", "pipe"),
    ] {
        let (_, t) = calibrate_sh(d, accel, keys, out);
        // The same numbers bit for bit; only the log's name differs.
        for key in [
            "bias_m_s2",
            "bias_sigma_m_s2",
            "noise_estimate",
            "nis",
            "diagnostics",
        ] {
            assert_eq!(s[key], t[key], "{out}: {key}");
        }
        assert_eq!(
            std::fs::read(d.join(out).join("estimates.csv")).unwrap(),
            estimates,
            "{out}"
        );
    }
    // The GPS σ's alone leave the NIS test failing, and the diagnosis names the white noise.
    let (said, s) = calibrate_sh(
        d,
        &format!("\"{}\"", plain.display()),
        "--estimate-noise",
        "sigmas",
    );
    assert!(said.contains("NIS test fail"), "{said}");
    let findings = s["diagnostics"]["findings"].to_string();
    assert!(findings.contains("accel_noise_var_m2_s4"), "{findings}");
}

#[test]
fn a_prior_900_sigma_off_warns_and_the_first_fix_gives_the_right_sign() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plain = format!("\"{}\"", example("accel_gravcomp.csv").display());
    // The simulation's prior: 100 m/s with σ 0.1 m/s against a car at 8.2 m/s.
    std::fs::write(
        d.join("sim.toml"),
        "[accelerometer]\nsample_rate_hz = 104.35668282688978\n\n[initial]\nvelocity_mean_m_s = 100.0\n",
    )
    .unwrap();
    let (said, s) = calibrate_sh(d, &plain, "--config sim.toml", "sim");
    assert!(
        said.contains("warning: the prior disagrees with the first fix"),
        "{said}"
    );
    assert!(
        s["warnings"][0]
            .as_str()
            .unwrap()
            .contains("initial.velocity_mean_m_s")
    );
    // No configuration: the first fix starts the integration and the bias is negative.
    let (said, s) = calibrate_sh(d, &plain, "", "first");
    assert!(!said.contains("warning"), "{said}");
    let (b, sb) = (
        s["bias_m_s2"].as_f64().unwrap(),
        s["bias_sigma_m_s2"].as_f64().unwrap(),
    );
    assert!(b + 3.0 * sb < 0.0, "{b} ± {sb}");
    // The GPS position errors are not white at 10 Hz: the whiteness test flags them.
    let position = &s["diagnostics"]["measurements"][0];
    assert_eq!(position["measurement"], "position");
    assert_eq!(position["whiteness"]["verdict"], "fail", "{position}");
}

#[test]
fn the_raw_axis_with_the_defaults_says_its_interval_rests_on_a_rejected_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let raw = format!("\"{}\"", example("accel_raw.csv").display());
    let (said, s) = calibrate_sh(d, &raw, "", "raw");
    // The NIS sum is hundreds of times its band: the flag, the tests, and the words beside the
    // interval.
    assert_eq!(s["intervals_conditional"], true, "{said}");
    let rejected: Vec<&str> = s["rejected_by"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert!(rejected.contains(&"nis"), "{rejected:?}");
    assert!(
        said.contains("which assumes a model the data reject (nis"),
        "{said}"
    );
    assert!(said.contains("bias without white innovations:"), "{said}");
    // The interval that does not assume white innovations is wider by √F, F ≥ the NIS mean's
    // excess (the sum is above its band, so the innovations' variance alone is > 1).
    let r = &s["bias_robust"];
    let (sigma, robust) = (
        s["bias_sigma_m_s2"].as_f64().unwrap(),
        r["sigma"].as_f64().unwrap(),
    );
    let factor = r["variance_factor"].as_f64().unwrap();
    assert!((robust / sigma - factor.sqrt()).abs() < 1e-9 * factor.sqrt());
    let nis_mean = s["nis"]["mean"].as_f64().unwrap();
    assert!(factor > nis_mean / 2.0, "F {factor}, NIS mean {nis_mean}");
    // The printed ends differ: at three digits alone they read [−0.614, −0.613].
    let line = said.lines().find(|l| l.starts_with("bias ")).unwrap();
    let ends = line.split("interval [").nth(1).unwrap();
    let (lo, hi) = ends.split_once(']').unwrap().0.split_once(", ").unwrap();
    assert_ne!(lo, hi, "{line}");
    assert!(lo.len() > "−0.614".len(), "{line}");
}
