//! Every figure on a small study: well-formed SVG, the expected axis titles, no non-finite
//! numbers, and the same bytes on a second run.

use std::sync::OnceLock;

use super::*;
use crate::checks::{Check, CheckId};
use crate::config::{Case, Config};
use crate::ensemble::EnsembleStats;
use crate::model::Model;
use crate::state::ErrorState;
use crate::study::Study;

mod presentation;

fn small_study() -> &'static Study {
    static STUDY: OnceLock<Study> = OnceLock::new();
    STUDY.get_or_init(|| {
        let mut c = Config::default();
        c.profile.duration_s = 4.0;
        c.ensemble.realizations = 200;
        c.checks.residual_pair_s = Some([1.0, 3.0]);
        Study::run(&Model::new(&c).unwrap(), &mut crate::study::Silent).unwrap()
    })
}

/// The point-sample case of the closed-form truth: the one with a mean error to draw.
const CASE: Case = Case::POINT_SAMPLES;

fn check(study: &Study, id: CheckId) -> &Check {
    study.case(CASE).verdicts.get(id)
}

/// The cases of `study` as the cross-case figures take them.
fn series(study: &Study) -> Vec<CaseSeries<'_>> {
    study
        .cases
        .iter()
        .map(|o| CaseSeries {
            label: o.case.to_string().replace('_', " "),
            stats: &o.run.stats,
            achieved_rms: &o.achieved_rms,
        })
        .collect()
}

/// Every figure of `study`, by name.
fn figures(study: &Study) -> Vec<(&'static str, String)> {
    figures_of(study, CASE)
}

/// Every figure of `study`, the ensemble figures drawn for `case`.
fn figures_of(study: &Study, case: Case) -> Vec<(&'static str, String)> {
    let p = study.case(case);
    let s = &p.run.stats;
    let v = &p.verdicts;
    let mut out = vec![
        (
            "realization_errors",
            realization_errors(&study.realization).unwrap(),
        ),
        ("trajectory", trajectory(&study.realization).unwrap()),
    ];
    // Every figure of a check; a check without a figure of its own is in the verdict tables only.
    for id in CheckId::ALL {
        let figure = match id {
            CheckId::MEAN_ERROR => ("mean_error", mean_error(s, v.get(id), &p.prediction.fixes)),
            CheckId::COVARIANCE_MATCH => ("covariance", covariance(s, v.get(id))),
            CheckId::COVARIANCE_CORRELATION => continue, // drawn by the covariance figure
            CheckId::ORTHOGONALITY => ("orthogonality", orthogonality(s, v.get(id))),
            CheckId::RESIDUAL_WHITENESS => (
                "residual_whiteness",
                residual_whiteness(s, v.get(id), &v.residual_pair),
            ),
            CheckId::NEES => (
                "consistency",
                consistency(s, v.get(id), v.get(CheckId::NIS)),
            ),
            CheckId::NIS => continue, // drawn with NEES
            _ => continue,
        };
        out.push((figure.0, figure.1.unwrap()));
    }
    let cases = series(study);
    out.push(("accuracy_ratio", accuracy_ratio(&cases).unwrap()));
    out.push((
        "mean_error_in_sigma",
        mean_error_in_sigma(&cases, 4.5).unwrap(),
    ));
    out
}

/// The text of every `<text>` element of `svg` (its `<tspan>`s included), which must parse as
/// XML.
fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| {
            n.descendants()
                .filter_map(|d| d.text().filter(|_| d.is_text()))
                .collect::<String>()
                .trim()
                .to_string()
        })
        .collect()
}

