//! The page of `accelcal calibrate --imu --gnss` (index.html): written beside summary.json,
//! self-contained, naming every assumption, saying the yaw is not determined on the shipped
//! minute (a straight drive) and not saying so for a simulated drive with turns, and printing
//! the numbers summary.json holds.

mod common;

use std::path::{Path, PathBuf};

use common::run_in;
use serde_json::Value;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19_3d")
        .join(name)
}

/// Runs the binary in `dir`, asserting it succeeds.
fn run(dir: &Path, args: &[&str]) -> String {
    let out = run_in(dir, args, None);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Calibrates `imu` and `gnss` into `dir/out`; the page and the summary.
fn calibrate(dir: &Path, imu: &Path, gnss: &Path, extra: &[&str]) -> (String, Value) {
    let (i, g) = (imu.to_str().unwrap(), gnss.to_str().unwrap());
    let mut args = vec![
        "calibrate",
        "--imu",
        i,
        "--gnss",
        g,
        "--out",
        "out",
        "--quiet",
    ];
    args.extend(extra);
    run(dir, &args);
    let page = std::fs::read_to_string(dir.join("out/index.html")).expect("index.html written");
    let summary = std::fs::read_to_string(dir.join("out/summary.json")).expect("summary written");
    (page, serde_json::from_str(&summary).expect("JSON"))
}

/// The first number of the first numeric cell of the table row `id`, and half a unit of its
/// last printed digit.
fn printed(page: &str, id: &str) -> Option<(f64, f64)> {
    let row = &page[page.find(&format!("<tr id=\"{id}\""))?..];
    let cell = &row[row.find("<td class=\"num\">")? + "<td class=\"num\">".len()..];
    let text = cell[..cell.find("</td>")?].replace('−', "-");
    let number = text.split_whitespace().next()?;
    let decimals = number.split_once('.').map_or(0, |(_, d)| d.len());
    Some((number.parse().ok()?, 0.5 * 10f64.powi(-(decimals as i32))))
}

/// Whether row `id` of the page prints `value` to its digits.
fn prints(page: &str, id: &str, value: f64) -> bool {
    printed(page, id).is_some_and(|(x, half)| (x - value).abs() <= half * (1.0 + 1e-9))
}

/// What every page must hold: no address outside itself, every assumption's key, the biases and
/// the attitude of summary.json, the NIS sum and its verdict.
fn check_page(page: &str, s: &Value) {
    assert!(page.starts_with("<!DOCTYPE html>"));
    for outside in ["http://", "https://", " src=\"", "<link", "<script"] {
        assert!(!page.contains(outside), "the page holds {outside}");
    }
    let assumptions = s["assumptions"].as_object().expect("assumptions");
    assert!(assumptions.len() >= 17);
    for key in assumptions.keys() {
        assert!(
            page.contains(&format!("<code>{key}</code>")),
            "assumption {key} missing"
        );
    }
    for (sensor, id) in [
        ("gyro_bias_rad_s", "gyro-bias"),
        ("accel_bias_m_s2", "accel-bias"),
    ] {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let v = s[sensor]["value"][k].as_f64().unwrap();
            let row = format!("{id}-{axis}");
            assert!(
                prints(page, &row, v),
                "{row}: {:?} against {v}",
                printed(page, &row)
            );
            let determined = s[sensor]["identifiable"][k].as_bool().unwrap();
            let row_html = &page[page.find(&format!("<tr id=\"{row}\"")).unwrap()..];
            let row_html = &row_html[..row_html.find("</tr>").unwrap()];
            assert_eq!(row_html.contains("not determined"), !determined, "{row}");
        }
    }
    for angle in ["roll", "pitch", "yaw"] {
        let v = s["attitude_deg"][angle].as_f64().unwrap();
        assert!(
            prints(page, angle, v),
            "{angle}: {:?} against {v}",
            printed(page, angle)
        );
    }
    let nis = s["nis"]["sum"].as_f64().unwrap();
    let verdict = s["nis"]["verdict"].as_str().unwrap();
    let sum = format!("Σ = {}", accelcal::format::sig(nis, 5));
    let tests = &page[page.find("id=\"tests-table\"").unwrap()..];
    assert!(tests.contains(&sum), "{sum}");
    assert!(tests.contains(&format!("<span class=\"badge {verdict}\">")));
    assert_eq!(
        page.contains("assumes a model the data reject"),
        s["intervals_conditional"].as_bool().unwrap()
    );
}

const YAW_NOT_DETERMINED: &str = "The yaw is not determined";

/// The shipped minute drives straight: its page says the yaw is not determined, in the
/// sentences and in the attitude table, and shows every number of summary.json.
#[test]
fn the_shipped_minute_has_its_page() {
    let dir = tempfile::tempdir().unwrap();
    let (page, s) = calibrate(dir.path(), &example("imu.csv"), &example("gnss.csv"), &[]);
    assert_eq!(s["attitude_deg"]["yaw_identifiable"], false);
    check_page(&page, &s);
    assert!(page.contains(YAW_NOT_DETERMINED));
    // Negative control: the reader of the rows tells a wrong number from the right one.
    let v = s["gyro_bias_rad_s"]["value"][2].as_f64().unwrap();
    assert!(prints(&page, "gyro-bias-z", v));
    assert!(!prints(&page, "gyro-bias-z", v + 2e-4));
    assert!(!prints(&page, "gyro-bias-z", -v));
}

/// The simulated default drive turns and changes speed; calibrated with the statistics it was
/// simulated with, its yaw is determined, and the page does not say otherwise.
#[test]
fn a_drive_with_turns_determines_the_yaw_on_its_page() {
    let dir = tempfile::tempdir().unwrap();
    run(
        dir.path(),
        &["simulate", "--model", "ins", "--logs", "sim", "--quiet"],
    );
    // The [imu] and [gnss] statistics of the simulation, without the rates (not a
    // calibration's keys), as the calibration's configuration.
    let defaults = run(dir.path(), &["config", "--model", "ins"]);
    let mut config = String::from("model = \"ins\"\n");
    let mut keep = false;
    for line in defaults.lines() {
        if let Some(section) = line.strip_prefix('[') {
            keep = section.starts_with("imu]") || section.starts_with("gnss]");
        }
        if keep && !line.contains("_rate_hz") {
            config.push_str(line);
            config.push('\n');
        }
    }
    std::fs::write(dir.path().join("sim.toml"), config).unwrap();
    let sim = dir.path().join("sim");
    let (page, s) = calibrate(
        dir.path(),
        &sim.join("imu.csv"),
        &sim.join("gnss.csv"),
        &["--config", "sim.toml"],
    );
    assert_eq!(s["attitude_deg"]["yaw_identifiable"], true);
    check_page(&page, &s);
    assert!(!page.contains(YAW_NOT_DETERMINED));
    assert!(page.contains("The yaw is determined by the drive"));
    assert!(page.contains("--config sim.toml"));
    // The statistics came from the file: the page says so for the ones it changed.
    let arw = &page[page.find("<code>gyro_arw_rad_per_sqrt_s</code>").unwrap()..];
    assert!(arw[..arw.find("</tr>").unwrap()].contains("--config"));
}
