//! A prior that disagrees with the first fix is said so, on standard error and in
//! `summary.json`; a prior drawn as the truth was is not.

use super::{run, simulate_logs, stderr};

/// Calibrates the logs of `simulate_logs` with `config` (TOML text, empty for the defaults);
/// returns the summary's warnings and standard error.
fn warnings(dir: &std::path::Path, name: &str, config: &str) -> (Vec<String>, String) {
    let toml = format!("{name}.toml");
    crate::full_config(dir, &toml, config);
    let o = run(
        &[
            "calibrate",
            "--config",
            &toml,
            "--accel",
            "logs/accelerometer.csv",
            "--gps",
            "logs/gps.csv",
            "--out",
            name,
            "-q",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join(name).join("summary.json")).unwrap(),
    )
    .unwrap();
    let list = summary["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    (list, stderr(&o))
}

/// The simulation draws v(0) ~ N(100, 1²) m/s and p(0) ~ N(0, 10²) m: the configured prior is
/// consistent (beyond 5σ with probability about 10⁻⁶) and nothing is said. A velocity prior of
/// 90 m/s (about 9σ off) and a position prior of 100 m (about 10σ off) are named by their keys.
#[test]
fn a_prior_far_from_the_first_fix_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    simulate_logs(d);
    let (none, err) = warnings(d, "consistent", "");
    assert!(none.is_empty(), "{none:?}");
    assert!(!err.contains("warning"), "{err}");
    for (name, config, key) in [
        (
            "velocity",
            "[initial]\nvelocity_mean_m_s = 90.0\n",
            "initial.velocity_mean_m_s",
        ),
        (
            "position",
            "[initial]\nposition_mean_m = 100.0\n",
            "initial.position_mean_m",
        ),
    ] {
        let (list, err) = warnings(d, name, config);
        assert_eq!(list.len(), 1, "{list:?}");
        assert!(list[0].contains(key), "{list:?}");
        assert!(err.contains(&format!("warning: {}", list[0])), "{err}");
    }
}
