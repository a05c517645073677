//! The kinds of the sections every report has (abstract, introduction, problem, theory, results,
//! the cases and the run times under the results, conclusions, appendix) and the sensitivity
//! section; their views are built in [`super::sections`].

use super::cases;
use super::figures;
use super::kind::{Built, Context, Place, Record, SectionKind, SectionView};
use super::outline::{CheckFigure, Equation, Figure, Label, Table};
use super::page::{AppendixView, IntroductionView};
use super::{RenderError, ReportInput, quantities, sensitivity};

/// A built view, boxed for the page.
fn boxed<V: SectionView>(v: V) -> Built {
    Some(Ok(Box::new(v)))
}

/// A view that may fail to draw its figures, boxed for the page.
fn drawn<V: SectionView>(v: Result<V, RenderError>) -> Built {
    Some(v.map(|v| Box::new(v) as Box<dyn SectionView>))
}

/// The abstract.
pub struct Abstract;

impl SectionKind for Abstract {
    fn key(&self) -> &'static str {
        "abstract"
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        boxed(ctx.abstract_view())
    }
}

/// The introduction.
pub struct Introduction;

impl SectionKind for Introduction {
    fn key(&self) -> &'static str {
        "introduction"
    }
    fn build(&self, _: &Context, _: usize) -> Built {
        boxed(IntroductionView {})
    }
}

/// The problem and its parameters.
pub struct Problem;

impl SectionKind for Problem {
    fn key(&self) -> &'static str {
        "problem"
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Equation(Equation::Profile),
            Label::Equation(Equation::AnalyticTruth),
            Label::Table(Table::Params),
            Label::Figure(Figure::Trajectory),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        drawn(ctx.problem())
    }
}

/// Theory and algorithm.
pub struct Theory;

impl SectionKind for Theory {
    fn key(&self) -> &'static str {
        "theory"
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        [
            Equation::Accelerometer,
            Equation::IntervalMean,
            Equation::Integration,
            Equation::Gps,
            Equation::EulerTruth,
            Equation::Dynamics,
            Equation::Measurement,
            Equation::Lag,
            Equation::Prediction,
        ]
        .map(Label::Equation)
        .to_vec()
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        boxed(ctx.theory())
    }
}

/// Results and performance: the realization, the verdict summary, accuracy, prediction; the
/// cases and the run times are its subsections.
pub struct Results;

impl SectionKind for Results {
    fn key(&self) -> &'static str {
        super::outline::RESULTS
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Figure(Figure::Realization),
            Label::Table(Table::Summary),
            Label::Table(Table::Accuracy),
            Label::Figure(Figure::Accuracy),
            Label::Table(Table::Prediction),
            Label::Figure(Figure::MeanErrorCases),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        drawn(ctx.results())
    }
}

/// One case of the study: instance i is the i-th case.
pub struct Case;

impl SectionKind for Case {
    fn key(&self) -> &'static str {
        "case"
    }
    fn place(&self) -> Place {
        Place::Results
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        (0..input.study.cases.len()).collect()
    }
    fn labels(&self, i: usize) -> Vec<Label> {
        [Label::Table(Table::Checks(i)), Label::Table(Table::Pair(i))]
            .into_iter()
            .chain(CheckFigure::ALL.map(|f| Label::Figure(Figure::Check(i, f))))
            .collect()
    }
    fn build(&self, ctx: &Context, i: usize) -> Built {
        let study = ctx.study();
        let o = study.cases.get(i)?;
        let n = ctx.numbers;
        let tables = (n.table(Table::Checks(i)), n.table(Table::Pair(i)));
        let claimed = quantities::claimed_sigma(study);
        drawn(
            figures::check_figures(o, i, n)
                .map(|figures| cases::case_view(o, i, tables, figures, claimed)),
        )
    }
}

/// The run times of the ensembles.
pub struct Performance;

impl SectionKind for Performance {
    fn key(&self) -> &'static str {
        "performance"
    }
    fn place(&self) -> Place {
        Place::Results
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![Label::Table(Table::Performance)]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        boxed(ctx.performance())
    }
}

/// Sensitivity to the assumed statistics, when the study ran it.
pub struct Sensitivity;

impl SectionKind for Sensitivity {
    fn key(&self) -> &'static str {
        "sensitivity"
    }
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        input.study.sensitivity.iter().map(|_| 0).collect()
    }
    fn labels(&self, _: usize) -> Vec<Label> {
        vec![
            Label::Figure(Figure::Sensitivity),
            Label::Table(Table::Detection),
        ]
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        let s = ctx.study().sensitivity.as_ref()?;
        drawn(sensitivity::view(s, ctx.numbers))
    }
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let s = input.study.sensitivity.as_ref()?;
        Some((
            "sensitivity",
            Box::new(crate::export::sensitivity::record(s)),
        ))
    }
}

/// Conclusions.
pub struct Conclusions;

impl SectionKind for Conclusions {
    fn key(&self) -> &'static str {
        "conclusions"
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        boxed(ctx.conclusions())
    }
}

/// Configuration and reproduction.
pub struct Appendix;

impl SectionKind for Appendix {
    fn key(&self) -> &'static str {
        "appendix"
    }
    fn build(&self, ctx: &Context, _: usize) -> Built {
        boxed(AppendixView {
            command: ctx.input.command.to_string(),
            config_toml: ctx.study().model.config.to_toml_string(),
        })
    }
}
