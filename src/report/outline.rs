//! The report's outline: which sections the page shows, in which order, and what each one holds.
//! Table, figure and equation numbers and the table of contents are derived from it, so that a
//! section moved in the outline takes its numbers and its entry in the contents along.
//!
//! Numbers are handed out like labels in a typeset document: a first pass walks the outline in
//! reading order and numbers every table, figure and equation each section declares; the
//! sections are then built with every number known, so a section may cite one that a later
//! section holds.

use std::collections::HashMap;

use crate::checks::CheckId;

/// A section of the report page.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Section {
    /// The abstract.
    Abstract,
    /// The introduction.
    Introduction,
    /// The problem and its parameters.
    Problem,
    /// Theory and algorithm.
    Theory,
    /// Results and performance: the realization, the verdict summary, accuracy, prediction.
    Results,
    /// One case of the study, by its index.
    Case(usize),
    /// The run times of the ensembles.
    Performance,
    /// Sensitivity to the assumed statistics.
    Sensitivity,
    /// Noise statistics from a static log: the Allan deviation and its validation.
    StaticNoise,
    /// A drifting bias seen by a constant-bias and a random-walk filter.
    Drift,
    /// The shipped real drive calibrated with noise statistics estimated from it.
    RealDrive,
    /// Noise statistics from a drive: simulated drives through `--estimate-noise`; with the
    /// white noise's identifiability on two drives when `true`.
    Noise(bool),
    /// Conclusions.
    Conclusions,
    /// Configuration and reproduction.
    Appendix,
}

/// A numbered table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Table {
    /// The parameters of the run.
    Params,
    /// The verdicts of every check on every case.
    Summary,
    /// Achieved against claimed accuracy.
    Accuracy,
    /// The predicted mean error against the measured one.
    Prediction,
    /// The verdict table of a case.
    Checks(usize),
    /// The single residual pair of a case.
    Pair(usize),
    /// The run times.
    Performance,
    /// The detection of a mistuned filter.
    Detection,
    /// The noise terms recovered from a static log, then their coverage over many logs (two
    /// consecutive numbers).
    StaticNoise,
    /// The coverage of the noise terms' intervals.
    StaticNoiseCoverage,
    /// Two filters on a drifting bias: claims, errors and verdicts.
    Drift,
    /// The real drive's calibrations.
    RealDrive,
    /// The coverage of the noise estimate's intervals over simulated drives.
    NoiseCoverage,
    /// The white noise's identifiability on two drives.
    WhiteNoise,
}

/// A numbered figure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Figure {
    /// The acceleration profile and trajectory.
    Trajectory,
    /// The estimation error of one realization.
    Realization,
    /// Achieved accuracy over the filter's σ, every case.
    Accuracy,
    /// The mean error of every case in units of σ.
    MeanErrorCases,
    /// A check figure of a case.
    Check(usize, CheckFigure),
    /// Actual against claimed σ of the mistuned filters.
    Sensitivity,
    /// The Allan deviation of a static log.
    AllanDeviation,
    /// Claimed against achieved σ of two filters on a drifting bias.
    Drift,
    /// The real drive's bias, gravity-compensated axis.
    RealDriveGravityCompensated,
    /// The real drive's bias, raw axis with a random walk.
    RealDriveRaw,
    /// The noise estimates of simulated drives against the truth.
    NoiseEstimates,
    /// The likelihood profile of one drive.
    NoiseProfile,
}

/// A numbered display equation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Equation {
    /// The acceleration profile.
    Profile,
    /// The closed-form truth.
    AnalyticTruth,
    /// The accelerometer, point samples.
    Accelerometer,
    /// The accelerometer, interval means.
    IntervalMean,
    /// The accelerometer's Euler integration.
    Integration,
    /// The GPS.
    Gps,
    /// The truth integrated like the accelerometer.
    EulerTruth,
    /// The error dynamics.
    Dynamics,
    /// The measurement of the error state.
    Measurement,
    /// The velocity lag of point samples.
    Lag,
    /// The predicted mean error.
    Prediction,
}

