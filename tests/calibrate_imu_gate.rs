//! `calibrate --imu` with the χ² innovation gate (`[filter] innovation_gate = true`) on a
//! simulated drive whose GNSS log has one fix in 100 moved north by 30σ: every moved fix is
//! rejected and named in `summary.json` (line, time, component), the biases stay within their
//! σ of the clean log's, and the NIS test passes; without the gate the same log fails the NIS
//! test (the control). The gate's key outside `[filter]`, and the gate with `--estimate-noise`,
//! are refused with exit code 2.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::run_in;

/// The study's statistics as `calibrate --imu` reads them: its `[imu]` and `[gnss]` sections
/// without the rates (the logs' own).
fn study_statistics(dir: &Path) -> String {
    let out = run_in(dir, &["config", "--model", "ins"], None);
    let text = String::from_utf8(out.stdout).expect("UTF-8");
    let mut keep = false;
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.starts_with('[') {
            keep = line == "[imu]" || line == "[gnss]";
        }
        let rate = line.starts_with("imu_rate_hz") || line.starts_with("gnss_rate_hz");
        if keep && !rate && !line.starts_with('#') {
            lines.push(line);
        }
    }
    lines.join("\n") + "\n"
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("written")).expect("JSON")
}

/// Runs `calibrate --imu` in `dir` into `out` with the configuration `config`.
fn calibrate(dir: &Path, gnss: &str, config: &str, out: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "calibrate",
        "--imu",
        "sim/imu.csv",
        "--gnss",
        gnss,
        "--config",
        config,
        "--out",
        out,
        "--quiet",
    ];
    args.extend(extra);
    let o = run_in(dir, &args, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    read_json(&dir.join(out).join("summary.json"))
}

/// The six biases and their σ's of a summary.
fn biases(s: &serde_json::Value) -> Vec<(f64, f64)> {
    ["gyro_bias_rad_s", "accel_bias_m_s2"]
        .iter()
        .flat_map(|k| {
            (0..3).map(move |i| {
                let t = &s[*k];
                (
                    t["value"][i].as_f64().expect("value"),
                    t["sigma"][i].as_f64().expect("sigma"),
                )
            })
        })
        .collect()
}

/// `moved.csv`: the simulated GNSS log with one fix in 100 moved 30σ north; the lines moved.
fn move_fixes(d: &Path) -> BTreeSet<u64> {
    // One fix in 100 (data rows 37, 137, …) moved 30 m north: 30σ of the north σ of 1 m. The
    // north radius of curvature at 37.4° is 6 357 500 m within 0.05 %.
    let text = std::fs::read_to_string(d.join("sim/gnss.csv")).unwrap();
    let mut moved = BTreeSet::new();
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if k > 0 && (k - 1) % 100 == 36 {
            let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
            let lat: f64 = f[1].parse().unwrap();
            f[1] = (lat + (30.0 / 6_357_500.0_f64).to_degrees()).to_string();
            out.push(f.join(","));
            moved.insert(k as u64 + 1);
        } else {
            out.push(line.to_string());
        }
    }
    assert_eq!(moved.len(), 3);
    std::fs::write(d.join("moved.csv"), out.join("\n") + "\n").unwrap();
    moved
}

#[test]
fn the_gate_rejects_every_moved_fix_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("short.toml"),
        "model = \"ins\"\n[drive]\nduration_s = 300.0\n",
    )
    .unwrap();
    let o = run_in(
        d,
        &[
            "simulate",
            "--model",
            "ins",
            "--config",
            "short.toml",
            "--logs",
            "sim",
            "--quiet",
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stats = study_statistics(d);
    std::fs::write(d.join("off.toml"), &stats).unwrap();
    std::fs::write(
        d.join("on.toml"),
        format!("{stats}[filter]\ninnovation_gate = true\n"),
    )
    .unwrap();

    let moved = move_fixes(d);

    let clean = calibrate(d, "sim/gnss.csv", "on.toml", "clean", &[]);
    let gated = calibrate(d, "moved.csv", "on.toml", "gated", &[]);
    let ungated = calibrate(d, "moved.csv", "off.toml", "ungated", &[]);

    let gate = &gated["gate"];
    assert_eq!(gate["enabled"], true);
    let rejected: BTreeSet<u64> = gate["rejected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["line"].as_u64().unwrap())
        .collect();
    eprintln!(
        "moved {moved:?}, rejected {rejected:?}, by chance {}",
        gate["expected_by_chance"]
    );
    for r in gate["rejected"].as_array().unwrap() {
        if moved.contains(&r["line"].as_u64().unwrap()) {
            assert_eq!(r["component"], "position_north", "{r}");
            assert!(r["nis"].as_f64().unwrap() > 100.0, "{r}");
        }
    }
    assert!(
        moved.is_subset(&rejected),
        "moved {moved:?}, rejected {rejected:?}"
    );
    // Besides the moved fixes, what chance explains: at most the 99 % point of Binomial(n, α).
    let tested = gate["tested"].as_u64().unwrap();
    let (_, hi) = common::imu::band(tested, 0.01, 0.02);
    assert!((rejected.len() - moved.len()) as u64 <= hi, "{rejected:?}");
    assert_eq!(
        gated["fixes_used"].as_u64().unwrap() + rejected.len() as u64,
        tested
    );
    for (k, (g, c)) in biases(&gated).iter().zip(biases(&clean)).enumerate() {
        assert!(
            (g.0 - c.0).abs() < c.1,
            "bias {k}: {g:?} against the clean {c:?}"
        );
    }
    assert_eq!(gated["nis"]["verdict"], "pass", "{}", gated["nis"]);
    // The control: the same log ungated takes the moved fixes and fails the NIS test.
    assert_eq!(ungated["gate"]["enabled"], false);
    assert!(ungated["gate"]["rejected"].as_array().unwrap().is_empty());
    assert_eq!(ungated["nis"]["verdict"], "fail", "{}", ungated["nis"]);
    let page = std::fs::read_to_string(d.join("gated/index.html")).unwrap();
    assert!(
        page.contains("The χ² gate at α = 0.01 tested"),
        "the page says what the gate did"
    );
}

#[test]
fn the_gate_is_refused_outside_the_filter_and_with_the_noise_search() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/comma2k19_3d");
    let (imu, gnss) = (examples.join("imu.csv"), examples.join("gnss.csv"));
    let (imu, gnss) = (imu.to_str().unwrap(), gnss.to_str().unwrap());
    for (text, extra, words) in [
        (
            "[imu]\ninnovation_gate = true\n",
            &[][..],
            "imu.innovation_gate",
        ),
        (
            "[filter]\ninnovation_gate = true\n",
            &["--estimate-noise"][..],
            "filter.innovation_gate",
        ),
    ] {
        std::fs::write(d.join("c.toml"), text).unwrap();
        let mut args = vec![
            "calibrate",
            "--imu",
            imu,
            "--gnss",
            gnss,
            "--config",
            "c.toml",
            "--out",
            "out",
        ];
        args.extend(extra);
        let o = run_in(d, &args, None);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(words), "{text}: {err}");
        assert!(!d.join("out").exists(), "nothing written on a refusal");
    }
}
