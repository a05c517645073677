//! The filter over a recording: the IMU log streamed once, the alignment's window summed on the
//! way, the filter started at the alignment's fix and updated at every later fix at its own
//! time (the IMU step that holds it cut there, its increments shared in proportion).

use nalgebra::Vector3;
use thiserror::Error;

use super::Settings;
use super::align::{self, AlignSettings, Alignment, Plan, Sources};
use super::drive::{LogFixes, LogSteps, Recorder};
pub use super::step::{FixRecord, bias_sigmas, euler_sigmas};
use super::step::{part, start, velocity_sigmas};
use crate::input::LogError;
use crate::input::csv::read::LogSource;
use crate::input::gnss_csv::read_gnss;
use crate::input::imu_csv::{HeldSteps, ImuLayout, ImuReader, ImuSpan, StepSource};
use crate::input::read_ahead::consume_beside;
use crate::input::records::{GnssRow, ImuStep};
use crate::ins::driver::{DriveError, Driver, ImuSource, Source};
use crate::ins::error_state::STATES;
use crate::ins::filter::{Ekf, FilterError, LinearView};
use crate::ins::measurement::Gate;

/// Why a recording cannot be calibrated.
#[derive(Debug, Error)]
pub enum ImuCalibrateError {
    /// A log is bad input.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The recording never gives the filter a start.
    #[error("{file}: {reason}")]
    Alignment {
        /// The GNSS log.
        file: String,
        /// What is missing.
        reason: String,
    },
    /// The filter's covariance stopped being positive definite.
    #[error(transparent)]
    Filter(#[from] FilterError),
}

/// A calibrated recording.
#[derive(Clone, Debug)]
pub struct Calibrated<const N: usize = STATES> {
    /// The GNSS log's file, as named.
    pub gnss_file: String,
    /// The IMU log's span and steps.
    pub span: ImuSpan,
    /// What its rows hold.
    pub layout: ImuLayout,
    /// The fixes read.
    pub fixes: usize,
    /// The alignment's fixes and result.
    pub plan: Plan,
    /// The alignment.
    pub alignment: Alignment,
    /// The filter's start time, s.
    pub start_s: f64,
    /// One record per fix after the start.
    pub records: Vec<FixRecord<N>>,
    /// Fixes whose vertical velocity was missing (the component left out).
    pub missing_velocity: [usize; 3],
    /// Fixes left out for lying more than half a median step outside the IMU log.
    pub outside_log: OutsideLog,
}

/// The fixes more than half a median step before the IMU log's first sample or after its last,
/// left out: a receiver that starts before the IMU (or runs on after it) is a recording's small
/// imperfection, not a fault.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OutsideLog {
    /// Fixes before the first sample.
    pub before: usize,
    /// Fixes after the last sample.
    pub after: usize,
    /// The first fix's time and the last's (as written), s.
    pub fixes_s: (f64, f64),
    /// The IMU log's first and last time stamps, s.
    pub log_s: (f64, f64),
}

impl OutsideLog {
    /// The fixes of `rows` (their times before the receiver's offset `offset_s` moved them)
    /// outside `span`.
    fn of(rows: &[GnssRow], span: &ImuSpan, offset_s: f64) -> Self {
        let tolerance = 0.5 * span.median_step_s;
        let times = || rows.iter().map(|r| r.t_s - offset_s);
        OutsideLog {
            before: times().filter(|t| *t < span.first_s - tolerance).count(),
            after: times().filter(|t| *t > span.last_s + tolerance).count(),
            fixes_s: (
                times().next().unwrap_or(f64::NAN),
                times().next_back().unwrap_or(f64::NAN),
            ),
            log_s: (span.first_s, span.last_s),
        }
    }

    /// The warning, when any fix was left out.
    pub fn warning(&self) -> Option<String> {
        if self.before + self.after == 0 {
            return None;
        }
        let short = |t: f64| format!("{t:.3}");
        let mut parts = Vec::new();
        if self.before > 0 {
            parts.push(format!(
                "{} before its first sample (the fixes start at {} s, the IMU log at {} s)",
                self.before,
                short(self.fixes_s.0),
                short(self.log_s.0)
            ));
        }
        if self.after > 0 {
            parts.push(format!(
                "{} after its last (the fixes end at {} s, the IMU log at {} s)",
                self.after,
                short(self.fixes_s.1),
                short(self.log_s.1)
            ));
        }
        Some(format!(
            "fixes outside the IMU log are left out: {}",
            parts.join(", and ")
        ))
    }
}