/// Something a section numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Label {
    /// A table.
    Table(Table),
    /// A figure.
    Figure(Figure),
    /// An equation.
    Equation(Equation),
}

impl Section {
    /// What the section numbers, in the order its template shows them.
    pub fn labels(self) -> Vec<Label> {
        use Label::{Equation as E, Figure as F, Table as T};
        match self {
            Section::Abstract
            | Section::Introduction
            | Section::Conclusions
            | Section::Appendix => Vec::new(),
            Section::Problem => vec![
                E(Equation::Profile),
                E(Equation::AnalyticTruth),
                T(Table::Params),
                F(Figure::Trajectory),
            ],
            Section::Theory => [
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
            .map(E)
            .to_vec(),
            Section::Results => vec![
                F(Figure::Realization),
                T(Table::Summary),
                T(Table::Accuracy),
                F(Figure::Accuracy),
                T(Table::Prediction),
                F(Figure::MeanErrorCases),
            ],
            Section::Case(i) => [T(Table::Checks(i)), T(Table::Pair(i))]
                .into_iter()
                .chain(CheckFigure::ALL.map(|f| F(Figure::Check(i, f))))
                .collect(),
            Section::Performance => vec![T(Table::Performance)],
            Section::Sensitivity => vec![F(Figure::Sensitivity), T(Table::Detection)],
            Section::StaticNoise => vec![
                F(Figure::AllanDeviation),
                T(Table::StaticNoise),
                T(Table::StaticNoiseCoverage),
            ],
            Section::Drift => vec![F(Figure::Drift), T(Table::Drift)],
            Section::RealDrive => vec![
                T(Table::RealDrive),
                F(Figure::RealDriveGravityCompensated),
                F(Figure::RealDriveRaw),
            ],
            Section::Noise(white_noise) => {
                let mut labels = vec![
                    T(Table::NoiseCoverage),
                    F(Figure::NoiseEstimates),
                    F(Figure::NoiseProfile),
                ];
                if white_noise {
                    labels.push(T(Table::WhiteNoise));
                }
                labels
            }
        }
    }
}

/// A section and the sections nested in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    /// The section.
    pub section: Section,
    /// Its subsections, in order; they follow everything the section itself shows.
    pub children: Vec<Section>,
}

impl Node {
    /// A section without subsections.
    pub fn leaf(section: Section) -> Self {
        Node {
            section,
            children: Vec::new(),
        }
    }
}

/// The sections of the page, in reading order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outline {
    /// The top-level sections.
    pub nodes: Vec<Node>,
}

impl Outline {
    /// The report's order for a study of `cases` cases, with the sensitivity section when
    /// `sensitivity` is true and the static-noise section when `static_noise` is.
    pub fn standard(cases: usize, sensitivity: bool, static_noise: bool) -> Self {
        let results = Node {
            section: Section::Results,
            children: (0..cases)
                .map(Section::Case)
                .chain([Section::Performance])
                .collect(),
        };
        let mut nodes = vec![
            Node::leaf(Section::Abstract),
            Node::leaf(Section::Introduction),
            Node::leaf(Section::Problem),
            Node::leaf(Section::Theory),
            results,
        ];
        if sensitivity {
            nodes.push(Node::leaf(Section::Sensitivity));
        }
        if static_noise {
            nodes.push(Node::leaf(Section::StaticNoise));
        }
        nodes.push(Node::leaf(Section::Conclusions));
        nodes.push(Node::leaf(Section::Appendix));
        Outline { nodes }
    }

    /// The same outline with the drifting-bias section before the conclusions.
    pub fn with_drift(self) -> Self {
        self.before_conclusions(Section::Drift)
    }

    /// The same outline with the real drive's section before the conclusions.
    pub fn with_real_drive(self) -> Self {
        self.before_conclusions(Section::RealDrive)
    }

