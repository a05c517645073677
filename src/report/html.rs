//! The templates of the report: one per section, and the page that places them in the order of
//! the outline. Each section renders to a complete HTML fragment.

use askama::Template;

use super::equations::Equations;
use super::page::{
    AbstractView, AppendixView, ConclusionsView, IntroductionView, PerformanceView, ProblemView,
    ReportView, ResultsView, SectionNode, TheoryView,
};
use super::view::{CaseView, SensitivityView};

/// The report page.
#[derive(Template)]
#[template(path = "report.html")]
pub struct ReportPage<'a> {
    /// The view.
    pub v: &'a ReportView,
    /// The sections, rendered, in outline order.
    pub sections_html: &'a [String],
    /// The stylesheet.
    pub style: &'a str,
}

#[derive(Template)]
#[template(path = "sections/abstract.html")]
struct AbstractHtml<'a> {
    v: &'a AbstractView,
}

#[derive(Template)]
#[template(path = "sections/introduction.html")]
struct IntroductionHtml<'a> {
    #[allow(dead_code)]
    v: &'a IntroductionView,
}

#[derive(Template)]
#[template(path = "sections/problem.html")]
struct ProblemHtml<'a> {
    v: &'a ProblemView,
    eq: &'a Equations,
}

#[derive(Template)]
#[template(path = "sections/theory.html")]
struct TheoryHtml<'a> {
    v: &'a TheoryView,
    eq: &'a Equations,
}

#[derive(Template)]
#[template(path = "sections/results.html")]
struct ResultsHtml<'a> {
    v: &'a ResultsView,
    children_html: &'a [String],
}

#[derive(Template)]
#[template(path = "sections/case.html")]
struct CaseHtml<'a> {
    c: &'a CaseView,
}

#[derive(Template)]
#[template(path = "sections/performance.html")]
struct PerformanceHtml<'a> {
    v: &'a PerformanceView,
}

#[derive(Template)]
#[template(path = "sections/sensitivity.html")]
struct SensitivityHtml<'a> {
    s: &'a SensitivityView,
}

#[derive(Template)]
#[template(path = "sections/conclusions.html")]
struct ConclusionsHtml<'a> {
    v: &'a ConclusionsView,
}

#[derive(Template)]
#[template(path = "sections/appendix.html")]
struct AppendixHtml<'a> {
    v: &'a AppendixView,
}

/// Renders `node` and its subsections with the equations `eq`.
///
/// # Errors
/// [`askama::Error`] when a template cannot be filled.
pub fn section(node: &SectionNode, eq: &Equations) -> Result<String, askama::Error> {
    let children: Vec<String> = node
        .children
        .iter()
        .map(|c| section(c, eq))
        .collect::<Result<_, _>>()?;
    let own = node.view.html(eq, &children)?;
    // The results place their subsections; any other section is followed by its own.
    Ok(if node.view.places_children() {
        own
    } else {
        [own]
            .into_iter()
            .chain(children)
            .collect::<Vec<_>>()
            .join("\n")
    })
}

crate::section_view!(AbstractView, AbstractHtml { v }, anchor: |_| "abstract".to_string(), title: |_| "Abstract".to_string());
crate::section_view!(IntroductionView, IntroductionHtml { v }, anchor: |_| "introduction".to_string(), title: |_| "Introduction".to_string());
crate::section_view!(ProblemView, ProblemHtml { v, eq }, anchor: |_| "problem".to_string(), title: |_| "The problem and its parameters".to_string());
crate::section_view!(TheoryView, TheoryHtml { v, eq }, anchor: |_| "theory".to_string(), title: |_| "Theory and algorithm".to_string());
crate::section_view!(ResultsView, ResultsHtml { v, children }, anchor: |_| "results".to_string(), title: |_| "Results and performance".to_string(), places_children: true);
crate::section_view!(CaseView, CaseHtml { c }, anchor: |c| format!("case-{}", c.id), title: |c| format!("Case {}: {}", c.letter, c.title));
crate::section_view!(PerformanceView, PerformanceHtml { v }, anchor: |_| "performance".to_string(), title: |_| "Performance".to_string());
crate::section_view!(SensitivityView, SensitivityHtml { s }, anchor: |_| "sensitivity".to_string(), title: |_| "Sensitivity to the assumed statistics".to_string());
crate::section_view!(ConclusionsView, ConclusionsHtml { v }, anchor: |_| "conclusions".to_string(), title: |_| "Conclusions".to_string());
crate::section_view!(AppendixView, AppendixHtml { v }, anchor: |_| "appendix".to_string(), title: |_| "Appendix: configuration and reproduction".to_string());