/// The filter run over the steps: its records and where it ended.
pub struct Filtered<const N: usize = STATES> {
    /// The alignment's fixes.
    pub plan: Plan,
    /// The alignment.
    pub alignment: Alignment,
    /// One record per fix updated.
    pub records: Vec<FixRecord<N>>,
    /// Fixes without each velocity component.
    pub missing: [usize; 3],
    /// The filter after the last step.
    pub ekf: Ekf<N>,
    /// The first fix not yet updated.
    pub next: usize,
    /// The mean specific force over the alignment's window, body axes, m/s².
    pub mean_f_b: Vector3<f64>,
    /// The filter's view at its start, when tracked ([`filter_tracked`]).
    pub start_view: Option<LinearView<N>>,
}

/// The alignment's error sources at the heading's fix `rh` under the assumptions `s`.
pub(super) fn alignment_sources(rh: &GnssRow, s: &Settings) -> Sources {
    Sources {
        velocity_sigma_m_s: velocity_sigmas(rh, s),
        accel_bias_sigma_m_s2: s.accel_bias_sigma_m_s2,
        vrw_m_s_per_sqrt_s: s.accel_vrw_m_s_per_sqrt_s,
        heading_offset_sigma_rad: s.heading_offset_sigma_deg.to_radians(),
    }
}

/// The GNSS rows with each fix's time moved by the receiver's offset `offset_s` (a fix stamped
/// t describes the antenna at t + offset).
pub fn shifted(rows: &[GnssRow], offset_s: f64) -> Vec<GnssRow> {
    rows.iter()
        .map(|r| GnssRow {
            t_s: r.t_s + offset_s,
            ..*r
        })
        .collect()
}

/// The filter over the fixes `rows` and the steps of `source`, started by the alignment.
///
/// # Errors
/// A log's problem; [`ImuCalibrateError::Alignment`] when no fix is fast enough for the
/// heading or the log ends before it; [`ImuCalibrateError::Filter`].
pub fn filter<const N: usize>(
    rows: &[GnssRow],
    source: &mut dyn StepSource,
    s: &Settings,
    gnss_name: &str,
) -> Result<Filtered<N>, ImuCalibrateError> {
    run_filter(rows, source, s, gnss_name, false)
}

/// [`filter`] with each record's [`FixRecord::linear`] filled: Q_d by noise group, H and the
/// predicted measurement's rate, which a likelihood linearized about the run needs.
///
/// # Errors
/// As [`filter`].
pub fn filter_tracked<const N: usize>(
    rows: &[GnssRow],
    source: &mut dyn StepSource,
    s: &Settings,
    gnss_name: &str,
) -> Result<Filtered<N>, ImuCalibrateError> {
    run_filter(rows, source, s, gnss_name, true)
}

/// [`ImuCalibrateError::Alignment`] when the mean specific force `f` over the alignment's
/// window `(t_a, t_h)` is zero or not finite: roll and pitch come from its direction.
fn levelable(
    f: &Vector3<f64>,
    (t_a, t_h): (f64, f64),
    gnss: &str,
) -> Result<(), ImuCalibrateError> {
    if f.norm() > 0.0 && f.norm().is_finite() {
        return Ok(());
    }
    Err(ImuCalibrateError::Alignment {
        file: gnss.to_string(),
        reason: format!(
            "the mean specific force from {t_a} s to {t_h} s is {:?} m/s²: roll and pitch need \
             the accelerometers' gravity",
            f.as_slice()
        ),
    })
}

