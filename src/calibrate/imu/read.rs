//! The 6-axis IMU log, streamed as increments.
//!
//! `t_s` and either the mean rates over the step ending at `t_s`
//!   (`ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s`: specific force and angular rate) or
//!   the increments over that step (`dvx_m_s,dvy_m_s,dvz_m_s,dthx_rad,dthy_rad,dthz_rad`), in
//!   body axes forward-right-down or forward-left-up. The first row only starts the first step.
//!   Rows go through the log reader of the one-axis path (blocks of whole lines, gzip, pipes),
//!   the steps through its checks against the median step.

use nalgebra::Vector3;

use crate::config::ins::Axes;
use crate::ins::mech::Increment;
use crate::logs::read::{CsvReader, LogSource};
use crate::logs::steps::{ACCEPTED_STEP_RATIO, StepAt, StepMedian};
use crate::logs::{LogError, LogProblem};

/// The IMU log's columns when it holds rates.
pub const RATE_COLUMNS: [&str; 7] = [
    "t_s", "ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s",
];
/// The IMU log's columns when it holds increments.
pub const INCREMENT_COLUMNS: [&str; 7] = [
    "t_s", "dvx_m_s", "dvy_m_s", "dvz_m_s", "dthx_rad", "dthy_rad", "dthz_rad",
];

/// What an IMU log's rows hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImuLayout {
    /// Mean specific force (m/s²) and angular rate (rad/s) over the step ending at `t_s`.
    Rates,
    /// Δv (m/s) and Δθ (rad) over the step ending at `t_s`.
    Increments,
}

/// The layout a header names, or why it names none.
fn choose(found: &[&str], line: u64, file: &str) -> Result<[&'static str; 7], LogError> {
    let has = |c: &&str| found.contains(c);
    let rate = RATE_COLUMNS[1..].iter().find(|c| has(c));
    let increment = INCREMENT_COLUMNS[1..].iter().find(|c| has(c));
    let expected = format!(
        "`{}` or `{}`",
        RATE_COLUMNS.join(","),
        INCREMENT_COLUMNS.join(",")
    );
    match (rate, increment) {
        (Some(first), Some(second)) => Err(LogError::at(
            file,
            line,
            LogProblem::ConflictingColumns {
                first,
                second,
                expected,
            },
        )),
        (None, Some(_)) => Ok(INCREMENT_COLUMNS),
        _ => Ok(RATE_COLUMNS),
    }
}

/// One step of the IMU log: the increments over (`t_s − dt_s`, `t_s`], in body axes
/// forward-right-down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuStep {
    /// Line of the row that ends the step.
    pub line: u64,
    /// The step's end, s.
    pub t_s: f64,
    /// Δθ, Δv and the step's length.
    pub increment: Increment,
}

/// The IMU log as a stream of steps.
pub struct ImuReader<'a> {
    csv: CsvReader<'a, 7>,
    layout: ImuLayout,
    axes: Axes,
    /// The line and time of the previous row.
    previous: Option<(u64, f64)>,
    first_s: Option<f64>,
    rows: u64,
    steps: StepMedian,
    shortest: Option<StepAt>,
    longest: Option<StepAt>,
}

/// What the reader learned of the steps once the log is read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSpan {
    /// The first and last time stamps, s.
    pub first_s: f64,
    /// The last time stamp, s.
    pub last_s: f64,
    /// Rows read.
    pub rows: u64,
    /// The median step, s.
    pub median_step_s: f64,
}

impl<'a> ImuReader<'a> {
    /// Opens the IMU log `source` whose body axes are `axes`.
    ///
    /// # Errors
    /// [`LogError`] when it cannot be read or its header names neither layout, or both.
    pub fn open(source: &'a dyn LogSource, axes: Axes) -> Result<Self, LogError> {
        let name = source.name().to_string();
        let expected = format!("{} (or increments)", RATE_COLUMNS.join(","));
        let csv =
            CsvReader::open_choosing(source, &expected, |found, line| choose(found, line, &name))?;
        let layout = if csv_columns_are_rates(&csv) {
            ImuLayout::Rates
        } else {
            ImuLayout::Increments
        };
        Ok(Self {
            csv,
            layout,
            axes,
            previous: None,
            first_s: None,
            rows: 0,
            steps: StepMedian::new(),
            shortest: None,
            longest: None,
        })
    }

    /// What the rows hold.
    pub fn layout(&self) -> ImuLayout {
        self.layout
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        self.csv.file()
    }

    /// The first time stamp, once a row is read.
    pub fn first_s(&self) -> Option<f64> {
        self.first_s
    }

