//! A bias that drifts (random walk, Gauss–Markov) in the truth and in the filter.
//!
//! - A filter whose bias model matches the truth's passes every check at N = 10 000 on the euler
//!   truth, with both engines, for a random walk and a Gauss–Markov bias whose drift over the run
//!   is comparable to the prior σ_b; a constant-bias filter on the random-walk truth fails NEES
//!   (the negative control: the drift is really simulated and really matters).
//! - The filter's covariance at every fix equals an independent computation: a Kalman filter
//!   written here with plain arrays, whose Φ and Q come from Van Loan's matrix exponential of an
//!   augmented continuous system (δp, δv, b held over the step, w held over the step, b).
//! - The per-sample engine's lanes reproduce the scalar realization bit for bit with a drifting
//!   bias too.
//! - `bias_model = "constant"` written out gives the same outputs as leaving it out; the truth's
//!   bias path is in `simulate --csv`; bad bias keys are refused by the command line (exit 2,
//!   the key named).

mod common;

use accelcal::checks::{CheckId, Verdict, Verdicts};
use accelcal::config::{BiasModelKind, Config, TruthModel};
use accelcal::ensemble::{Engine, Ensemble, kernel};
use accelcal::simulation::{FixState, run_realization, stream_key};
use accelcal::study::{Silent, run_case};
use common::plain::{M3, gps_gain, i_minus_kh, mul, transpose};
use nalgebra::SMatrix;

/// K of the random-walk truth, m/s²/√s: over the 30 s run the bias moves by K·√30 ≈ 0.11 m/s²,
/// about its prior σ_b = 0.1 m/s².
const K: f64 = 0.02;
/// τ_b of the Gauss–Markov truth, s: over 30 s the bias changes by σ_b·√(2(1 − e^(−1.5))) ≈
/// 1.2·σ_b.
const TAU_B: f64 = 20.0;

fn random_walk() -> Config {
    let mut c = Config::default();
    c.accelerometer.bias_model = BiasModelKind::RandomWalk;
    c.accelerometer.bias_random_walk_m_s2_per_sqrt_s = Some(K);
    c.ensemble.truth = TruthModel::Euler;
    c
}

fn gauss_markov() -> Config {
    let mut c = Config::default();
    c.accelerometer.bias_model = BiasModelKind::GaussMarkov;
    c.accelerometer.bias_correlation_time_s = Some(TAU_B);
    c.ensemble.truth = TruthModel::Euler;
    c
}

fn verdicts(config: &Config, engine: Engine) -> Verdicts {
    let (model, schedule) = common::model_of(config);
    let ensemble = Ensemble::new(&model, &schedule).with_engine(engine);
    run_case(&ensemble, &mut Silent).verdicts
}

#[test]
fn the_drift_over_the_run_is_comparable_to_the_prior_sigma() {
    let c = Config::default();
    let (sigma_b, t) = (c.accelerometer.bias_var_m2_s4.sqrt(), c.profile.duration_s);
    let rw = K * t.sqrt();
    let gm = sigma_b * (2.0 * (1.0 - (-t / TAU_B).exp())).sqrt();
    for drift in [rw, gm] {
        assert!(
            (0.5..2.0).contains(&(drift / sigma_b)),
            "{drift} vs {sigma_b}"
        );
    }
}

#[test]
fn matching_filters_pass_every_check_on_both_engines() {
    for (name, config) in [
        ("random walk", random_walk()),
        ("gauss-markov", gauss_markov()),
    ] {
        assert_eq!(config.ensemble.realizations, 10_000);
        assert!(config.filter_matches_truth());
        for engine in [Engine::Sample, Engine::Epoch] {
            let v = verdicts(&config, engine);
            for c in &v.checks {
                assert_eq!(c.verdict, Verdict::Pass, "{name}, {engine}: {c:?}");
            }
        }
    }
}

#[test]
fn a_constant_bias_filter_on_a_random_walk_fails_nees() {
    let mut config = random_walk();
    config.filter.bias_model = Some(BiasModelKind::Constant);
    for engine in [Engine::Sample, Engine::Epoch] {
        let v = verdicts(&config, engine);
        assert_eq!(v.get(CheckId::NEES).verdict, Verdict::Fail, "{engine}");
    }
}

