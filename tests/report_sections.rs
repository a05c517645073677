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
use accelcal::report::kind::{Built, Context, JsonRecord, Record, SectionKind};
use accelcal::report::outline::{Equation, Figure, Label, Node, Outline, Table};
use accelcal::report::page::{AbstractView, ReportView, ResultsView, TheoryView};
use accelcal::report::registry::SECTIONS;
use accelcal::report::view::CaseView;
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
    view.find::<TheoryView>().unwrap().eqn.accelerometer
}

fn case_tables(view: &ReportView) -> Vec<(String, usize)> {
    view.sections
        .iter()
        .flat_map(|n| &n.children)
        .filter_map(|n| n.get::<CaseView>())
        .map(|c| (c.letter.clone(), c.table_number))
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
        .position(|n| n.section.key() == "theory")
        .unwrap();
    let node = moved.nodes.remove(theory);
    moved.nodes.insert(2, node);
    let results = moved
        .nodes
        .iter_mut()
        .find(|n| n.section.key() == "results")
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
        .find(|n| n.section.key() == "results")
        .unwrap();
    let first_case = results.children.remove(0);
    flat.nodes.push(Node::leaf(first_case));
    let page = render(study, &flat);
    assert_numbered_in_reading_order(&page.html);
    let Some(a) = page.view.sections.last().and_then(|n| n.get::<CaseView>()) else {
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
    for node in page.view.all() {
        if let Some(a) = node.get::<AbstractView>() {
            assert_eq!(a.check_count, n);
            assert!(a.check_titles.ends_with("NIS and a posteriori NEES"));
            seen += 1;
        }
        if let Some(t) = node.get::<TheoryView>() {
            assert_eq!(t.check_count, n);
            assert!(t.catalogue.iter().any(|c| c.id == id.name()));
            seen += 1;
        }
        if let Some(r) = node.get::<ResultsView>() {
            assert!(r.summary.iter().any(|row| row.id == id.name()));
            seen += 1;
        }
        if let Some(c) = node.get::<CaseView>() {
            assert_eq!(c.checks.len(), catalogue.len());
            assert!(c.checks.iter().any(|row| row.id == id.name()));
            assert!(c.passed_count.ends_with(&format!("of {n}")));
            seen += 1;
        }
    }
    assert_eq!(seen, 3 + study.cases.len());
    assert!(page.html.contains(&format!("with {n} statistical checks")));
    assert!(page.html.contains("<code>posterior_nees</code>"));
    // The registered catalogue itself is untouched.
    assert_eq!(CheckId::ALL.len(), CATALOGUE.len());
    assert!(CheckId::from_name("posterior_nees").is_none());
}

/// A section defined only here, in the one file a section takes (its kind, its view, its
/// template) plus its line in a list of sections: a table, a figure and an equation of its own, a
/// record in data.json, shown when `shown`.
struct Margin {
    shown: bool,
}

/// The throwaway section's view.
#[derive(Debug, serde::Serialize)]
struct MarginView {
    table: usize,
    figure: usize,
    equation: usize,
    cases: String,
}

/// Its record in data.json.
#[derive(serde::Serialize)]
struct MarginRecord {
    cases: usize,
    note: &'static str,
}

const MARGIN_TABLE: Table = Table::Named("margin");
const MARGIN_FIGURE: Figure = Figure::Named("margin");
const MARGIN_EQUATION: Equation = Equation::Named("margin");

impl SectionKind for Margin {
    fn key(&self) -> &'static str {
        "margin"
    }
    fn instances(&self, _: &ReportInput) -> Vec<usize> {
        if self.shown { vec![0] } else { Vec::new() }
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Table(MARGIN_TABLE),
            Label::Figure(MARGIN_FIGURE),
            Label::Equation(MARGIN_EQUATION),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        if !self.shown {
            return None;
        }
        let n = ctx.numbers;
        Some(Ok(Box::new(MarginView {
            table: n.table(MARGIN_TABLE),
            figure: n.figure(MARGIN_FIGURE),
            equation: n.equation(MARGIN_EQUATION),
            cases: ctx.study().cases.len().to_string(),
        })))
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        self.shown.then(|| {
            let record = MarginRecord {
                cases: input.study.cases.len(),
                note: "a throwaway section",
            };
            ("margin", Box::new(record) as Box<dyn JsonRecord>)
        })
    }
}

