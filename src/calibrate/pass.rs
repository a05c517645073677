//! The one streamed pass over the accelerometer log: every row checked, and the log reduced to
//! what the filter and the smoother need between fixes.
//!
//! The text is read in blocks on the calling thread; the blocks are parsed on all threads and
//! stitched in file order on one, so the numbers do not depend on the number of threads. The Δt
//! mode is known only at the end (it takes every step), so both integrations of eq. (3), the
//! nominal one and the per-step one, are carried through the pass, with the per-step process
//! noise of each interval as unit contributions ([`NoiseUnits`]).

use std::sync::mpsc;

use rayon::prelude::*;

use crate::input::csv::block::{BLOCK_BYTES, Block, Layout, MAX_LINE_BYTES, Rows, parse_block};
use crate::input::csv::read::{LogSource, open_blocks};
use crate::input::csv::steps::{StepAt, StepMedian};
use crate::input::csv::{ACCEL_COLUMNS, GpsFix};
use crate::input::{LogError, LogProblem};
use crate::state::BiasModel;

use super::chunked::Chunked;

pub use super::integration::{Integrated, Start, update_time_s};
pub use super::units::NoiseUnits;

/// Relative tolerance within which every step of a log must equal the configured Δt for the
/// nominal recursion to run: time stamps written as j·Δt differ from j·Δt by a rounding error.
pub const NOMINAL_TOLERANCE: f64 = 1e-9;

/// Blocks parsed together, one per thread or more: a bound on the text held at once.
const PARSE_GROUP: usize = 4;

/// A GPS fix placed in the step of the accelerometer sample at or before it.
#[derive(Clone, Debug, PartialEq)]
pub struct FixAt {
    /// Index of the fix in the GPS log.
    pub fix: usize,
    /// Index of the sample whose step holds the fix (t_sample ≤ t_s < the next sample's).
    pub sample: u64,
    /// The time the filter updates at, s: the fix's own ([`update_time_s`]).
    pub t_s: f64,
    /// How far into the sample's step that is, τ = t_s − t_sample, s (0 on the sample).
    pub tau_s: f64,
    /// The sample's line in the accelerometer log.
    pub line: u64,
    /// (p_c, v_c) at `t_s` with the nominal Δt and with each step's own: the sample's, carried
    /// over the fraction τ = t_s − t_sample of its step by eq. (3) with that sample's output.
    pub integrated: [Integrated; 2],
    /// The per-step process noise since the previous fix's time (the log's first sample), with
    /// the pieces of the steps the two fixes cut ([`NoiseUnits::add_piece`]).
    pub units: NoiseUnits,
}

/// The accelerometer log reduced by the pass.
#[derive(Clone, Debug)]
pub struct Reduced {
    /// Samples.
    pub samples: u64,
    /// First and last time stamps, s.
    pub span_s: (f64, f64),
    /// Line of the first sample.
    pub first_line: u64,
    /// The output of the first sample, m/s².
    pub first_accel_m_s2: f64,
    /// The steps' histogram, with the first step of each key.
    pub median: StepMedian,
    /// The shortest and the longest step.
    pub step_range: (StepAt, StepAt),
    /// Whether every step equals the nominal Δt within [`NOMINAL_TOLERANCE`] and every fix
    /// lies on a sample (its time stamp that sample's, or beyond the log's ends).
    pub nominal: bool,
    /// Every fix at its sample, in the GPS log's order.
    pub fixes: Chunked<FixAt>,
    /// The last sample: (p_c, v_c) as in [`FixAt::integrated`], and the per-step noise since
    /// the last fix.
    pub end: ([Integrated; 2], NoiseUnits),
    /// The first sample whose step leaves the integration non-finite, with its line, in each
    /// Δt mode (nominal, per-step).
    pub overflow: [Option<(u64, u64)>; 2],
}

/// The sample being stitched.
#[derive(Clone, Copy, Debug)]
struct Current {
    t_s: f64,
    accel_m_s2: f64,
    line: u64,
}