#[test]
#[allow(clippy::needless_range_loop)] // k is the lane, of the group and of `scalar`
fn lane_groups_reproduce_the_scalar_realizations_with_a_drifting_bias() {
    for mut config in [random_walk(), gauss_markov()] {
        config.profile.duration_s = 3.0;
        for truth in TruthModel::ALL {
            config.ensemble.truth = truth;
            let (m, s) = common::model_of(&config);
            let key = stream_key(11, m.case());
            let (first, active) = (37u64, 5usize);
            let scalar: Vec<Vec<FixState>> = (0..active as u64)
                .map(|k| {
                    let mut keep = common::Keep(Vec::new());
                    run_realization(&m, &s, 11, first + k, &mut keep);
                    keep.0
                })
                .collect();
            let mut bias_moved = false;
            kernel::run_group(&m, &s, key, first, active, |i, f| {
                for k in 0..active {
                    let r = &scalar[k][i];
                    let lane = |v: &[accelcal::lanes::Lanes]| -> Vec<u64> {
                        v.iter().map(|x| x.0[k].to_bits()).collect()
                    };
                    let bits = |v: &[f64]| -> Vec<u64> { v.iter().map(|x| x.to_bits()).collect() };
                    assert_eq!(
                        lane(&f.delta_x),
                        bits(r.delta_x.as_slice()),
                        "{truth} {i} {k}"
                    );
                    assert_eq!(lane(&f.post), bits(r.post.as_slice()), "{truth} {i} {k}");
                    assert_eq!(lane(&f.residual), bits(r.residual.as_slice()));
                    bias_moved |= i > 0 && r.delta_x[2] != scalar[k][0].delta_x[2];
                }
            });
            assert!(bias_moved, "the truth's bias never moved");
        }
    }
}

/// One accelerometer step of the sampled system, from the matrix exponential of its continuous
/// form: Van Loan's method on z = (δp, δv, b_h, w_h, b), where b_h and w_h hold the bias and the
/// white noise read at the sample over the step, and b moves continuously
/// (ḃ = −b/τ_b + w_b, or ḃ = w_b for a random walk, w_b of spectral density `q_c`).
fn van_loan_step(dt: f64, w: f64, decay_per_s: f64, q_c: f64) -> (M3, M3) {
    type M5 = SMatrix<f64, 5, 5>;
    let mut a = M5::zeros();
    a[(0, 1)] = 1.0;
    a[(1, 2)] = -1.0;
    a[(1, 3)] = -1.0;
    a[(4, 4)] = -decay_per_s;
    let mut gqg = M5::zeros();
    gqg[(4, 4)] = q_c;
    let mut f = SMatrix::<f64, 10, 10>::zeros();
    f.fixed_view_mut::<5, 5>(0, 0).copy_from(&(-a * dt));
    f.fixed_view_mut::<5, 5>(0, 5).copy_from(&(gqg * dt));
    f.fixed_view_mut::<5, 5>(5, 5)
        .copy_from(&(a.transpose() * dt));
    let e = f.exp();
    let phi: M5 = e.fixed_view::<5, 5>(5, 5).transpose();
    let q: M5 = phi * e.fixed_view::<5, 5>(0, 5);
    // z(t_j) = S·x + (0, 0, 0, w_j, 0), x(t_{j+1}) = T·z(t_{j+1}).
    let mut s = SMatrix::<f64, 5, 3>::zeros();
    s[(0, 0)] = 1.0;
    s[(1, 1)] = 1.0;
    s[(2, 2)] = 1.0;
    s[(4, 2)] = 1.0;
    let mut t = SMatrix::<f64, 3, 5>::zeros();
    t[(0, 0)] = 1.0;
    t[(1, 1)] = 1.0;
    t[(2, 4)] = 1.0;
    let mut held_w = M5::zeros();
    held_w[(3, 3)] = w;
    let phi3 = t * phi * s;
    let q3 = t * (phi * held_w * phi.transpose() + q) * t.transpose();
    let arr = |m: SMatrix<f64, 3, 3>| -> M3 {
        std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
    };
    (arr(phi3), arr(q3))
}

