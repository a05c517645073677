//! The smoother: never less certain than the filter, a constant bias estimate, and errors that
//! match its σ over an ensemble of simulated logs.

use accelcal::calibrate::{Settings, prepare};
use accelcal::config::{Config, TruthModel};
use accelcal::input::csv::read::LogText;
use accelcal::logs::write::LogWriter;
use accelcal::simulation::run_realization;
use accelcal::stats::chi_squared_band;

use crate::{calibrate, column, common, read_csv, simulate_logs};

#[test]
fn smoothed_sigma_is_never_above_the_filtered_and_the_bias_is_constant() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    simulate_logs(dir);
    calibrate(dir, "logs/accelerometer.csv", "logs/gps.csv", "out");
    let est = read_csv(&dir.join("out/estimates.csv"));
    let mut worst_ratio = 0.0f64;
    for name in ["dp", "dv", "bias"] {
        let unit = match name {
            "dp" => "m",
            "dv" => "m_s",
            _ => "m_s2",
        };
        let f = column(&est, &format!("sigma_{name}_filtered_{unit}"));
        let s = column(&est, &format!("sigma_{name}_smoothed_{unit}"));
        for (j, (f, s)) in f.iter().zip(&s).enumerate() {
            assert!(s <= f, "{name} at row {j}: smoothed σ {s} > filtered σ {f}");
            worst_ratio = worst_ratio.max(s / f);
        }
    }
    // With a constant bias every sample's smoothed bias is the final one.
    let b = column(&est, "bias_smoothed_m_s2");
    let sb = column(&est, "sigma_bias_smoothed_m_s2");
    let end = *b.last().unwrap();
    let spread = b.iter().map(|x| (x - end).abs()).fold(0.0, f64::max);
    assert!(spread < 1e-9 * sb.last().unwrap(), "{spread}");
    eprintln!("smoothed σ / filtered σ ≤ {worst_ratio}; smoothed bias spread {spread:.1e} m/s²");
}

/// Members of the ensemble test: the samples and the states.
const SAMPLES: [usize; 4] = [0, 2020, 4000, 6000];

#[test]
fn smoothed_errors_are_consistent_with_their_sigma_over_an_ensemble() {
    let realizations = 200;
    let mut config = Config::default();
    config.ensemble.truth = TruthModel::Euler;
    let (model, schedule) = common::model_of(&config);
    let settings = Settings::from_model(&model);
    // Σ_l (e_l / σ_l)² per sample and state: χ²(L) for a consistent smoother. Negative control,
    // `wrong`: the filtered estimates judged against the smoothed σ, which the same test must
    // reject (before the last fix the smoother is more certain than the filter).
    let mut sums = [[0.0f64; 3]; SAMPLES.len()];
    let mut wrong = [[0.0f64; 3]; SAMPLES.len()];
    for l in 0..realizations {
        let (mut accel, mut gps, mut truth) = (Vec::new(), Vec::new(), Vec::new());
        let mut writer = LogWriter::new(&model.timeline, &mut accel, &mut gps, &mut truth).unwrap();
        run_realization(&model, &schedule, config.ensemble.seed, l, &mut writer);
        writer.finish().unwrap();
        let (accel, gps) = (LogText::new("a.csv", accel), LogText::new("g.csv", gps));
        let prepared = prepare(&accel, &gps, &settings).unwrap();
        let mut est = Vec::new();
        prepared.write_estimates(&mut est).unwrap();
        let parse = |bytes: &[u8]| -> Vec<Vec<f64>> {
            std::str::from_utf8(bytes)
                .unwrap()
                .lines()
                .skip(1)
                .map(|r| r.split(',').map(|x| x.parse().unwrap()).collect())
                .collect()
        };
        let (est, truth) = (parse(&est), parse(&truth));
        for (m, &j) in SAMPLES.iter().enumerate() {
            let (e, t) = (&est[j], &truth[j]);
            // δx = (p − p_c, v − v_c, b) against the smoothed estimate (columns 10–15).
            let true_dx = [t[1] - e[2], t[2] - e[3], t[3]];
            for k in 0..3 {
                let z = (true_dx[k] - e[10 + k]) / e[13 + k];
                sums[m][k] += z * z;
                let z = (true_dx[k] - e[4 + k]) / e[13 + k];
                wrong[m][k] += z * z;
            }
        }
    }
    let members = (SAMPLES.len() * 3) as f64;
    let (lo, hi) = chi_squared_band(realizations as f64, 1.0, 0.01 / members);
    eprintln!("χ²({realizations}) band [{lo:.1}, {hi:.1}]; sums {sums:.1?}; control {wrong:.1?}");
    let rejected = wrong
        .iter()
        .flatten()
        .filter(|s| !(lo..=hi).contains(*s))
        .count();
    assert!(rejected > 0, "the control was not rejected: {wrong:?}");
    for (m, row) in sums.iter().enumerate() {
        for (k, &s) in row.iter().enumerate() {
            assert!(
                (lo..=hi).contains(&s),
                "sample {} state {k}: Σ(e/σ)² = {s} outside [{lo}, {hi}]",
                SAMPLES[m]
            );
        }
    }
}