/// The pass's state between rows.
struct Stitch<'g> {
    dt_s: f64,
    /// The filter's bias model: the per-step units' bias part.
    bias: BiasModel,
    half_dt2_s2: f64,
    gps: &'g [GpsFix],
    start: Start,
    k: u64,
    current: Option<Current>,
    integrated: [Integrated; 2],
    units: NoiseUnits,
    reduced: Reduced,
    file: String,
}

impl Stitch<'_> {
    /// Places in the step from the current sample `c` every remaining fix before the next
    /// sample at `next_s` (every one at the last sample), each at its own time: the units get the
    /// fraction of the step up to it as a step of its own. Returns the part of the step already
    /// in the units, s.
    fn assign(&mut self, c: Current, next_s: Option<f64>) -> f64 {
        let mut done_s = 0.0;
        while let Some(f) = self.gps.get(self.reduced.fixes.len()) {
            if next_s.is_some_and(|n| f.t_s >= n) {
                break;
            }
            let t_s = update_time_s(f.t_s, c.t_s, next_s.is_none());
            let tau_s = t_s - c.t_s;
            if tau_s > done_s {
                self.reduced.nominal = false;
                // A fix before the next sample: `next_s` is known.
                let step_s = next_s.map_or(0.0, |n| n - c.t_s);
                self.add_piece(tau_s - done_s, step_s);
                done_s = tau_s;
            }
            let fix = FixAt {
                fix: self.reduced.fixes.len(),
                sample: self.k,
                t_s,
                tau_s,
                line: c.line,
                integrated: self.integrated.map(|i| i.advanced(c.accel_m_s2, tau_s)),
                units: std::mem::take(&mut self.units),
            };
            self.reduced.fixes.push(fix);
        }
        done_s
    }

    /// The process noise of a step of `tau_s`.
    #[inline]
    fn add_step(&mut self, tau_s: f64) {
        self.units.add_step(tau_s);
        if self.bias.drifts() {
            self.units.add_bias_step(tau_s, self.bias);
        }
    }

    /// The process noise of a piece of `tau_s` of a step of `step_s` cut by a fix
    /// ([`NoiseUnits::add_piece`]).
    fn add_piece(&mut self, tau_s: f64, step_s: f64) {
        self.units.add_piece(tau_s, step_s);
        if self.bias.drifts() {
            self.units.add_bias_step(tau_s, self.bias);
        }
    }

    /// One row.
    #[inline]
    fn row(&mut self, t_s: f64, accel_m_s2: f64, line: u64) -> Result<(), LogError> {
        let next = Current {
            t_s,
            accel_m_s2,
            line,
        };
        let Some(c) = self.current else {
            self.current = Some(next);
            self.integrated = [self.start.at(t_s, accel_m_s2); 2];
            (self.reduced.span_s, self.reduced.first_line) = ((t_s, t_s), line);
            self.reduced.first_accel_m_s2 = accel_m_s2;
            return Ok(());
        };
        if t_s <= c.t_s {
            let problem = LogProblem::NotIncreasing {
                t_s,
                previous_s: c.t_s,
            };
            return Err(LogError::at(&self.file, line, problem));
        }
        let step = t_s - c.t_s;
        let at = StepAt {
            sample: self.k + 1,
            line,
            previous_s: c.t_s,
            t_s,
        };
        let r = &mut self.reduced;
        r.median.add_at(step, at);
        if step < r.step_range.0.step_s() {
            r.step_range.0 = at;
        }
        if step > r.step_range.1.step_s() {
            r.step_range.1 = at;
        }
        r.nominal &= (step - self.dt_s).abs() <= NOMINAL_TOLERANCE * self.dt_s;
        let done_s = if self.reduced.fixes.len() < self.gps.len() {
            self.assign(c, Some(t_s))
        } else {
            0.0
        };
        let a = c.accel_m_s2;
        self.integrated[0].advance(a, self.dt_s, self.half_dt2_s2);
        self.integrated[1].advance(a, step, 0.5 * step * step);
        // The rest of the step after its last fix, or all of it without one.
        if done_s > 0.0 {
            self.add_piece(step - done_s, step);
        } else {
            self.add_step(step);
        }
        let finite = [
            self.integrated[0].is_finite(),
            self.integrated[1].is_finite() && self.units.is_finite(),
        ];
        for (overflow, finite) in self.reduced.overflow.iter_mut().zip(finite) {
            if !finite && overflow.is_none() {
                *overflow = Some((self.k, c.line));
            }
        }
        (self.current, self.k) = (Some(next), self.k + 1);
        Ok(())
    }

    fn rows(&mut self, rows: &Rows<2>) -> Result<(), LogError> {
        for (&[t_s, a], &line) in rows.values.iter().zip(&rows.lines) {
            self.row(t_s, a, line)?;
        }
        Ok(())
    }
}

