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

use crate::logs::block::{BLOCK_BYTES, Block, Layout, MAX_LINE_BYTES, Rows, parse_block};
use crate::logs::read::{LogSource, open_blocks};
use crate::logs::steps::{StepAt, StepMedian};
use crate::logs::{ACCEL_COLUMNS, GpsFix, LogError, LogProblem};
use crate::state::BiasModel;

pub use super::units::NoiseUnits;

/// Relative tolerance within which every step of a log must equal the configured Δt for the
/// nominal recursion to run: time stamps written as j·Δt differ from j·Δt by a rounding error.
pub const NOMINAL_TOLERANCE: f64 = 1e-9;

/// Blocks parsed together, one per thread or more: a bound on the text held at once.
const PARSE_GROUP: usize = 4;

/// Integrated accelerometer (p_c, v_c), (m, m/s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integrated {
    /// p_c, m.
    pub pc_m: f64,
    /// v_c, m/s.
    pub vc_m_s: f64,
}

impl Integrated {
    /// eq. (3) over a step of `dt` with `half_dt2` = Δt²/2, written as the simulation does.
    #[inline]
    fn advance(&mut self, a: f64, dt: f64, half_dt2: f64) {
        self.pc_m += self.vc_m_s * dt + a * half_dt2;
        self.vc_m_s += a * dt;
    }

    fn is_finite(&self) -> bool {
        self.pc_m.is_finite() && self.vc_m_s.is_finite()
    }
}

/// A GPS fix at the accelerometer sample nearest to it (the earlier one of a tie).
#[derive(Clone, Debug, PartialEq)]
pub struct FixAt {
    /// Index of the fix in the GPS log.
    pub fix: usize,
    /// Index of the sample.
    pub sample: u64,
    /// Its time stamp, s.
    pub t_s: f64,
    /// Its line in the accelerometer log.
    pub line: u64,
    /// |t_fix − t_sample|, s.
    pub distance_s: f64,
    /// The samples around the fix: the time stamp before it, and the sample after it.
    pub before_s: f64,
    /// Index and time stamp of the sample after the fix, if any.
    pub after: Option<(u64, f64)>,
    /// (p_c, v_c) at the sample with the nominal Δt and with each step's own.
    pub integrated: [Integrated; 2],
    /// The per-step process noise since the previous fix's sample (the log's first).
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
    /// The steps' histogram, with the first step of each key.
    pub median: StepMedian,
    /// The shortest and the longest step.
    pub step_range: (StepAt, StepAt),
    /// Whether every step equals the nominal Δt within [`NOMINAL_TOLERANCE`].
    pub nominal: bool,
    /// Every fix at its sample, in the GPS log's order.
    pub fixes: Vec<FixAt>,
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
    k: u64,
    current: Option<Current>,
    before_s: f64,
    integrated: [Integrated; 2],
    units: NoiseUnits,
    reduced: Reduced,
    file: String,
}

impl Stitch<'_> {
    /// Assigns to the current sample every remaining fix nearer to it than to the next sample
    /// at `next_s` (all of them at the last sample).
    fn assign(&mut self, c: Current, next_s: Option<f64>) {
        while let Some(f) = self.gps.get(self.reduced.fixes.len()) {
            let d = (f.t_s - c.t_s).abs();
            if next_s.is_some_and(|n| d > (n - f.t_s).abs()) {
                break;
            }
            let (before_s, after) = if f.t_s >= c.t_s {
                (c.t_s, next_s.map(|n| (self.k + 1, n)))
            } else {
                (self.before_s, Some((self.k, c.t_s)))
            };
            let fix = FixAt {
                fix: self.reduced.fixes.len(),
                sample: self.k,
                t_s: c.t_s,
                line: c.line,
                distance_s: d,
                before_s,
                after,
                integrated: self.integrated,
                units: std::mem::take(&mut self.units),
            };
            self.reduced.fixes.push(fix);
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
            (self.before_s, self.reduced.span_s, self.reduced.first_line) = (t_s, (t_s, t_s), line);
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
        if self.reduced.fixes.len() < self.gps.len() {
            self.assign(c, Some(t_s));
        }
        let a = c.accel_m_s2;
        self.integrated[0].advance(a, self.dt_s, self.half_dt2_s2);
        self.integrated[1].advance(a, step, 0.5 * step * step);
        self.units.add_step(step);
        if self.bias.drifts() {
            self.units.add_bias_step(step, self.bias);
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
        (self.before_s, self.current, self.k) = (c.t_s, Some(next), self.k + 1);
        Ok(())
    }

    fn rows(&mut self, rows: &Rows<2>) -> Result<(), LogError> {
        for (&[t_s, a], &line) in rows.values.iter().zip(&rows.lines) {
            self.row(t_s, a, line)?;
        }
        Ok(())
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
/// (`nominal_dt_s` the configured step, `bias` the filter's bias model for the per-step units).
/// Starts eq. (3) from `start` = (p_c(0), v_c(0)).
///
/// # Errors
/// [`LogError`] naming the line of the first malformed row or time stamp not after the
/// previous one, or the file when it holds fewer than two samples.
pub fn reduce(
    source: &dyn LogSource,
    gps: &[GpsFix],
    (nominal_dt_s, bias): (f64, BiasModel),
    start: Integrated,
) -> Result<Reduced, LogError> {
    let (layout, mut feed) = open_blocks(source, ACCEL_COLUMNS)?;
    let empty = StepAt {
        previous_s: 0.0,
        t_s: f64::INFINITY,
        ..StepAt::default()
    };
    let mut stitch = Stitch {
        dt_s: nominal_dt_s,
        bias,
        half_dt2_s2: 0.5 * nominal_dt_s * nominal_dt_s,
        gps,
        k: 0,
        current: None,
        before_s: 0.0,
        integrated: [start; 2],
        units: NoiseUnits::default(),
        reduced: Reduced {
            samples: 0,
            span_s: (0.0, 0.0),
            first_line: 0,
            median: StepMedian::new(),
            step_range: (empty, StepAt::default()),
            nominal: true,
            fixes: Vec::with_capacity(gps.len()),
            end: Default::default(),
            overflow: [None; 2],
        },
        file: source.name().to_string(),
    };
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
    let Some(last) = stitch.current else {
        return Err(too_few(source.name(), 0));
    };
    stitch.assign(last, None);
    stitch.reduced.samples = stitch.k + 1;
    if stitch.k == 0 {
        return Err(too_few(source.name(), 1));
    }
    stitch.reduced.span_s.1 = last.t_s;
    stitch.reduced.end = (stitch.integrated, stitch.units);
    Ok(stitch.reduced)
}

fn too_few(file: &str, found: u64) -> LogError {
    LogError::of_file(file, LogProblem::TooFewRows { found, needed: 2 })
}
