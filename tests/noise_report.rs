//! The report's section "Noise statistics from a drive": it follows the drifting bias, shows the
//! study's counts and verdicts, and numbers its tables and figures with the rest of the page; its
//! sentences follow the numbers; the calibration page's part gives a bound, never a bare value,
//! for a statistic the drive does not determine.

use accelcal::config::Config;
use accelcal::format::{count, sig};
use accelcal::likelihood::Key;
use accelcal::model::Model;
use accelcal::report::noise::NoiseView;
use accelcal::report::noise::{coverage_words, estimate_html, estimate_words, white_noise_words};
use accelcal::report::{self, ReportInput};
use accelcal::study::identify::{self, WhiteNoiseDrives};
use accelcal::study::noise::{KeyCoverage, NoiseStudy};
use accelcal::study::{Silent, Study};

/// Drives of the small study: enough for every row, few enough to be quick.
const DRIVES: u64 = 24;

fn study() -> &'static Study {
    static STUDY: std::sync::OnceLock<Study> = std::sync::OnceLock::new();
    STUDY.get_or_init(|| {
        let mut c = Config::default();
        c.profile.duration_s = 6.0;
        c.ensemble.realizations = 400;
        Study::run(&Model::new(&c).unwrap(), &mut Silent)
            .unwrap()
            .with_noise(DRIVES, &mut Silent)
            .unwrap()
    })
}

/// The numbers following `marker` in `html`, in page order.
fn numbers_after(html: &str, marker: &str) -> Vec<usize> {
    html.match_indices(marker)
        .map(|(i, _)| {
            let digits: String = html[i + marker.len()..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            digits.parse().unwrap()
        })
        .collect()
}

#[test]
fn the_section_shows_the_study_s_numbers() {
    let study = study();
    let page = report::render(&ReportInput {
        study,
        command: "accelcal report",
        threads: 1,
        static_noise: None,
    })
    .unwrap();
    let toc: Vec<&str> = page.view.toc.iter().map(|t| t.anchor.as_str()).collect();
    let at = toc
        .iter()
        .position(|a| *a == "noise-estimate")
        .expect("in the contents");
    assert_eq!(toc[at + 1], "conclusions", "{toc:?}");
    let n = page.view.find::<NoiseView>().expect("the section's view");
    let noise = study.noise.as_ref().unwrap();
    assert_eq!(n.drives, count(DRIVES));
    assert_eq!(n.rows.len(), noise.coverage.len());
    for (row, c) in n.rows.iter().zip(&noise.coverage) {
        assert_eq!(row.key, c.key.name());
        assert_eq!(row.covered, count(c.covered));
        assert_eq!(row.identifiable, count(c.identifiable));
        assert_eq!(
            row.band,
            format!("[{}, {}]", count(c.band.0), count(c.band.1))
        );
        assert_eq!(row.verdict.to_string() == "pass", c.holds());
        assert_eq!(
            row.half_width_verdict.to_string() == "pass",
            c.half_width_holds()
        );
    }
    // The white noise: the default drive gives W a bound only, the vibrating car a value.
    let white = study.white_noise.as_ref().unwrap();
    assert_eq!(n.white_noise_rows.len(), 2);
    assert_eq!(
        n.white_noise_rows[0].identifiable_words,
        if white.quiet.w().identifiable {
            "identifiable"
        } else {
            "not identifiable"
        }
    );
    assert!(!white.quiet.w().identifiable && white.vibrating.w().identifiable);
    // The page holds what the view says, numbered in reading order with every other table and
    // figure.
    let html = &page.html;
    assert!(
        html.contains("<section id=\"noise-estimate\">\n<h2>Noise statistics from a drive</h2>")
    );
    assert!(html.contains(&format!("<caption>Table {}. Coverage", n.coverage_table)));
    let t = n.white_noise_table.unwrap();
    assert!(html.contains(&format!("<caption>Table {t}. The white-noise variance W")));
    for f in [&n.estimates, &n.profile] {
        assert!(html.contains(&format!(
            "<span class=\"fignum\">Figure {}.</span>",
            f.number
        )));
    }
    for marker in ["<caption>Table ", "<span class=\"fignum\">Figure "] {
        let found = numbers_after(html, marker);
        assert_eq!(found, (1..=found.len()).collect::<Vec<_>>(), "{marker}");
    }
    assert!(html.contains(&n.coverage_html));
    assert!(html.contains(&n.white_noise_html));
}

#[test]
fn the_section_comes_after_the_drifting_bias() {
    let keys: Vec<&str> = report::registry::SECTIONS.iter().map(|k| k.key()).collect();
    let drift = keys.iter().position(|k| *k == "drift").unwrap();
    assert_eq!(keys[drift + 1], "noise");
    let at = |key: &str| keys.iter().position(|k| *k == key).unwrap();
    assert!(at("noise") < at("conclusions"), "{keys:?}");
}

/// The two drives of the default configuration, run once.
fn drives() -> &'static WhiteNoiseDrives {
    static D: std::sync::OnceLock<WhiteNoiseDrives> = std::sync::OnceLock::new();
    D.get_or_init(|| {
        identify::run(&Config::default())
            .unwrap()
            .expect("both drives can be made")
    })
}

