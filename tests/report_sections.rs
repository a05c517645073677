//! The report is built from its outline and its checks from the catalogue: moving a section
//! renumbers every table, figure and equation and the contents follow, and a check added to the
//! catalogue shows up in every table and count of the page.

use accelcal::checks::{
    self, Budget, CATALOGUE, Check, CheckId, Definition, FailureWords, MemberId, Null,
};
use accelcal::config::Config;
use accelcal::ensemble::Statistics;
use accelcal::filter::Stage;
use accelcal::model::Model;
use accelcal::report::outline::{Node, Outline, Section};
use accelcal::report::page::{ReportView, SectionView};
use accelcal::report::{self, Page, ReportInput};
use accelcal::study::{Silent, Study};

/// A small study without the sensitivity section, run once.
fn study() -> &'static Study {
    static STUDY: std::sync::OnceLock<Study> = std::sync::OnceLock::new();
    STUDY.get_or_init(|| {
        let mut c = Config::default();
        c.profile.duration_s = 6.0;
        c.ensemble.realizations = 400;
        Study::run(&Model::new(&c).unwrap(), &mut Silent).unwrap()
    })
}

fn input(study: &Study) -> ReportInput<'_> {
    ReportInput {
        study,
        command: "accelcal report",
        threads: 1,
        static_noise: None,
    }
}

fn render(study: &Study, outline: &Outline) -> Page {
    report::render_outline(&input(study), outline).unwrap()
}

/// The numbers following `marker` in `html`, in the order the page shows them.
fn numbers_after(html: &str, marker: &str) -> Vec<usize> {
    html.match_indices(marker)
        .map(|(i, _)| {
            let rest = &html[i + marker.len()..];
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            digits.parse().unwrap()
        })
        .collect()
}

/// Tables, figures and equations are numbered 1, 2, 3, … in reading order.
fn assert_numbered_in_reading_order(html: &str) {
    for marker in [
        "<caption>Table ",
        "<span class=\"fignum\">Figure ",
        "<span class=\"eqno\">(",
    ] {
        let found = numbers_after(html, marker);
        let expected: Vec<usize> = (1..=found.len()).collect();
        assert!(!found.is_empty(), "no {marker}");
        assert_eq!(found, expected, "{marker} out of reading order");
    }
}

/// The contents name the top-level sections in the order the page shows them.
fn assert_contents_follow(page: &Page) {
    let html = &page.html;
    let main = &html[html.find("<main>").unwrap()..];
    let mut at = 0;
    for entry in &page.view.toc {
        let open = format!(
            "<section id=\"{}\">\n<h2>{}</h2>",
            entry.anchor, entry.title
        );
        let i = main[at..]
            .find(&open)
            .unwrap_or_else(|| panic!("{} not after the previous section", entry.anchor));
        at += i + open.len();
        assert!(html.contains(&format!(
            "<li><a href=\"#{}\">{}</a></li>",
            entry.anchor, entry.title
        )));
    }
    assert_eq!(main.matches("<section id=").count(), page.view.toc.len());
}

fn theory_eq(view: &ReportView) -> usize {
    view.sections
        .iter()
        .find_map(|n| match &n.view {
            SectionView::Theory(t) => Some(t.eqn.accelerometer),
            _ => None,
        })
        .unwrap()
}

fn case_tables(view: &ReportView) -> Vec<(String, usize)> {
    view.sections
        .iter()
        .flat_map(|n| &n.children)
        .filter_map(|n| match &n.view {
            SectionView::Case(c) => Some((c.letter.clone(), c.table_number)),
            _ => None,
        })
        .collect()
}