/// [`filter`], tracking what a linearized likelihood needs when `tracked`.
fn run_filter<const N: usize>(
    rows: &[GnssRow],
    source: &mut dyn StepSource,
    s: &Settings,
    gnss_name: &str,
    tracked: bool,
) -> Result<Filtered<N>, ImuCalibrateError> {
    let mut first = source.next_step()?;
    let imu_first_s = source.first_s().unwrap_or(f64::INFINITY);
    let settings = AlignSettings {
        speed_m_s: s.heading_speed_m_s,
        window_s: s.alignment_window_s,
        heading_offset_sigma_rad: s.heading_offset_sigma_deg.to_radians(),
    };
    let plan = align::plan(rows, imu_first_s, &settings).ok_or_else(|| no_heading(gnss_name, s))?;
    let (ra, rh) = (&rows[plan.first], &rows[plan.start]);
    let mut sum_dv = Vector3::zeros();
    // The alignment's window summed, up to the step that holds the heading's fix.
    let held = loop {
        let Some(step) = first
            .take()
            .map_or_else(|| source.next_step(), |f| Ok(Some(f)))?
        else {
            return Err(ImuCalibrateError::Alignment {
                file: gnss_name.to_string(),
                reason: format!(
                    "the IMU log ends before the alignment's fix at {} s",
                    rh.t_s
                ),
            });
        };
        let (t1, inc) = (step.t_s, step.increment);
        let (lo, hi) = ((t1 - inc.dt_s).max(ra.t_s), t1.min(rh.t_s));
        if hi > lo {
            sum_dv += part(&inc, t1, lo, hi).dvel_m_s;
        }
        if t1 >= rh.t_s {
            break step;
        }
    };
    let mean_f_b = sum_dv / (rh.t_s - ra.t_s);
    levelable(&mean_f_b, (ra.t_s, rh.t_s), gnss_name)?;
    let alignment = align::align(ra, rh, &mean_f_b, &alignment_sources(rh, s));
    let mut ekf = start::<N>(rh, &alignment, s, tracked);
    let start_view = tracked.then(|| ekf.linear_view());
    let next = plan.start + 1;
    let mut fixes = LogFixes {
        rows,
        next,
        end: rows.len(),
        settings: s,
        missing: [0; 3],
    };
    let mut recorder = Recorder::new(rows, next, Vec::with_capacity(rows.len() - next));
    let mut steps = LogSteps {
        first: Some(held),
        source,
    };
    let last_s = rows.last().map_or(rh.t_s, |r| r.t_s);
    let mut extra = crate::ins::extra::sources::<N, LogSteps>(rh.t_s, last_s, &Default::default());
    {
        let mut list = vec![&mut fixes as &mut dyn Source<N, LogSteps>];
        list.extend(
            extra
                .iter_mut()
                .map(|s| &mut **s as &mut dyn Source<N, LogSteps>),
        );
        Driver::new(list)
            .with_gate(gate_of(s))
            .starting_at(rh.t_s)
            .run(&mut ekf, &mut steps, &mut recorder)
            .map_err(drive_error)?;
    }
    Ok(Filtered {
        plan,
        alignment,
        records: recorder.records,
        missing: fixes.missing,
        ekf,
        next: fixes.next,
        mean_f_b,
        start_view,
    })
}

/// The χ² gate `s` asks for, at its false-alarm rate.
fn gate_of(s: &Settings) -> Option<Gate> {
    s.innovation_gate.then(|| Gate::new(s.false_alarm_rate))
}

/// A driver's error as the calibration's.
fn drive_error(e: DriveError<LogError>) -> ImuCalibrateError {
    match e {
        DriveError::Filter(f) => ImuCalibrateError::Filter(f),
        DriveError::Other(log) => ImuCalibrateError::Log(log),
    }
}

/// Calibrates the recording `imu` + `gnss` with the assumptions `s`.
///
/// # Errors
/// [`ImuCalibrateError::Log`] naming the file and line of the first problem of either log (a
/// fix outside the IMU log's span included); [`ImuCalibrateError::Alignment`] when no fix is
/// fast enough for the heading; [`ImuCalibrateError::Filter`] when the filter breaks down.
pub fn calibrate(
    imu: &dyn LogSource,
    gnss: &dyn LogSource,
    s: &Settings,
) -> Result<Calibrated, ImuCalibrateError> {
    calibrate_of::<STATES>(imu, gnss, s)
}