impl<'g> Stitch<'g> {
    /// A pass about to read the log `file`, before its first row.
    fn new(
        file: &str,
        gps: &'g [GpsFix],
        (nominal_dt_s, bias): (f64, BiasModel),
        start: Start,
    ) -> Self {
        let empty = StepAt {
            previous_s: 0.0,
            t_s: f64::INFINITY,
            ..StepAt::default()
        };
        Stitch {
            dt_s: nominal_dt_s,
            bias,
            half_dt2_s2: 0.5 * nominal_dt_s * nominal_dt_s,
            gps,
            start,
            k: 0,
            current: None,
            integrated: [Integrated::default(); 2],
            units: NoiseUnits::default(),
            reduced: Reduced {
                samples: 0,
                span_s: (0.0, 0.0),
                first_line: 0,
                first_accel_m_s2: 0.0,
                median: StepMedian::new(),
                step_range: (empty, StepAt::default()),
                nominal: true,
                fixes: Chunked::default(),
                end: Default::default(),
                overflow: [None; 2],
            },
            file: file.to_string(),
        }
    }

    /// The reduced log once every row is in.
    fn finish(mut self) -> Result<Reduced, LogError> {
        let Some(last) = self.current else {
            return Err(too_few(&self.file, 0));
        };
        self.assign(last, None);
        self.reduced.samples = self.k + 1;
        if self.k == 0 {
            return Err(too_few(&self.file, 1));
        }
        self.reduced.span_s.1 = last.t_s;
        self.reduced.end = (self.integrated, self.units);
        Ok(self.reduced)
    }
}

/// What the reading thread hands over: a block, or the problem that ended the reading.
type Message = Result<Block, LogError>;

/// A block's rows, and the problem that ended them.
type Parsed = (Rows<2>, Option<LogError>);

/// Parses `group` on all threads, into the row buffers of `spare` (used before).
fn parse_group(layout: &Layout<2>, group: &[Message], mut spare: Vec<Parsed>) -> Vec<Parsed> {
    let mut out: Vec<Parsed> = group
        .iter()
        .map(|_| spare.pop().unwrap_or_default())
        .collect();
    let parse = |((rows, error), m): (&mut Parsed, &Message)| {
        rows.clear();
        *error = match m {
            Ok(block) => parse_block(layout, block, rows).err(),
            Err(e) => Some(e.clone()),
        };
    };
    if on_pool() {
        out.iter_mut().zip(group).for_each(parse);
    } else {
        out.par_iter_mut().zip(group).for_each(parse);
    }
    out
}

/// Whether the pass was started on a worker of the thread pool (a calibration among others run
/// in parallel): then it parses and stitches on its own threads only, since the pool's workers
/// may all be blocked in passes of their own, waiting for blocks that only this pass's reading
/// thread sends. The numbers are the same either way.
fn on_pool() -> bool {
    ON_POOL.with(|p| p.get())
}

