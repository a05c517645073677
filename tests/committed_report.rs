//! The committed `report/data.json` is what the code produces now for the default
//! configuration; only timing and version fields may differ. Regenerate with `cargo run --release`.

use accelcal::config::Config;
use accelcal::model::Model;
use accelcal::study::{Silent, Study};
use serde_json::Value;

const VOLATILE: [&str; 3] = ["accelcal_version", "realizations_per_s", "elapsed_s"];

/// Compares `a` and `b`, numbers to a relative 1e-9, skipping volatile keys; returns the first
/// difference's path.
fn diff(a: &Value, b: &Value, path: &str) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter()
                .filter(|k| !VOLATILE.contains(&k.as_str()))
                .find_map(|k| match (x.get(k), y.get(k)) {
                    (Some(p), Some(q)) => diff(p, q, &format!("{path}.{k}")),
                    _ => Some(format!("{path}.{k} is only on one side")),
                })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (p, q))| diff(p, q, &format!("{path}[{i}]"))),
        (Value::Number(x), Value::Number(y)) => {
            let (p, q) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            ((p - q).abs() > 1e-9 * p.abs().max(q.abs()) + 1e-300)
                .then(|| format!("{path}: {p} vs {q}"))
        }
        _ => (a != b).then(|| format!("{path}: {a} vs {b}")),
    }
}

/// The default study with its sensitivity, its drifting bias, the three-axis study and its noise statistics, as `cargo run --release` writes it; run once.
fn default_study() -> &'static Study {
    static STUDY: std::sync::OnceLock<Study> = std::sync::OnceLock::new();
    STUDY.get_or_init(|| {
        Study::run(&Model::new(&Config::default()).unwrap(), &mut Silent)
            .unwrap()
            .with_sensitivity(&mut Silent)
            .unwrap()
            .with_drift(&mut Silent)
            .unwrap()
            .with_ins(&mut Silent)
            .unwrap()
            .with_noise(accelcal::study::noise::NOISE_DRIVES, &mut Silent)
            .unwrap()
            .with_real_drive()
            .unwrap()
            .with_real_drive_3d()
            .unwrap()
    })
}

/// `html` with the content of every element of class `timing` removed: run times, rates and
/// the thread count vary between runs.
fn without_timing(html: &str) -> String {
    let mut out = String::with_capacity(html.len());
    let mut rest = html;
    while let Some(i) = rest.find("timing\">") {
        let start = i + "timing\">".len();
        out.push_str(&rest[..start]);
        let end = rest[start..].find('<').map_or(rest.len(), |j| start + j);
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

#[test]
fn committed_page_matches_the_code() {
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/report/index.html"))
            .expect("report/index.html is committed");
    let study = default_study();
    let static_noise = accelcal::allan::section::report_coverage().unwrap();
    let input = accelcal::report::ReportInput {
        study,
        command: "accelcal report",
        threads: 1,
        static_noise: Some(&static_noise),
    };
    let now = accelcal::report::render(&input).unwrap().html;
    let (a, b) = (without_timing(&committed), without_timing(&now));
    if a != b {
        let line = a
            .lines()
            .zip(b.lines())
            .position(|(x, y)| x != y)
            .unwrap_or(a.lines().count().min(b.lines().count()));
        panic!(
            "report/index.html is stale (run `cargo run --release`): first difference at line {}:\n{}\nvs\n{}",
            line + 1,
            a.lines()
                .nth(line)
                .unwrap_or("")
                .chars()
                .take(300)
                .collect::<String>(),
            b.lines()
                .nth(line)
                .unwrap_or("")
                .chars()
                .take(300)
                .collect::<String>()
        );
    }
}

#[test]
fn timing_cells_are_masked_and_nothing_else() {
    let a = "<td class=\"num timing\">1.23</td><td>4</td>";
    let b = "<td class=\"num timing\">9.87</td><td>4</td>";
    assert_eq!(without_timing(a), without_timing(b));
    assert_ne!(without_timing(a), without_timing(&b.replace('4', "5")));
}

#[test]
fn committed_data_matches_the_code() {
    let committed: Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/report/data.json"))
            .expect("report/data.json is committed"),
    )
    .unwrap();
    let study = default_study();
    let input = accelcal::report::ReportInput {
        study,
        command: "accelcal report",
        threads: 1,
        static_noise: None,
    };
    let now: Value = serde_json::from_str(&accelcal::report::data_json(&input)).unwrap();
    if let Some(d) = diff(&committed, &now, "data") {
        panic!("report/data.json is stale (run `cargo run --release`): first difference at {d}");
    }
}

#[test]
fn the_comparison_sees_a_change() {
    let a: Value = serde_json::json!({"x": [1.0, 2.0], "elapsed_s": 1.0});
    let b: Value = serde_json::json!({"x": [1.0, 2.000001], "elapsed_s": 9.0});
    assert!(diff(&a, &b, "d").is_some());
    let c: Value = serde_json::json!({"x": [1.0, 2.0], "elapsed_s": 9.0});
    assert!(diff(&a, &c, "d").is_none());
}
