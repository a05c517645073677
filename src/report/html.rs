//! The templates of the report: one per section, and the page that places them in the order of
//! the outline. Each section renders to a complete HTML fragment.

use askama::Template;

use super::equations::Equations;
use super::page::{
    AbstractView, AppendixView, ConclusionsView, PerformanceView, ProblemView, ReportView,
    ResultsView, SectionNode, SectionView, TheoryView,
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
struct IntroductionHtml;

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
#[template(path = "sections/allan.html")]
struct StaticNoiseHtml<'a> {
    a: &'a crate::allan::section::AllanSection,
}

#[derive(Template)]
#[template(path = "sections/drift.html")]
struct DriftHtml<'a> {
    d: &'a super::drift::DriftView,
}

#[derive(Template)]
#[template(path = "sections/real_drive.html")]
struct RealDriveHtml<'a> {
    d: &'a super::real_drive::RealDriveView,
}

#[derive(Template)]
#[template(path = "sections/noise.html")]
struct NoiseHtml<'a> {
    n: &'a super::noise::NoiseView,
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
    let children_html = children.as_slice();
    let own = match &node.view {
        SectionView::Abstract(v) => AbstractHtml { v }.render(),
        SectionView::Introduction(_) => IntroductionHtml.render(),
        SectionView::Problem(v) => ProblemHtml { v, eq }.render(),
        SectionView::Theory(v) => TheoryHtml { v, eq }.render(),
        SectionView::Results(v) => ResultsHtml { v, children_html }.render(),
        SectionView::Case(c) => CaseHtml { c }.render(),
        SectionView::Performance(v) => PerformanceHtml { v }.render(),
        SectionView::Sensitivity(s) => SensitivityHtml { s }.render(),
        SectionView::StaticNoise(a) => StaticNoiseHtml { a }.render(),
        SectionView::Drift(d) => DriftHtml { d }.render(),
        SectionView::RealDrive(d) => RealDriveHtml { d }.render(),
        SectionView::Noise(n) => NoiseHtml { n }.render(),
        SectionView::Conclusions(v) => ConclusionsHtml { v }.render(),
        SectionView::Appendix(v) => AppendixHtml { v }.render(),
    }?;
    // The results place their subsections; any other section is followed by its own.
    Ok(match node.view {
        SectionView::Results(_) => own,
        _ => [own]
            .into_iter()
            .chain(children)
            .collect::<Vec<_>>()
            .join("\n"),
    })
}