/// [`calibrate`] with a filter of `N` error states (21: the scale factors too).
///
/// # Errors
/// As [`calibrate`].
pub fn calibrate_of<const N: usize>(
    imu: &dyn LogSource,
    gnss: &dyn LogSource,
    s: &Settings,
) -> Result<Calibrated<N>, ImuCalibrateError> {
    let rows = shifted(&read_gnss(gnss)?, s.gnss_time_offset_s);
    let mut reader = ImuReader::open(imu, s.axes)?;
    let layout = reader.layout();
    let name = gnss.name();
    let run = consume_beside(&mut reader, |steps| filter(&rows, steps, s, name));
    // A row the reader refused ended the run: its line is the error, not the rows short of it.
    if let Err(e @ ImuCalibrateError::Log(_)) = run {
        return Err(e);
    }
    let span = reader.finish()?;
    assemble(&rows, run?, (span, layout), s, gnss.name())
}

/// [`calibrate`] from the GNSS log's `rows` (as read) and the IMU log's `steps`, `span` and
/// `layout` held in memory.
///
/// # Errors
/// As [`calibrate`].
pub fn calibrate_held<const N: usize>(
    rows: &[GnssRow],
    (steps, span, layout): (&[ImuStep], ImuSpan, ImuLayout),
    s: &Settings,
    gnss: &str,
) -> Result<Calibrated<N>, ImuCalibrateError> {
    let rows = shifted(rows, s.gnss_time_offset_s);
    let run = filter(&rows, &mut HeldSteps::new(steps), s, gnss);
    assemble(&rows, run?, (span, layout), s, gnss)
}

/// The calibration from a filter's run over the whole log: every fix checked against the
/// log's span, the last fixes updated.
fn assemble<const N: usize>(
    rows: &[GnssRow],
    mut run: Filtered<N>,
    (span, layout): (ImuSpan, ImuLayout),
    s: &Settings,
    gnss: &str,
) -> Result<Calibrated<N>, ImuCalibrateError> {
    let outside_log = OutsideLog::of(rows, &span, s.gnss_time_offset_s);
    // The fixes past the log's end (as written, or carried there by a time offset) are left out.
    let tolerance = 0.5 * span.median_step_s;
    let within = rows.partition_point(|r| r.t_s <= span.last_s + tolerance);
    finish(within, &mut run, s, rows)?;
    Ok(Calibrated {
        gnss_file: gnss.to_string(),
        span,
        layout,
        fixes: rows.len(),
        plan: run.plan,
        alignment: run.alignment,
        start_s: rows[run.plan.start].t_s,
        records: run.records,
        missing_velocity: run.missing,
        outside_log,
    })
}

/// The fixes within half a step after the last sample (the first `fixes`), updated where the
/// log ends.
fn finish<const N: usize>(
    fixes: usize,
    run: &mut Filtered<N>,
    s: &Settings,
    rows: &[GnssRow],
) -> Result<(), ImuCalibrateError> {
    let mut source = LogFixes {
        rows,
        next: run.next,
        end: fixes.max(run.next),
        settings: s,
        missing: run.missing,
    };
    let mut recorder = Recorder::new(rows, run.next, std::mem::take(&mut run.records));
    let mut none = NoSteps;
    Driver::new(vec![&mut source as &mut dyn Source<N, NoSteps>])
        .with_gate(gate_of(s))
        .drain(&mut run.ekf, &mut none, &mut recorder, f64::INFINITY)
        .map_err(drive_error)?;
    run.records = recorder.records;
    run.missing = source.missing;
    run.next = source.next;
    Ok(())
}

/// The IMU source after the log's end.
struct NoSteps;

impl ImuSource for NoSteps {
    type Error = LogError;

    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        Ok(None)
    }
}

/// The error of a recording whose course never gives the heading.
fn no_heading(gnss: &str, s: &Settings) -> ImuCalibrateError {
    ImuCalibrateError::Alignment {
        file: gnss.to_string(),
        reason: format!(
            "no fix with a horizontal speed of at least {} m/s and a fix with a horizontal \
             velocity {} s or more before it (within the IMU log): the course cannot give the \
             heading",
            s.heading_speed_m_s, s.alignment_window_s
        ),
    }
}