fn coverage(covered: u64, half: u64) -> KeyCoverage {
    KeyCoverage {
        key: Key::GpsVelocity,
        truth: 0.04,
        identifiable: 200,
        covered,
        band: (181, 197),
        half_width_covered: half,
        median_ratio: 1.0,
    }
}

fn noise_study(c: KeyCoverage) -> NoiseStudy {
    NoiseStudy {
        drives: 200,
        duration_s: 120.0,
        config: Config::default(),
        estimates: Vec::new(),
        coverage: vec![c],
    }
}

#[test]
fn the_coverage_sentence_follows_the_counts() {
    let good = coverage_words(&noise_study(coverage(190, 130)));
    assert!(good.contains("as often as their confidence says"), "{good}");
    assert!(
        good.contains("the test sees an interval of the wrong width"),
        "{good}"
    );
    assert!(!good.contains("too rarely"), "{good}");
    let low = coverage_words(&noise_study(coverage(170, 130)));
    assert!(
        low.contains("cover the truth too rarely: 170 of 200"),
        "{low}"
    );
    assert!(!low.contains("as often as"), "{low}");
    let high = coverage_words(&noise_study(coverage(199, 130)));
    assert!(high.contains("too often"), "{high}");
    // The negative control inside the band: the test could not see a wrong width.
    let blind = coverage_words(&noise_study(coverage(190, 185)));
    assert!(blind.contains("cannot tell a wrong width"), "{blind}");
    assert!(!blind.contains("sees an interval"), "{blind}");
    let mut few = coverage(150, 100);
    few.identifiable = 160;
    let few = coverage_words(&noise_study(few));
    assert!(
        few.contains("identifiable on 160 of 200 drives only"),
        "{few}"
    );
}

#[test]
fn the_white_noise_sentence_is_the_estimator_s_verdict() {
    let d = drives();
    // Measured: the default drive gives W only an upper bound, the vibrating car a value.
    assert!(!d.quiet.w().identifiable && d.vibrating.w().identifiable);
    let words = white_noise_words(d);
    let upper = sig(d.quiet.w().upper.unwrap(), 3);
    assert!(
        words.contains(&format!(
            "not identifiable: only an upper bound, W ≤ {upper}"
        )),
        "{words}"
    );
    assert!(words.contains("W is identified: "), "{words}");
    assert!(words.contains("depends on the drive"), "{words}");
    // The same sentence with the verdicts swapped.
    let swapped = WhiteNoiseDrives {
        quiet: d.vibrating.clone(),
        vibrating: d.quiet.clone(),
    };
    let words = white_noise_words(&swapped);
    assert!(words.contains("the vibrating one does not"), "{words}");
    // A value is never given bare for a statistic the drive does not determine.
    let w = d.quiet.w();
    assert!(!estimate_words(w).contains(&sig(w.value, 3)));
    let mut lower_only = w.clone();
    (lower_only.lower, lower_only.upper) = (1e-4, None);
    let words = estimate_words(&lower_only);
    assert!(
        words.contains(&format!("only a lower bound, W ≥ {}", sig(1e-4, 3))),
        "{words}"
    );
}

#[test]
fn the_calibration_part_shows_bounds_for_what_is_not_identifiable() {
    let d = drives();
    let html = estimate_html(&d.quiet.estimate, 5).unwrap();
    let table = &html[..html.find("<figure").expect("the profile figure")];
    let w = d.quiet.w();
    assert!(
        table.contains("not identifiable: only an upper bound"),
        "{table}"
    );
    assert!(!table.contains(&sig(w.value, 3)), "{table}");
    assert!(table.contains(&format!("[0, {}]", sig(w.upper.unwrap(), 3))));
    // The identifiable σ's show their values and intervals.
    let p = &d.quiet.estimate.keys[0];
    assert!(p.identifiable);
    assert!(table.contains(&estimate_words(p)), "{table}");
    assert!(html.contains("Figure 5."));
    assert_eq!(html.matches("<svg").count(), 1);
}