#[test]
fn every_figure_is_well_formed_and_labelled() {
    let expected: [(&str, &[&str]); 9] = [
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
        ("mean_error", &["time (s)", "eave ("]),
        ("covariance", &["time (s)", "variance (m²)", "Pave / P"]),
        ("orthogonality", &["time (s)", "√N · correlation"]),
        ("residual_whiteness", &["tm (s)", "ti (s)"]),
        ("consistency", &["time (s)", "average NEES", "average NIS"]),
        ("accuracy_ratio", &["time (s)", "RMS error / σ"]),
        ("mean_error_in_sigma", &["time (s)", "|mean error| / σ"]),
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
    let mut stats = study.case(CASE).run.stats.clone();
    stats.fixes[1].post.mean_error[ErrorState::POSITION] = f64::NAN;
    stats.fixes[2].post.ensemble_cov[ErrorState::VELOCITY][ErrorState::VELOCITY] = f64::INFINITY;
    stats.fixes[3].prior.orthogonality_corr[ErrorState::BIAS][ErrorState::POSITION] = f64::NAN;
    stats.fixes[4].nis_avg = f64::NAN;
    let c = check(study, CheckId::MEAN_ERROR);
    let prediction = vec![[[f64::NAN; ErrorState::DIM]; 2]; stats.fixes.len()];
    let rms = vec![[f64::NAN; ErrorState::DIM]; stats.fixes.len()];
    for svg in [
        mean_error(&stats, c, &prediction).unwrap(),
        covariance(&stats, c).unwrap(),
        orthogonality(&stats, c).unwrap(),
        consistency(&stats, c, c).unwrap(),
        accuracy_ratio(&undefined(&stats, &rms)).unwrap(),
        mean_error_in_sigma(&undefined(&stats, &rms), 4.5).unwrap(),
    ] {
        texts(&svg);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}

#[test]
fn figures_survive_statistics_that_are_all_undefined() {
    let study = small_study();
    let mut stats = study.case(CASE).run.stats.clone();
    for f in &mut stats.fixes {
        for s in [&mut f.prior, &mut f.post] {
            s.mean_error = [f64::NAN; ErrorState::DIM];
            s.ensemble_cov = [[f64::NAN; ErrorState::DIM]; ErrorState::DIM];
            s.filter_cov = [[f64::INFINITY; ErrorState::DIM]; ErrorState::DIM];
            s.orthogonality_corr = [[f64::NAN; ErrorState::DIM]; ErrorState::DIM];
            s.nees_avg = f64::NAN;
        }
        f.nis_avg = f64::NAN;
    }
    stats
        .residual_moments
        .iter_mut()
        .for_each(|x| *x = f64::NAN);
    let mut r = study.realization.clone();
    for s in &mut r.samples {
        s.sigma = [f64::NAN; ErrorState::DIM];
        s.estimate = [f64::INFINITY; ErrorState::DIM];
    }
    let c = check(study, CheckId::MEAN_ERROR);
    let mut pair = study.case(CASE).verdicts.residual_pair.clone();
    pair.z = vec![vec![f64::NAN; ErrorState::MEAS]; ErrorState::MEAS];
    let prediction = vec![[[f64::INFINITY; ErrorState::DIM]; 2]; stats.fixes.len()];
    let rms = vec![[f64::NAN; ErrorState::DIM]; stats.fixes.len()];
    for svg in [
        realization_errors(&r).unwrap(),
        trajectory(&r).unwrap(),
        mean_error(&stats, c, &prediction).unwrap(),
        covariance(&stats, c).unwrap(),
        orthogonality(&stats, c).unwrap(),
        residual_whiteness(&stats, c, &pair).unwrap(),
        consistency(&stats, c, c).unwrap(),
        accuracy_ratio(&undefined(&stats, &rms)).unwrap(),
        mean_error_in_sigma(&undefined(&stats, &rms), 4.5).unwrap(),
    ] {
        texts(&svg);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}

/// One case series of `stats` with achieved RMS errors `rms`.
fn undefined<'a>(
    stats: &'a EnsembleStats,
    rms: &'a [[f64; ErrorState::DIM]],
) -> Vec<CaseSeries<'a>> {
    vec![CaseSeries {
        label: "undefined".to_string(),
        stats,
        achieved_rms: rms,
    }]
}

/// Writes every figure of the default configuration to /tmp/figs for a look:
/// `cargo test --release --lib plot::tests::render_default_figures -- --ignored`.
#[test]
#[ignore = "runs the full default study (seconds in release, minutes in debug)"]
fn render_default_figures() {
    let study = Study::run(
        &Model::new(&Config::default()).unwrap(),
        &mut crate::study::Silent,
    )
    .unwrap();
    let dir = std::path::Path::new("/tmp/figs-wt");
    std::fs::create_dir_all(dir).unwrap();
    let small = small_study();
    for (suffix, study, case) in [
        ("", &study, Case::POINT_SAMPLES),
        ("_euler", &study, Case::MODEL_WORLD),
        ("_interval", &study, Case::INTERVAL_MEANS),
        ("_small", small, Case::POINT_SAMPLES),
    ] {
        for (name, svg) in figures_of(study, case) {
            texts(&svg);
            std::fs::write(dir.join(format!("{name}{suffix}.svg")), &svg).unwrap();
            println!("{name}{suffix}: {:.0} KB", svg.len() as f64 / 1024.0);
        }
    }
}
