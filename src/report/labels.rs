//! What a section numbers: its tables, figures and equations ([`Label`]), and the number each
//! gets ([`Numbers`], handed out by [`super::outline::Outline::numbers`] in reading order).

use std::collections::HashMap;

use crate::checks::CheckId;

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
    /// A table named by the section that shows it (a section's own tables need no variant).
    Named(&'static str),
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
    /// A figure named by the section that shows it.
    Named(&'static str),
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
    /// An equation named by the section that shows it.
    Named(&'static str),
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

/// The number of every table, figure and equation of an outline.
#[derive(Clone, Debug, Default)]
pub struct Numbers {
    map: HashMap<Label, usize>,
}

impl Numbers {
    /// The numbers of `map`.
    pub fn from_map(map: HashMap<Label, usize>) -> Self {
        Numbers { map }
    }

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
