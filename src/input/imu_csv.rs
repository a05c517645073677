//! The 6-axis IMU log of `calibrate --imu`, streamed as increments ([`ImuStep`]s), or its
//! columns held in memory (the Python package's arrays) turned into the same steps.
//!
//! # Format
//! The CSV text of [`super::csv`] with the columns of `docs/guide/calibrate_imu.md` (§ The
//! recordings): `t_s` and either the mean rates over the step ending at `t_s`
//!   (`ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s`: specific force and angular rate) or
//!   the increments over that step (`dvx_m_s,dvy_m_s,dvz_m_s,dthx_rad,dthy_rad,dthz_rad`), in
//!   body axes forward-right-down or forward-left-up. The first row only starts the first step.
//!   Rows go through the log reader of the one-axis path (blocks of whole lines, gzip, pipes),
//!   the steps through its checks against the median step.

use nalgebra::Vector3;

use super::csv::read::{CsvReader, LogSource};
use super::csv::steps::{ACCEPTED_STEP_RATIO, StepAt, StepMedian};
use super::records::{ImuStep, Increment};
use super::{LogError, LogProblem};
use crate::config::ins::Axes;

/// The IMU log's columns when it holds rates.
pub const RATE_COLUMNS: [&str; 7] = [
    "t_s", "ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s",
];
/// The IMU log's columns when it holds increments.
pub const INCREMENT_COLUMNS: [&str; 7] = [
    "t_s", "dvx_m_s", "dvy_m_s", "dvz_m_s", "dthx_rad", "dthy_rad", "dthz_rad",
];

/// The largest specific force a row may hold, m/s² (about 10⁵ g, beyond any shock-rated
/// accelerometer): a larger one is a damaged field, and its square would leave the filter's
/// double precision.
pub const MAX_SPECIFIC_FORCE_M_S2: f64 = 1e6;
/// The largest angular rate a row may hold, rad/s (about 1 600 turns a second).
pub const MAX_ANGULAR_RATE_RAD_S: f64 = 1e4;

/// What an IMU log's rows hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImuLayout {
    /// Mean specific force (m/s²) and angular rate (rad/s) over the step ending at `t_s`.
    Rates,
    /// Δv (m/s) and Δθ (rad) over the step ending at `t_s`.
    Increments,
}

impl ImuLayout {
    /// The log's columns in this layout.
    pub fn columns(self) -> [&'static str; 7] {
        match self {
            ImuLayout::Rates => RATE_COLUMNS,
            ImuLayout::Increments => INCREMENT_COLUMNS,
        }
    }
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

/// The IMU log as a stream of steps.
pub struct ImuReader<'a> {
    csv: CsvReader<'a, 7>,
    rows: Rows,
}

/// The rows of an IMU log turned into steps, and what the steps' check needs: the one
/// arithmetic of the reader and of columns held in memory ([`held_steps`]).
struct Rows {
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
            rows: Rows::new(layout, axes),
        })
    }

    /// What the rows hold.
    pub fn layout(&self) -> ImuLayout {
        self.rows.layout
    }

    /// The name of the file in messages.
    pub fn file(&self) -> &str {
        self.csv.file()
    }

    /// The first time stamp, once a row is read.
    pub fn first_s(&self) -> Option<f64> {
        self.rows.first_s
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
            match self.rows.step(line, &v) {
                Ok(Some(step)) => return Ok(Some(step)),
                Ok(None) => continue,
                Err(problem) => return Err(self.csv.error(problem)),
            }
        }
    }

    /// The log's span and median step, once every row is read, after the steps' check: every
    /// step within [`ACCEPTED_STEP_RATIO`] of the median, as the one-axis path checks its log.
    ///
    /// # Errors
    /// [`LogProblem::TooFewRows`] for fewer than two rows; [`LogProblem::Gap`] naming the line
    /// of the first step outside the band.
    pub fn finish(self) -> Result<ImuSpan, LogError> {
        self.rows.finish(self.csv.file())
    }
}

impl Rows {
    fn new(layout: ImuLayout, axes: Axes) -> Self {
        Self {
            layout,
            axes,
            previous: None,
            first_s: None,
            rows: 0,
            steps: StepMedian::new(),
            shortest: None,
            longest: None,
        }
    }