/// The covariance at every fix (a priori, a posteriori) and the transition between fixes of a
/// textbook Kalman filter with the step (Φ, Q), 40 steps per fix, H selecting (δp, δv).
fn plain_filter(config: &Config, phi: &M3, q: &M3) -> Vec<(M3, M3, M3)> {
    let (a, g, i) = (&config.accelerometer, &config.gps, &config.initial);
    let (rp, rv) = (g.position_sigma_m.powi(2), g.velocity_sigma_m_s.powi(2));
    let mut p: M3 = [
        [i.position_sigma_m.powi(2), 0.0, 0.0],
        [0.0, i.velocity_sigma_m_s.powi(2), 0.0],
        [0.0, 0.0, a.bias_var_m2_s4],
    ];
    let per_fix = (a.sample_rate_hz / g.sample_rate_hz).round() as usize;
    let fixes = (config.profile.duration_s * g.sample_rate_hz).round() as usize;
    let mut out = Vec::new();
    for _ in 0..fixes {
        let mut phi_n: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for _ in 0..per_fix {
            p = mul(&mul(phi, &p), &transpose(phi));
            for r in 0..3 {
                for c in 0..3 {
                    p[r][c] += q[r][c];
                }
            }
            phi_n = mul(phi, &phi_n);
        }
        let prior = p;
        p = mul(&i_minus_kh(&gps_gain(&prior, rp, rv)), &prior);
        out.push((prior, p, phi_n));
    }
    out
}

fn assert_close(got: &SMatrix<f64, 3, 3>, want: &M3, what: &str) {
    for r in 0..3 {
        for c in 0..3 {
            let scale = (want[r][r] * want[c][c]).sqrt().max(want[r][c].abs());
            let err = (got[(r, c)] - want[r][c]).abs();
            assert!(
                err <= 1e-9 * scale,
                "{what} ({r}, {c}): {} vs {}",
                got[(r, c)],
                want[r][c]
            );
        }
    }
}

#[test]
fn the_covariance_is_the_exact_discretization_at_every_fix() {
    for config in [random_walk(), gauss_markov()] {
        let a = &config.accelerometer;
        let (w, var_b) = (a.noise_var_m2_s4, a.bias_var_m2_s4);
        let dt = 1.0 / a.sample_rate_hz;
        let (decay, q_c) = match a.bias_model {
            BiasModelKind::RandomWalk => (0.0, K * K),
            _ => (1.0 / TAU_B, 2.0 * var_b / TAU_B),
        };
        let (phi, q) = van_loan_step(dt, w, decay, q_c);
        let reference = plain_filter(&config, &phi, &q);
        let (_, schedule) = common::model_of(&config);
        assert_eq!(schedule.fixes.len(), reference.len());
        for (i, (fix, (prior, post, phi_n))) in schedule.fixes.iter().zip(&reference).enumerate() {
            let what = format!("{}, fix {i}", a.bias_model);
            assert_close(&fix.p_prior, prior, &format!("P⁻ {what}"));
            assert_close(&fix.p_post, post, &format!("P⁺ {what}"));
            for (r, row) in phi_n.iter().enumerate() {
                for (c, want) in row.iter().enumerate() {
                    let err = (fix.phi_from_previous[(r, c)] - want).abs();
                    assert!(err <= 1e-9 * want.abs().max(1e-3), "Φ {what} ({r}, {c})");
                }
            }
        }
        // The negative control: the constant-bias step differs from the drifting one by more
        // than the tolerance, so the comparison can fail.
        let (_, constant) = van_loan_step(dt, w, 0.0, 0.0);
        let drifted = plain_filter(&config, &phi, &constant);
        let last = schedule.fixes.last().unwrap();
        let (_, post, _) = drifted.last().unwrap();
        assert!((last.p_post[(2, 2)] - post[2][2]).abs() > 1e-6 * post[2][2]);
    }
}

fn write_config(dir: &std::path::Path, name: &str, toml: &str) {
    std::fs::write(dir.join(name), toml).unwrap();
}

/// The ensemble JSON of `config` (timings left out) with `engine`.
fn ensemble_doc(dir: &std::path::Path, config: &str, engine: &str) -> serde_json::Value {
    let out = format!("{config}-{engine}.json");
    let args = [
        "ensemble",
        "--config",
        config,
        "--engine",
        engine,
        "--realizations",
        "500",
        "--json",
        &out,
        "--quiet",
    ];
    let o = common::run_in(dir, &args, Some(2));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    common::summary_without_timing(&dir.join(out))
}

