//! The report's section "Noise statistics from a drive": it follows the drifting bias, shows the
//! study's counts and verdicts, and numbers its tables and figures with the rest of the page.

use accelcal::config::Config;
use accelcal::format::count;
use accelcal::model::Model;
use accelcal::report::outline::{Outline, Section};
use accelcal::report::page::SectionView;
use accelcal::report::{self, ReportInput};
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
    let n = page
        .view
        .sections
        .iter()
        .find_map(|s| match &s.view {
            SectionView::Noise(n) => Some(n),
            _ => None,
        })
        .expect("the section's view");
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
    let outline = Outline::standard(3, true, true)
        .with_drift()
        .with_noise(true);
    let sections: Vec<Section> = outline.sections().collect();
    let drift = sections.iter().position(|s| *s == Section::Drift).unwrap();
    assert_eq!(sections[drift + 1], Section::Noise(true));
    assert_eq!(sections[drift + 2], Section::Conclusions);
}
