//! Every figure on a small study: well-formed SVG, the expected axis titles, no non-finite
//! numbers, and the same bytes on a second run.

use std::sync::OnceLock;

use super::*;
use crate::checks::Check;
use crate::config::{Config, TruthModel};
use crate::model::Model;
use crate::study::Study;

fn small_study() -> &'static Study {
    static STUDY: OnceLock<Study> = OnceLock::new();
    STUDY.get_or_init(|| {
        let mut c = Config::default();
        c.profile.duration_s = 4.0;
        c.ensemble.realizations = 200;
        c.checks.residual_pair_s = Some([1.0, 3.0]);
        Study::run(&Model::new(&c).unwrap(), true).unwrap()
    })
}

fn check<'a>(study: &'a Study, id: &str) -> &'a Check {
    study.primary().verdicts.get(id).unwrap()
}

/// Every figure of `study`, by name.
fn figures(study: &Study) -> Vec<(&'static str, String)> {
    figures_of(study, study.model.truth)
}

/// Every figure of `study`, the ensemble figures drawn for truth model `truth`.
fn figures_of(study: &Study, truth: TruthModel) -> Vec<(&'static str, String)> {
    let p = study.ensemble(truth);
    let s = &p.run.stats;
    let v = &p.verdicts;
    let check = |_: &Study, id: &str| v.get(id).unwrap();
    vec![
        (
            "realization_errors",
            realization_errors(&study.realization).unwrap(),
        ),
        ("trajectory", trajectory(&study.realization).unwrap()),
        (
            "mean_error",
            mean_error(s, check(study, "mean_error")).unwrap(),
        ),
        (
            "covariance",
            covariance(s, check(study, "covariance_match")).unwrap(),
        ),
        (
            "orthogonality",
            orthogonality(s, check(study, "orthogonality")).unwrap(),
        ),
        (
            "residual_whiteness",
            residual_whiteness(s, check(study, "residual_whiteness"), &v.residual_pair).unwrap(),
        ),
        (
            "consistency",
            consistency(s, check(study, "nees"), check(study, "nis")).unwrap(),
        ),
        (
            "truth_models",
            truth_models(
                &study.ensemble(TruthModel::Analytic).run.stats,
                &study.ensemble(TruthModel::Euler).run.stats,
            )
            .unwrap(),
        ),
    ]
}

/// The text of every `<text>` element of `svg`, which must parse as XML.
fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

#[test]
fn every_figure_is_well_formed_and_labelled() {
    let expected: [(&str, &[&str]); 8] = [
        (
            "realization_errors",
            &[
                "time (s)",
                "position error (",
                "velocity error (",
                "bias σ (",
            ],
        ),
        (
            "trajectory",
            &["time (s)", "acceleration (m/s²)", "position (m)"],
        ),
        ("mean_error", &["time (s)", "e_ave ("]),
        ("covariance", &["time (s)", "variance (m²)", "P_ave / P"]),
        ("orthogonality", &["time (s)", "√N · correlation"]),
        ("residual_whiteness", &["t_m (s)", "t_i (s)"]),
        ("consistency", &["time (s)", "average NEES", "average NIS"]),
        ("truth_models", &["time (s)", "e_ave / σ"]),
    ];
    let figs = figures(small_study());
    for ((name, svg), (expected_name, labels)) in figs.iter().zip(expected) {
        assert_eq!(*name, expected_name);
        let texts = texts(svg);
        for label in labels {
            // A label ending in "(" stands for any unit that follows, which may carry a power of
            // ten chosen from the data.
            let found = texts
                .iter()
                .any(|t| t == label || (label.ends_with('(') && t.starts_with(label)));
            assert!(found, "{name}: no text {label:?} among {texts:?}");
        }
        assert!(!svg.contains("NaN"), "{name} holds NaN");
        assert!(!svg.contains("inf"), "{name} holds inf");
    }
}

#[test]
fn figures_are_deterministic() {
    let study = small_study();
    assert_eq!(figures(study), figures(study));
}

#[test]
fn non_finite_statistics_are_skipped() {
    let study = small_study();
    let mut stats = study.primary().run.stats.clone();
    stats.fixes[1].post.mean_error[0] = f64::NAN;
    stats.fixes[2].post.ensemble_cov[1][1] = f64::INFINITY;
    stats.fixes[3].prior.orthogonality_corr[2][0] = f64::NAN;
    stats.fixes[4].nis_avg = f64::NAN;
    let c = check(study, "mean_error");
    for svg in [
        mean_error(&stats, c).unwrap(),
        covariance(&stats, c).unwrap(),
        orthogonality(&stats, c).unwrap(),
        consistency(&stats, c, c).unwrap(),
        truth_models(&stats, &stats).unwrap(),
    ] {
        texts(&svg);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}

#[test]
fn figures_survive_statistics_that_are_all_undefined() {
    let study = small_study();
    let mut stats = study.primary().run.stats.clone();
    for f in &mut stats.fixes {
        for s in [&mut f.prior, &mut f.post] {
            s.mean_error = [f64::NAN; 3];
            s.ensemble_cov = [[f64::NAN; 3]; 3];
            s.filter_cov = [[f64::INFINITY; 3]; 3];
            s.orthogonality_corr = [[f64::NAN; 3]; 3];
            s.nees_avg = f64::NAN;
        }
        f.nis_avg = f64::NAN;
    }
    stats.residual_corr.iter_mut().for_each(|x| *x = f64::NAN);
    let mut r = study.realization.clone();
    for s in &mut r.samples {
        s.sigma = [f64::NAN; 3];
        s.estimate = [f64::INFINITY; 3];
    }
    let c = check(study, "mean_error");
    let mut pair = study.primary().verdicts.residual_pair.clone();
    pair.z = [[f64::NAN; 2]; 2];
    for svg in [
        realization_errors(&r).unwrap(),
        trajectory(&r).unwrap(),
        mean_error(&stats, c).unwrap(),
        covariance(&stats, c).unwrap(),
        orthogonality(&stats, c).unwrap(),
        residual_whiteness(&stats, c, &pair).unwrap(),
        consistency(&stats, c, c).unwrap(),
        truth_models(&stats, &stats).unwrap(),
    ] {
        texts(&svg);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}

/// Writes every figure of the default configuration to /tmp/figs for a look:
/// `cargo test --release --lib plot::tests::render_default_figures -- --ignored`.
#[test]
#[ignore = "runs the full default study (seconds in release, minutes in debug)"]
fn render_default_figures() {
    let study = Study::run(&Model::new(&Config::default()).unwrap(), true).unwrap();
    let dir = std::path::Path::new("/tmp/figs");
    std::fs::create_dir_all(dir).unwrap();
    let small = small_study();
    for (suffix, study, truth) in [
        ("", &study, TruthModel::Analytic),
        ("_euler", &study, TruthModel::Euler),
        ("_small", small, TruthModel::Analytic),
    ] {
        for (name, svg) in figures_of(study, truth) {
            texts(&svg);
            std::fs::write(dir.join(format!("{name}{suffix}.svg")), &svg).unwrap();
            println!("{name}{suffix}: {:.0} KB", svg.len() as f64 / 1024.0);
        }
    }
}