#[test]
fn an_explicit_constant_bias_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let euler = "[ensemble]\ntruth = \"euler\"\n";
    write_config(dir.path(), "none.toml", euler);
    let truth = format!("[accelerometer]\nbias_model = \"constant\"\n{euler}");
    write_config(dir.path(), "truth.toml", &truth);
    let filter = format!("{truth}[filter]\nbias_model = \"constant\"\n");
    write_config(dir.path(), "filter.toml", &filter);
    let rw = format!(
        "{truth}[filter]\nbias_model = \"random_walk\"\nbias_random_walk_m_s2_per_sqrt_s = 1e-12\n"
    );
    write_config(dir.path(), "rw.toml", &rw);
    for engine in ["sample", "epoch"] {
        let none = ensemble_doc(dir.path(), "none.toml", engine);
        // The accelerometer's constant bias is not echoed: the whole document is the same.
        assert!(
            ensemble_doc(dir.path(), "truth.toml", engine) == none,
            "{engine}"
        );
        // A filter key set is echoed in the configuration, as every [filter] key is; nothing else
        // changes.
        let without_config = |mut v: serde_json::Value| {
            v.as_object_mut().unwrap().remove("config");
            v
        };
        let explicit = without_config(ensemble_doc(dir.path(), "filter.toml", engine));
        assert!(explicit == without_config(none.clone()), "{engine}");
        // The negative control: a random walk of K = 10⁻¹² has almost the same covariance, but its
        // bias is no longer a constant state, so the checks count its a priori copy: the document
        // differs, and the comparison can tell.
        let walk = without_config(ensemble_doc(dir.path(), "rw.toml", engine));
        assert!(walk != explicit, "{engine}");
    }
}

