//! `accelcal allan` against allantools: literal values computed by allantools 2024.06 outside
//! the code under test, and a live comparison with `tests/allan_reference.py` (allantools from
//! PyPI; CI installs it, and the test fails naming the missing piece when it is absent).

use std::path::Path;
use std::process::Command;

use accelcal::allan::edf::greenhall_edf;
use accelcal::allan::simulate::StaticLog;
use accelcal::allan::{analyse, deviation};
use accelcal::input::csv::text::{header, push_row};

fn relative(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// y_i = g + ((37 i mod 17) − 8)·10⁻³, i < 64, at 100 Hz: a 1 g offset on small steps.
fn small_log() -> Vec<f64> {
    (0..64)
        .map(|i| 9.80665 + (((i * 37) % 17) as f64 - 8.0) * 1e-3)
        .collect()
}

#[test]
fn oadev_of_a_small_log_equals_allantools_literals() {
    // allantools.oadev(y, rate=100.0, data_type="freq", taus="octave")
    let want = [
        0.004563485162175378,
        0.00445491991795694,
        0.0021395912874174372,
        0.0014559321826268239,
        0.0002898005779842271,
    ];
    let y = small_log();
    let factors = deviation::octave_factors(y.len());
    assert_eq!(factors, vec![1, 2, 4, 8, 16]);
    for (got, want) in deviation::oadev(&y, &factors).iter().zip(want) {
        assert!(relative(*got, want) < 1e-9, "{got} vs {want}");
    }
}

#[test]
fn greenhall_edf_equals_allantools_literals() {
    // allantools.ci.edf_greenhall(alpha, d=2, m, N, overlapping=True, modified=False)
    let cases = [
        (0, 4.0, 65.0, 18.162226912326734),
        (-2, 16.0, 65.0, 2.2883645353744133),
        (2, 2.0, 65.0, 31.909480705097664),
        (-1, 1.0, 65.0, 56.6345304043888),
        (1, 8.0, 65.0, 15.03463924698178),
        (0, 1000.0, 100001.0, 147.75534611439883),
        (-2, 1000.0, 100001.0, 91.14295421785638),
        (1, 1000.0, 100001.0, 1200.7473374792703),
        (2, 1000.0, 100001.0, 50666.399382773045),
    ];
    for (alpha, m, n, want) in cases {
        let got = greenhall_edf(alpha, 2, m, n, true).unwrap();
        assert!(
            relative(got, want) < 1e-9,
            "α {alpha}, m {m}: {got} vs {want}"
        );
    }
}

/// Whether python3 with allantools and numpy is there to compare with. Without it the live
/// comparison is skipped with a message, unless `ACCELCAL_REQUIRE_REFERENCES` is set (as `.ci/run`
/// sets it): then its absence fails the test. The literal values above are checked either way.
fn reference_available() -> bool {
    let found = Command::new("python3")
        .args(["-c", "import allantools, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("ACCELCAL_REQUIRE_REFERENCES").is_none(),
            "the live reference needs python3 with allantools and numpy \
             (pip install allantools numpy)"
        );
        eprintln!(
            "skipped: the live allantools comparison needs python3 with allantools and numpy \
             (pip install allantools numpy); the literal values were checked"
        );
    }
    found
}

fn reference(csv: &Path) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/allan_reference.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(csv)
        .args(["accel_m_s2", "100"])
        .output()
        .expect("python3 is required for this test (the allantools reference)");
    assert!(
        out.status.success(),
        "tests/allan_reference.py failed; it needs python3 with allantools and numpy \
         (pip install allantools numpy):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_simulated_log_equals_allantools_live() {
    if !reference_available() {
        return;
    }
    let log = StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 1e-3,
        offset_m_s2: 9.80665,
    };
    let y = log.samples(5000, 3);
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("static.csv");
    let mut text = header(&["t_s", "accel_m_s2"]);
    for (i, v) in y.iter().enumerate() {
        push_row(&mut text, &[i as f64 * 0.01, *v]);
    }
    std::fs::write(&csv, text).unwrap();
    let r = reference(&csv);
    let a = analyse(&y, 0.01, 0.683).unwrap();
    let taus = r["tau_s"].as_array().unwrap();
    assert_eq!(taus.len(), a.points.len());
    for (k, p) in a.points.iter().enumerate() {
        let want = r["adev"][k].as_f64().unwrap();
        assert!(
            relative(p.adev, want) < 1e-9,
            "τ {}: {} vs {want}",
            p.tau_s,
            p.adev
        );
        assert!(relative(p.tau_s, taus[k].as_f64().unwrap()) < 1e-12);
        if let Some(alpha) = r["alpha"][k].as_i64() {
            assert!(p.identified_here);
            assert_eq!(p.noise.unwrap().alpha as i64, alpha, "α at τ {}", p.tau_s);
        }
    }
    for case in r["edf"].as_array().unwrap() {
        let (alpha, m, n) = (
            case["alpha"].as_i64().unwrap() as i32,
            case["m"].as_f64().unwrap(),
            case["n_phase"].as_f64().unwrap(),
        );
        let got = greenhall_edf(alpha, 2, m, n, true);
        match case["edf"].as_f64() {
            Some(want) => assert!(relative(got.unwrap(), want) < 1e-9, "{case}: {got:?}"),
            None => assert!(got.is_none(), "{case}: {got:?}"),
        }
    }
}