    /// The step that row `v` (`t_s` and the six values, on `line`) ends; `None` for the first
    /// row, which only starts the first step.
    fn step(&mut self, line: u64, v: &[f64; 7]) -> Result<Option<ImuStep>, LogProblem> {
        let t_s = v[0];
        self.rows += 1;
        let Some((_, previous_s)) = self.previous.replace((line, t_s)) else {
            self.first_s = Some(t_s);
            return Ok(None);
        };
        if t_s <= previous_s {
            return Err(LogProblem::NotIncreasing { t_s, previous_s });
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
        self.in_range(v, dt_s)?;
        let f = Vector3::new(v[1], v[2], v[3]).component_mul(&sign) * scale;
        let w = Vector3::new(v[4], v[5], v[6]).component_mul(&sign) * scale;
        Ok(Some(ImuStep {
            line,
            t_s,
            increment: Increment {
                dtheta_rad: w,
                dvel_m_s: f,
                dt_s,
            },
        }))
    }

    /// [`LogProblem::OutOfRange`] for the first of row `v`'s six values whose rate (the value,
    /// or the increment over the step `dt_s`) exceeds [`MAX_SPECIFIC_FORCE_M_S2`] or
    /// [`MAX_ANGULAR_RATE_RAD_S`].
    fn in_range(&self, v: &[f64; 7], dt_s: f64) -> Result<(), LogProblem> {
        let columns = self.layout.columns();
        for k in 1..7 {
            let (limit, unit) = if k <= 3 {
                (MAX_SPECIFIC_FORCE_M_S2, "m/s²")
            } else {
                (MAX_ANGULAR_RATE_RAD_S, "rad/s")
            };
            let rate = match self.layout {
                ImuLayout::Rates => v[k],
                ImuLayout::Increments => v[k] / dt_s,
            };
            if rate.abs() > limit {
                let range = match self.layout {
                    ImuLayout::Rates => format!("|{}| ≤ {limit:e} {unit}", columns[k]),
                    ImuLayout::Increments => format!(
                        "|{}| ≤ {limit:e} {unit} times the step of {} s",
                        columns[k],
                        crate::format::short(dt_s)
                    ),
                };
                let (column, value) = (columns[k], v[k]);
                return Err(LogProblem::OutOfRange {
                    column,
                    value,
                    range,
                });
            }
        }
        Ok(())
    }

    /// [`ImuReader::finish`] of the log named `file`.
    fn finish(self, file: &str) -> Result<ImuSpan, LogError> {
        let (Some(first_s), Some((_, last_s)), Some(median_step_s)) =
            (self.first_s, self.previous, self.steps.median())
        else {
            let problem = LogProblem::TooFewRows {
                found: self.rows,
                needed: 2,
            };
            return Err(LogError::of_file(file, problem));
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
            return Err(LogError::at(file, at.line, problem));
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
    axes: Axes,
) -> Result<(Vec<ImuStep>, ImuSpan, ImuLayout), LogError> {
    let mut reader = ImuReader::open(imu, axes)?;
    let layout = reader.layout();
    let mut steps = Vec::new();
    while let Some(step) = reader.next_step()? {
        steps.push(step);
    }
    Ok((steps, reader.finish()?, layout))
}

/// The columns of an IMU log held in memory (the Python package's arrays): `t_s` (s) and the
/// six columns of `layout`, in the order of [`RATE_COLUMNS`] or [`INCREMENT_COLUMNS`], in body
/// axes `axes`. Row `i` is the row on line `i + 2` of the log written as CSV (after its header):
/// the steps, the span and the checks are the reader's, so every number equals that of the log
/// written as text with each number in its shortest round-trip form.
///
/// # Errors
/// [`LogProblem::Unreadable`] when a column's length differs from `t_s`'s;
/// [`LogProblem::NotFinite`] naming the column and line of a NaN or an infinity; the reader's
/// for time stamps that do not increase, fewer than two rows and a gap.
pub fn held_steps(
    name: &str,
    t_s: &[f64],
    columns: [&[f64]; 6],
    layout: ImuLayout,
    axes: Axes,
) -> Result<(Vec<ImuStep>, ImuSpan, ImuLayout), LogError> {
    let names = layout.columns();
    if let Some(k) = columns.iter().position(|c| c.len() != t_s.len()) {
        let message = format!(
            "{} has {} values and t_s has {}: expected one value per time stamp",
            names[k + 1],
            columns[k].len(),
            t_s.len()
        );
        return Err(LogError::of_file(name, LogProblem::Unreadable { message }));
    }
    let mut rows = Rows::new(layout, axes);
    let mut steps = Vec::with_capacity(t_s.len().saturating_sub(1));
    for (i, &t) in t_s.iter().enumerate() {
        let line = i as u64 + 2;
        let mut v = [t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        for (x, c) in v[1..].iter_mut().zip(columns) {
            *x = c[i];
        }
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            let problem = LogProblem::NotFinite {
                column: names[k],
                text: v[k].to_string(),
            };
            return Err(LogError::at(name, line, problem));
        }
        if let Some(step) = rows
            .step(line, &v)
            .map_err(|p| LogError::at(name, line, p))?
        {
            steps.push(step);
        }
    }
    Ok((steps, rows.finish(name)?, layout))
}