#[derive(askama::Template)]
#[template(
    ext = "html",
    source = "<section id=\"margin\">\n<h2>A margin</h2>\n<p>{{ m.cases }} cases.</p>\n<div class=\"eq\"><span class=\"eqno\">({{ m.equation }})</span></div>\n<figure><figcaption><span class=\"fignum\">Figure {{ m.figure }}.</span> A margin.</figcaption></figure>\n<table><caption>Table {{ m.table }}. A margin.</caption></table>\n</section>"
)]
struct MarginHtml<'a> {
    m: &'a MarginView,
}

accelcal::section_view!(MarginView, MarginHtml { m }, anchor: |_| "margin".to_string(), title: |_| "A margin".to_string());

static SHOWN: Margin = Margin { shown: true };
static HIDDEN: Margin = Margin { shown: false };

/// The registry with `margin` right after the theory.
fn with_margin(margin: &'static Margin) -> Vec<&'static dyn SectionKind> {
    let mut kinds = SECTIONS.to_vec();
    let theory = kinds.iter().position(|k| k.key() == "theory").unwrap();
    kinds.insert(theory + 1, margin);
    kinds
}

#[test]
fn a_section_added_to_the_registry_appears_everywhere_it_should() {
    let study = study();
    let input = input(study);
    let standard = render(study, &report::outline_of(&input));
    let kinds = with_margin(&SHOWN);
    let outline = Outline::of(&input, &kinds);

    // The outline: right after the theory, at the top level.
    let keys: Vec<&str> = outline.nodes.iter().map(|n| n.section.key()).collect();
    let theory = keys.iter().position(|k| *k == "theory").unwrap();
    assert_eq!(keys[theory + 1], "margin", "{keys:?}");

    // The page: its section and its contents entry in reading order, every number in order.
    let page = render(study, &outline);
    assert_numbered_in_reading_order(&page.html);
    assert_contents_follow(&page);
    assert_eq!(page.view.toc[theory + 1].anchor, "margin");
    assert!(
        page.html
            .contains("<li><a href=\"#margin\">A margin</a></li>")
    );
    assert!(
        page.html
            .contains(&format!("<p>{} cases.</p>", study.cases.len()))
    );

    // Its numbers follow the problem's and the theory's, and everything after moves on by one.
    let m = page.view.find::<MarginView>().expect("the margin's view");
    assert_eq!(
        (m.table, m.figure),
        (2, 2),
        "after the problem's table 1 and figure 1"
    );
    assert_eq!(
        m.equation,
        theory_eq(&page.view) + 9,
        "after the theory's nine"
    );
    let (before, after) = (case_tables(&standard.view), case_tables(&page.view));
    assert_eq!(before.len(), after.len());
    for ((a, t0), (b, t1)) in before.iter().zip(&after) {
        assert_eq!((a, t0 + 1), (b, *t1));
    }
    let figures = |html: &str| numbers_after(html, "<span class=\"fignum\">Figure ").len();
    assert_eq!(figures(&page.html), figures(&standard.html) + 1);

    // view.json holds its view; data.json its record, after the study's own fields.
    assert!(page.view_json.contains("\"section\": \"margin\""));
    let view: serde_json::Value = serde_json::from_str(&page.view_json).unwrap();
    let shown = &view["sections"][theory + 1];
    assert_eq!(shown["section"], "margin");
    assert_eq!(shown["table"], 2);
    let text = report::data_json_of(&input, &kinds);
    let data: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(data["margin"]["cases"], study.cases.len());
    assert_eq!(data["margin"]["note"], "a throwaway section");
    assert!(text.find("\"ensembles\"").unwrap() < text.find("\"margin\"").unwrap());
    let plain: serde_json::Value = serde_json::from_str(&report::data_json(&input)).unwrap();
    assert!(plain.get("margin").is_none());
    let mut without = data.clone();
    without.as_object_mut().unwrap().remove("margin");
    assert_eq!(without, plain, "nothing else in data.json changes");

    // Optional: a study without its value shows it nowhere, and nothing else changes.
    let hidden = with_margin(&HIDDEN);
    let outline = Outline::of(&input, &hidden);
    assert_eq!(outline, report::outline_of(&input));
    let page = render(study, &outline);
    assert!(!page.html.contains("id=\"margin\"") && !page.html.contains("#margin"));
    assert_eq!(page.html, standard.html);
    assert_eq!(page.view_json, standard.view_json);
    assert_eq!(
        report::data_json_of(&input, &hidden),
        report::data_json(&input)
    );
}