    /// The next step; `None` at the end of the log.
    ///
    /// # Errors
    /// [`LogError`] naming the line of a malformed row or a time stamp not after the previous.
    pub fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        loop {
            let Some((line, v)) = self.csv.next_row()? else {
                return Ok(None);
            };
            let t_s = v[0];
            self.rows += 1;
            let Some((_, previous_s)) = self.previous.replace((line, t_s)) else {
                self.first_s = Some(t_s);
                continue;
            };
            if t_s <= previous_s {
                let problem = LogProblem::NotIncreasing { t_s, previous_s };
                return Err(self.csv.error(problem));
            }
            let dt_s = t_s - previous_s;
            let at = StepAt {
                sample: self.rows - 1,
                line,
                previous_s,
                t_s,
            };
            self.steps.add_at(dt_s, at);
            if self.shortest.is_none_or(|s| dt_s < s.step_s()) {
                self.shortest = Some(at);
            }
            if self.longest.is_none_or(|s| dt_s > s.step_s()) {
                self.longest = Some(at);
            }
            let sign = match self.axes {
                Axes::Frd => Vector3::new(1.0, 1.0, 1.0),
                Axes::Flu => Vector3::new(1.0, -1.0, -1.0),
            };
            let scale = match self.layout {
                ImuLayout::Rates => dt_s,
                ImuLayout::Increments => 1.0,
            };
            let f = Vector3::new(v[1], v[2], v[3]).component_mul(&sign) * scale;
            let w = Vector3::new(v[4], v[5], v[6]).component_mul(&sign) * scale;
            return Ok(Some(ImuStep {
                line,
                t_s,
                increment: Increment {
                    dtheta_rad: w,
                    dvel_m_s: f,
                    dt_s,
                },
            }));
        }
    }

    /// The log's span and median step, once every row is read, after the steps' check: every
    /// step within [`ACCEPTED_STEP_RATIO`] of the median, as the one-axis path checks its log.
    ///
    /// # Errors
    /// [`LogProblem::TooFewRows`] for fewer than two rows; [`LogProblem::Gap`] naming the line
    /// of the first step outside the band.
    pub fn finish(self) -> Result<ImuSpan, LogError> {
        let file = self.csv.file().to_string();
        let (Some(first_s), Some((_, last_s)), Some(median_step_s)) =
            (self.first_s, self.previous, self.steps.median())
        else {
            let problem = LogProblem::TooFewRows {
                found: self.rows,
                needed: 2,
            };
            return Err(LogError::of_file(&file, problem));
        };
        let (lo, hi) = (
            ACCEPTED_STEP_RATIO.0 * median_step_s,
            ACCEPTED_STEP_RATIO.1 * median_step_s,
        );
        let outside = [
            self.steps.first_outside(lo, hi),
            self.shortest,
            self.longest,
        ]
        .into_iter()
        .flatten()
        .filter(|at| !(lo..=hi).contains(&at.step_s()))
        .min_by_key(|at| at.sample);
        if let Some(at) = outside {
            let step_s = at.step_s();
            let problem = LogProblem::Gap {
                previous_s: at.previous_s,
                t_s: at.t_s,
                step_s,
                ratio: step_s / median_step_s,
                median_s: median_step_s,
            };
            return Err(LogError::at(&file, at.line, problem));
        }
        Ok(ImuSpan {
            first_s,
            last_s,
            rows: self.rows,
            median_step_s,
        })
    }
}

/// Whether the reader's first data column is a rate column.
fn csv_columns_are_rates(csv: &CsvReader<'_, 7>) -> bool {
    csv.columns()[1] == RATE_COLUMNS[1]
}

/// A source of IMU steps: the log's reader, or steps held in memory.
pub trait StepSource {
    /// The next step; `None` at the end.
    ///
    /// # Errors
    /// The log's problem at that row.
    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError>;
    /// The first row's time, once a step is read.
    fn first_s(&self) -> Option<f64>;
}

impl StepSource for ImuReader<'_> {
    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        ImuReader::next_step(self)
    }

    fn first_s(&self) -> Option<f64> {
        ImuReader::first_s(self)
    }
}

/// Steps held in memory, read from their start.
pub struct HeldSteps<'a> {
    steps: &'a [ImuStep],
    next: usize,
}

impl<'a> HeldSteps<'a> {
    /// The steps `steps`.
    pub fn new(steps: &'a [ImuStep]) -> Self {
        Self { steps, next: 0 }
    }
}

impl StepSource for HeldSteps<'_> {
    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        let step = self.steps.get(self.next).copied();
        self.next += 1;
        Ok(step)
    }

    fn first_s(&self) -> Option<f64> {
        self.steps.first().map(|s| s.t_s - s.increment.dt_s)
    }
}

/// The IMU log `imu` read whole: its steps, span and layout (`--estimate-noise` runs the
/// filter over them many times).
///
/// # Errors
/// The log's first problem, with its line.
pub fn read_steps(
    imu: &dyn LogSource,
    axes: crate::config::ins::Axes,
) -> Result<(Vec<ImuStep>, ImuSpan, ImuLayout), LogError> {
    let mut reader = ImuReader::open(imu, axes)?;
    let layout = reader.layout();
    let mut steps = Vec::new();
    while let Some(step) = reader.next_step()? {
        steps.push(step);
    }
    Ok((steps, reader.finish()?, layout))
}