/// The bias column of `simulate --csv`, sample by sample.
fn simulated_bias(dir: &std::path::Path, config: &str) -> Vec<f64> {
    let o = common::run_in(
        dir,
        &["simulate", "--config", config, "--csv", "r.csv", "--quiet"],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.join("r.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "bias_true_m_s2").unwrap();
    lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn simulate_writes_the_truths_bias_path() {
    let dir = tempfile::tempdir().unwrap();
    write_config(dir.path(), "constant.toml", "");
    write_config(
        dir.path(),
        "rw.toml",
        &format!(
            "[accelerometer]\nbias_model = \"random_walk\"\n\
             bias_random_walk_m_s2_per_sqrt_s = {K}\n"
        ),
    );
    let constant = simulated_bias(dir.path(), "constant.toml");
    assert!(constant.iter().all(|&b| b == constant[0]));
    let rw = simulated_bias(dir.path(), "rw.toml");
    assert_eq!(rw.len(), constant.len());
    // The increments of the path have the variance K²·Δt (6000 of them: within 10 %, more than
    // 7 standard errors of a variance estimate, √(2/6000) ≈ 1.8 %).
    let dt = 0.005;
    let var = rw.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (rw.len() - 1) as f64;
    assert!(
        (var / (K * K * dt) - 1.0).abs() < 0.1,
        "increment variance {var}"
    );
}

fn refuses(toml: &str, key: &str) {
    let dir = tempfile::tempdir().unwrap();
    write_config(dir.path(), "c.toml", toml);
    let o = common::run_in(
        dir.path(),
        &["ensemble", "--config", "c.toml", "--quiet"],
        None,
    );
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{toml:?}: {msg}");
    assert!(msg.contains(key), "{toml:?}: {msg}");
    assert!(msg.contains("c.toml") && !msg.contains("panicked"), "{msg}");
}

#[test]
fn bad_bias_keys_are_refused_by_name() {
    let rw = "[accelerometer]\nbias_model = \"random_walk\"\n";
    let gm = "[accelerometer]\nbias_model = \"gauss_markov\"\n";
    let k = "bias_random_walk_m_s2_per_sqrt_s";
    let tau = "bias_correlation_time_s";
    refuses(
        &format!("[accelerometer]\n{k} = 0.01\n"),
        &format!("accelerometer.{k}"),
    );
    refuses(
        &format!("{rw}{k} = 0.01\n{tau} = 5.0\n"),
        &format!("accelerometer.{tau}"),
    );
    refuses(&format!("{rw}{k} = -0.01\n"), &format!("accelerometer.{k}"));
    refuses(&format!("{rw}{k} = nan\n"), &format!("accelerometer.{k}"));
    refuses(rw, &format!("accelerometer.{k}"));
    refuses(
        &format!("{gm}{tau} = 0.0\n"),
        &format!("accelerometer.{tau}"),
    );
    refuses(
        &format!("{gm}{tau} = -3.0\n"),
        &format!("accelerometer.{tau}"),
    );
    refuses(
        &format!("{gm}{tau} = inf\n"),
        &format!("accelerometer.{tau}"),
    );
    refuses(
        &format!("{gm}{tau} = 5.0\n[filter]\n{k} = 0.1\n"),
        &format!("filter.{k}"),
    );
    refuses(
        "[filter]\nbias_model = \"random_walk\"\n",
        &format!("filter.{k}"),
    );
    refuses(
        &format!("[filter]\nbias_model = \"gauss_markov\"\n{tau} = 0\n"),
        &format!("filter.{tau}"),
    );
    refuses(
        "[accelerometer]\nbias_model = \"wandering\"\n",
        "bias_model",
    );
}

/// The drifting-bias section of a small study's report: the constant-bias filter fails NEES and
/// claims far less error than it makes, the random-walk filter passes every check and achieves
/// what it claims, and the page's sentence says so; the same section with the filters' numbers
/// exchanged says the opposite (the words follow the numbers, not the filters' names).
#[test]
fn the_report_shows_what_a_drifting_bias_costs() {
    use accelcal::report::{ReportInput, render};
    use accelcal::study::Study;
    let mut config = Config::default();
    config.ensemble.realizations = 500;
    let model = accelcal::model::Model::new(&config).unwrap();
    let study = Study::run(&model, &mut Silent)
        .unwrap()
        .with_drift(&mut Silent)
        .unwrap();
    let d = study.drift.as_ref().expect("the drifting-bias study ran");
    assert_eq!(
        d.constant.verdicts.get(CheckId::NEES).verdict,
        Verdict::Fail
    );
    assert!(d.random_walk.verdicts.all_passed());
    let bias = |f: &accelcal::study::drift::DriftFilter| {
        let i = f.nearest(120.0);
        (f.claimed_sigma[i][2], f.achieved_rms[i][2])
    };
    let ((cc, ca), (rc, ra)) = (bias(&d.constant), bias(&d.random_walk));
    assert!(ca > 10.0 * cc, "constant: claims {cc}, achieves {ca}");
    assert!(
        (ra / rc - 1.0).abs() < 1e-9,
        "random walk: claims {rc}, achieves {ra}"
    );
    let input = |study| ReportInput {
        study,
        command: "accelcal report",
        threads: 1,
        static_noise: None,
    };
    let page = render(&input(&study)).unwrap();
    assert!(page.view.toc.iter().any(|t| t.anchor == "drifting-bias"));
    assert!(page.html.contains("<section id=\"drifting-bias\">"));
    assert!(page.html.contains("id=\"fig-drift\"") && page.html.contains("<svg"));
    let sentence = format!(
        "The constant-bias filter claims {} mm/s² at 120 s",
        fmt_mm(cc)
    );
    assert!(page.html.contains(&sentence), "{sentence}");
    assert!(page.html.contains("times worse than it claims"));
    assert!(page.html.contains("its claim holds (every check passes)"));
    let data: serde_json::Value =
        serde_json::from_str(&accelcal::report::data_json(&input(&study))).unwrap();
    let filters = &data["drifting_bias"]["filters"];
    assert_eq!(filters[0]["bias_model"], "constant");
    assert_eq!(filters[0]["verdicts"]["nees"], "fail");
    assert_eq!(filters[1]["bias_model"], "random_walk");
    // The negative control: the numbers exchanged, the words follow them.
    let mut swapped = study.clone();
    let s = swapped.drift.as_mut().unwrap();
    std::mem::swap(&mut s.constant, &mut s.random_walk);
    let html = render(&input(&swapped)).unwrap().html;
    let sentence = format!(
        "The constant-bias filter claims {} mm/s² at 120 s and achieves {} mm/s²: its claim holds",
        fmt_mm(rc),
        fmt_mm(ra)
    );
    assert!(html.contains(&sentence), "{sentence}");
    assert!(html.contains("the random-walk filter claims") && html.contains("nees, nis fail"));
}

/// x in mm/s² with two significant digits, as the report writes it.
fn fmt_mm(x_m_s2: f64) -> String {
    accelcal::format::sig(1e3 * x_m_s2, 2)
}

/// K is a parameter of the sensitivity study for a filter that assumes a random walk: the filter
/// with the truth's K claims what it achieves, one that assumes a quarter of it claims less and
/// is detected by NEES, one that assumes four times it claims more; a filter without a random
/// walk is not offered K.
#[test]
fn the_random_walk_is_a_parameter_of_the_sensitivity_study() {
    use accelcal::ensemble::Engine;
    use accelcal::sensitivity::{self, AssumedStatistic, Plan};
    assert!(!AssumedStatistic::of(&Config::default()).contains(&AssumedStatistic::BiasRandomWalk));
    let config = random_walk();
    assert!(AssumedStatistic::of(&config).contains(&AssumedStatistic::BiasRandomWalk));
    let plan = Plan {
        parameters: vec![AssumedStatistic::BiasRandomWalk],
        factors: vec![0.25, 1.0, 4.0],
        realizations: 1_000,
        ensembles: 1,
        draws: 200,
        engine: Engine::Epoch,
    };
    let s = sensitivity::run(&config, &plan, &mut Silent).unwrap();
    let ratio = |i: usize| {
        let c = &s.cases[i];
        c.actual_sigma_final[2] / c.claimed_sigma_final[2]
    };
    assert!(ratio(0) > 1.5, "K × 0.25: {}", ratio(0));
    assert!((ratio(1) - 1.0).abs() < 1e-9, "K × 1: {}", ratio(1));
    assert!((s.cases[1].expected_nees_final - 3.0).abs() < 1e-9);
    assert!(ratio(2) < 0.9, "K × 4: {}", ratio(2));
    assert!(s.cases[0].expected_nees_final > 4.0);
    assert_eq!(s.cases[0].detection(CheckId::NEES), Some(1.0));
    let measured = s.cases[0].detected.as_ref().unwrap();
    assert_eq!(measured[CheckId::NEES.index()], 1.0);
    // τ_b is offered for a Gauss–Markov filter, K is not.
    let gm = AssumedStatistic::of(&gauss_markov());
    assert!(gm.contains(&AssumedStatistic::BiasCorrelationTime));
    assert!(!gm.contains(&AssumedStatistic::BiasRandomWalk));
}

/// Where the filter's Φ is not the truth's (a Gauss–Markov bias assumed with a quarter of its τ_b,
/// or assumed constant), the exact actual covariance runs on the joint (error, estimate): it
/// agrees with the variance of an epoch ensemble of 10 000 realizations at several fixes, within
/// 6 standard errors of a sample variance (√(2/(N − 1)) each). The negative control: the
/// recursion of the error alone with the truth's Φ, exact only when the filter's Φ is the same,
/// disagrees with the ensemble beyond that bound.
#[test]
fn the_actual_covariance_follows_a_filter_with_another_transition() {
    use accelcal::filter::ErrorStateModel;
    use accelcal::sensitivity::{AssumedStatistic, actual_covariance};
    let bound = 6.0 * (2.0_f64 / 9_999.0).sqrt();
    let mut worst_alone: f64 = 0.0;
    for filter in [Some(0.25), None] {
        let mut config = match filter {
            Some(f) => AssumedStatistic::BiasCorrelationTime.scaled(&gauss_markov(), f),
            None => gauss_markov(),
        };
        if filter.is_none() {
            config.filter.bias_model = Some(BiasModelKind::Constant);
        }
        let (model, schedule) = common::model_of(&config);
        let world = ErrorStateModel::new(model.timeline.dt_s, &model.truth_stats);
        assert_ne!(world.phi, schedule.model.phi);
        let actual = actual_covariance(&model.timeline, &schedule, &model.truth_stats);
        let run = Ensemble::new(&model, &schedule)
            .with_engine(Engine::Epoch)
            .run(|_| {});
        // The error alone, propagated with the truth's Φ (the recursion of a filter with it).
        let mut alone = Vec::new();
        let (mut p, mut j) = (world.p0, 0);
        for (&jf, fix) in model.timeline.fix_steps.iter().zip(&schedule.fixes) {
            while j < jf {
                p = world.propagate(&p);
                j += 1;
            }
            let i_kh = accelcal::state::StateMatrix::identity() - fix.gain * world.h;
            p = i_kh * p * i_kh.transpose() + fix.gain * world.r * fix.gain.transpose();
            alone.push(p);
        }
        for i in [29, 74, 149] {
            let sample = &run.stats.fixes[i].post.ensemble_cov;
            for k in 0..3 {
                let ratio = sample[k][k] / actual[i].post[(k, k)];
                assert!(
                    (ratio - 1.0).abs() < bound,
                    "{filter:?}, fix {i}, state {k}: {ratio}"
                );
                worst_alone = worst_alone.max((sample[k][k] / alone[i][(k, k)] - 1.0).abs());
            }
        }
    }
    assert!(
        worst_alone > bound,
        "the error alone is off by only {worst_alone}"
    );
}