thread_local! {
    /// Set on the stitching thread of a pass started on a pool worker.
    static ON_POOL: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Stitches parsed blocks in order; stops at the first problem.
fn stitch_group(parsed: &[Parsed], stitch: &mut Stitch<'_>) -> Result<(), LogError> {
    for (rows, error) in parsed {
        stitch.rows(rows)?;
        if let Some(e) = error {
            return Err(e.clone());
        }
    }
    Ok(())
}

/// Parses and stitches the blocks arriving on `blocks`, in order, handing their buffers back on
/// `used`; stops at the first problem. A group of blocks is parsed while the group before it is
/// stitched.
fn stitch_all(
    layout: &Layout<2>,
    (blocks, used): (&mpsc::Receiver<Message>, &mpsc::Sender<Vec<u8>>),
    stitch: &mut Stitch<'_>,
) -> Result<(), LogError> {
    let mut parsed: Vec<Parsed> = Vec::new();
    let mut spare: Vec<Parsed> = Vec::new();
    loop {
        let mut group: Vec<Message> = Vec::with_capacity(PARSE_GROUP);
        if let Ok(first) = blocks.recv() {
            group.push(first);
        }
        while group.len() < PARSE_GROUP
            && let Ok(more) = blocks.try_recv()
        {
            group.push(more);
        }
        let (next, stitched) = if on_pool() {
            let stitched = stitch_group(&parsed, stitch);
            (
                parse_group(layout, &group, std::mem::take(&mut spare)),
                stitched,
            )
        } else {
            rayon::join(
                || parse_group(layout, &group, std::mem::take(&mut spare)),
                || stitch_group(&parsed, stitch),
            )
        };
        stitched?;
        for block in group.drain(..).flatten() {
            // The reader may have stopped; a buffer it does not take is dropped.
            let _ = used.send(block.bytes);
        }
        if next.is_empty() {
            return Ok(());
        }
        spare = std::mem::replace(&mut parsed, next);
    }
}

/// Streams the accelerometer log `source` once: every row checked (format, increasing time
/// stamps), the steps counted, and the log reduced between the `gps` fixes for either Δt mode
/// (`nominal_dt_s` the configured step, NaN when none is, `bias` the filter's bias model for the
/// per-step units). Starts eq. (3) from `start` at the first sample.
///
/// # Errors
/// [`LogError`] naming the line of the first malformed row or time stamp not after the
/// previous one, or the file when it holds fewer than two samples.
pub fn reduce(
    source: &dyn LogSource,
    gps: &[GpsFix],
    (nominal_dt_s, bias): (f64, BiasModel),
    start: Start,
) -> Result<Reduced, LogError> {
    let mut stitch = Stitch::new(source.name(), gps, (nominal_dt_s, bias), start);
    if let Some((times_s, samples_m_s2)) = source.accel_columns() {
        // Arrays: every sample checked as a row of text is, in place (sample i is line i + 2).
        for (i, (&t_s, &accel_m_s2)) in times_s.iter().zip(samples_m_s2).enumerate() {
            let line = i as u64 + 2;
            for (column, x) in [(ACCEL_COLUMNS[0], t_s), (ACCEL_COLUMNS[1], accel_m_s2)] {
                if !x.is_finite() {
                    let problem = LogProblem::NotFinite {
                        column,
                        text: x.to_string(),
                    };
                    return Err(LogError::at(source.name(), line, problem));
                }
            }
            stitch.row(t_s, accel_m_s2, line)?;
        }
        return stitch.finish();
    }
    let (layout, mut feed) = open_blocks(source, ACCEL_COLUMNS)?;
    let (tx, rx) = mpsc::sync_channel::<Message>(2 * PARSE_GROUP);
    let (used_tx, used) = mpsc::channel::<Vec<u8>>();
    std::thread::scope(|scope| {
        let (layout, stitch) = (&layout, &mut stitch);
        let pool = rayon::current_thread_index().is_some();
        let worker = scope.spawn(move || {
            ON_POOL.with(|p| p.set(pool));
            stitch_all(layout, (&rx, &used_tx), stitch)
        });
        // The reading stays on this thread (a source need not be sendable); it stops when the
        // text ends, fails, or the stitching stopped at a problem.
        loop {
            let buffer = used.try_recv().unwrap_or_default();
            let message = feed.next_block_in(buffer, BLOCK_BYTES, MAX_LINE_BYTES);
            let stop = !matches!(message, Ok(Some(_)));
            if tx
                .send(message.transpose().unwrap_or(Ok(Block::default())))
                .is_err()
                || stop
            {
                break;
            }
        }
        drop(tx);
        worker.join().expect("the stitching does not panic")
    })?;
    stitch.finish()
}

fn too_few(file: &str, found: u64) -> LogError {
    LogError::of_file(file, LogProblem::TooFewRows { found, needed: 2 })
}