#[test]
fn moving_a_section_renumbers_the_page_and_the_contents_follow() {
    let study = study();
    let standard = report::outline_of(&input(study));
    let page = render(study, &standard);
    assert_numbered_in_reading_order(&page.html);
    assert_contents_follow(&page);
    // Problem (eqs. 1–2) comes before theory.
    assert_eq!(theory_eq(&page.view), 3);
    assert_eq!(case_tables(&page.view)[0], ("A".to_string(), 5));

    // Theory before the problem, the cases in reverse order.
    let mut moved = standard.clone();
    let theory = moved
        .nodes
        .iter()
        .position(|n| n.section == Section::Theory)
        .unwrap();
    let node = moved.nodes.remove(theory);
    moved.nodes.insert(2, node);
    let results = moved
        .nodes
        .iter_mut()
        .find(|n| n.section == Section::Results)
        .unwrap();
    let cases = study.cases.len();
    results.children[..cases].reverse();
    assert_ne!(moved, standard);
    let page = render(study, &moved);
    assert_numbered_in_reading_order(&page.html);
    assert_contents_follow(&page);
    assert_eq!(theory_eq(&page.view), 1);
    assert_eq!(page.view.toc[2].anchor, "theory");
    assert_eq!(page.view.toc[3].anchor, "problem");
    let tables = case_tables(&page.view);
    let last = ((b'A' + cases as u8 - 1) as char).to_string();
    assert_eq!(tables[0], (last, 5), "the last case now comes first");

    // A section of its own at the end: the case tables move behind the conclusions' numbers.
    let mut flat = standard.clone();
    let results = flat
        .nodes
        .iter_mut()
        .find(|n| n.section == Section::Results)
        .unwrap();
    let first_case = results.children.remove(0);
    flat.nodes.push(Node::leaf(first_case));
    let page = render(study, &flat);
    assert_numbered_in_reading_order(&page.html);
    let Some(SectionView::Case(a)) = page.view.sections.last().map(|n| &n.view) else {
        panic!("case A is the last section");
    };
    let others = case_tables(&page.view);
    assert_eq!(others.len(), cases - 1);
    assert!(others.iter().all(|(_, t)| *t < a.table_number));
    assert_eq!(
        page.view.toc.last().unwrap().anchor,
        format!("case-{}", a.id)
    );
    assert!(page.html.rfind("id=\"case-").unwrap() > page.html.find("id=\"appendix\"").unwrap());
}

/// A check registered only here: the a posteriori NEES of every fix, as its own check.
const POSTERIOR_NEES: Definition = Definition {
    id: CheckId::new("posterior_nees"),
    title: "a posteriori NEES",
    hypothesis: "the average a posteriori NEES is the state dimension",
    statistic: "(1/N) Σ e⁺ᵀP⁺⁻¹e⁺",
    members: "each fix, a posteriori",
    rationale: "Each realization's a posteriori eᵀP⁻¹e is χ²(3) for Gaussian errors.",
    formula: r"N \bar{\epsilon}^{+} \sim \chi^2(3N)",
    null: |n, dims| Null::ChiSquared {
        dof: dims.states as f64 * n,
        scale: n,
    },
    for_each_member: posterior_nees,
    failure: |c: &Check, w: &FailureWords| format!("{} fails at {}", c.id.name(), w.outside),
};

fn posterior_nees(stats: &dyn Statistics, f: &mut dyn FnMut(f64, MemberId)) {
    for i in 0..stats.fix_count() {
        let member = MemberId::Nees {
            fix: i as u32,
            stage: Stage::Posterior,
        };
        f(stats.stage(i, Stage::Posterior).nees_avg, member);
    }
}

#[test]
fn a_check_added_to_the_catalogue_shows_up_in_every_table_and_count() {
    let mut study = study().clone();
    let catalogue: Vec<&'static Definition> =
        CATALOGUE.iter().copied().chain([&POSTERIOR_NEES]).collect();
    let alpha = study.model.config.checks.false_alarm_rate;
    let budget = Budget::over(alpha, catalogue.len());
    for o in &mut study.cases {
        o.verdicts = checks::evaluate_with(&o.run.stats, &budget, &catalogue);
        assert!((o.verdicts.false_alarm_rate - alpha).abs() < 1e-15);
        assert_eq!(o.verdicts.checks.len(), CATALOGUE.len() + 1);
    }
    let page = render(&study, &report::outline_of(&input(&study)));
    let n = catalogue.len().to_string();
    let id = POSTERIOR_NEES.id;
    let mut seen = 0;
    for node in page
        .view
        .sections
        .iter()
        .flat_map(|n| std::iter::once(n).chain(&n.children))
    {
        match &node.view {
            SectionView::Abstract(a) => {
                assert_eq!(a.check_count, n);
                assert!(a.check_titles.ends_with("NIS and a posteriori NEES"));
                seen += 1;
            }
            SectionView::Theory(t) => {
                assert_eq!(t.check_count, n);
                assert!(t.catalogue.iter().any(|c| c.id == id.name()));
                seen += 1;
            }
            SectionView::Results(r) => {
                assert!(r.summary.iter().any(|row| row.id == id.name()));
                seen += 1;
            }
            SectionView::Case(c) => {
                assert_eq!(c.checks.len(), catalogue.len());
                assert!(c.checks.iter().any(|row| row.id == id.name()));
                assert!(c.passed_count.ends_with(&format!("of {n}")));
                seen += 1;
            }
            _ => {}
        }
    }
    assert_eq!(seen, 3 + study.cases.len());
    assert!(page.html.contains(&format!("with {n} statistical checks")));
    assert!(page.html.contains("<code>posterior_nees</code>"));
    // The registered catalogue itself is untouched.
    assert_eq!(CheckId::ALL.len(), CATALOGUE.len());
    assert!(CheckId::from_name("posterior_nees").is_none());
}