    /// The same outline with the section on noise statistics from a drive before the
    /// conclusions (after the drifting bias), with the white noise's identifiability when
    /// `white_noise`.
    pub fn with_noise(self, white_noise: bool) -> Self {
        self.before_conclusions(Section::Noise(white_noise))
    }

    /// The same outline with `section` inserted before the conclusions (at the end without them).
    fn before_conclusions(mut self, section: Section) -> Self {
        let at = self
            .nodes
            .iter()
            .position(|n| n.section == Section::Conclusions)
            .unwrap_or(self.nodes.len());
        self.nodes.insert(at, Node::leaf(section));
        self
    }

    /// Every section in reading order, subsections after their section.
    pub fn sections(&self) -> impl Iterator<Item = Section> + '_ {
        self.nodes
            .iter()
            .flat_map(|n| std::iter::once(n.section).chain(n.children.iter().copied()))
    }

    /// Numbers every table, figure and equation in reading order, each kind from 1.
    pub fn numbers(&self) -> Numbers {
        let mut next = [0usize; 3];
        let mut map = HashMap::new();
        for label in self.sections().flat_map(Section::labels) {
            let kind = match label {
                Label::Table(_) => 0,
                Label::Figure(_) => 1,
                Label::Equation(_) => 2,
            };
            next[kind] += 1;
            map.insert(label, next[kind]);
        }
        Numbers { map }
    }
}

/// The number of every table, figure and equation of an outline.
#[derive(Clone, Debug, Default)]
pub struct Numbers {
    map: HashMap<Label, usize>,
}

impl Numbers {
    /// The number of `label`.
    ///
    /// # Panics
    /// When no section of the outline shows it: a section cites what the page does not hold.
    pub fn of(&self, label: Label) -> usize {
        *self
            .map
            .get(&label)
            .unwrap_or_else(|| panic!("{label:?} is in no section of the outline"))
    }

    /// The number of table `t`.
    pub fn table(&self, t: Table) -> usize {
        self.of(Label::Table(t))
    }

    /// The number of figure `f`.
    pub fn figure(&self, f: Figure) -> usize {
        self.of(Label::Figure(f))
    }

    /// The number of equation `e`.
    pub fn equation(&self, e: Equation) -> usize {
        self.of(Label::Equation(e))
    }
}

/// A figure that shows the members of one or more checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CheckFigure {
    /// The ensemble mean error.
    MeanError,
    /// Ensemble against filter variance.
    Covariance,
    /// Error–estimate correlations.
    Orthogonality,
    /// Residual correlations over pairs of fixes.
    Whiteness,
    /// NEES and NIS.
    Consistency,
}

impl CheckFigure {
    /// The check figures, in the order the report shows them.
    pub const ALL: [CheckFigure; 5] = [
        CheckFigure::MeanError,
        CheckFigure::Covariance,
        CheckFigure::Orthogonality,
        CheckFigure::Whiteness,
        CheckFigure::Consistency,
    ];

    /// The figure that shows check `id`; `None` for a check that has no figure of its own.
    pub fn of(id: CheckId) -> Option<Self> {
        Some(match id {
            CheckId::MEAN_ERROR => CheckFigure::MeanError,
            // The correlations are the off-diagonal terms of the covariance the figure compares.
            CheckId::COVARIANCE_MATCH | CheckId::COVARIANCE_CORRELATION => CheckFigure::Covariance,
            CheckId::ORTHOGONALITY => CheckFigure::Orthogonality,
            CheckId::RESIDUAL_WHITENESS => CheckFigure::Whiteness,
            CheckId::NEES | CheckId::NIS => CheckFigure::Consistency,
            _ => return None,
        })
    }

    /// The element id stem of the figure.
    pub fn id(self) -> &'static str {
        match self {
            CheckFigure::MeanError => "fig-mean-error",
            CheckFigure::Covariance => "fig-covariance",
            CheckFigure::Orthogonality => "fig-orthogonality",
            CheckFigure::Whiteness => "fig-whiteness",
            CheckFigure::Consistency => "fig-consistency",
        }
    }
}
