//! `allan --imu` on a log read once and held, or read twice and held nowhere.
//!
//! - A log of at most the rows the caller lets it hold ([`DEFAULT_HOLD_BYTES`], 64 bytes a
//!   six-channel row: the stamp, its place and the values, [`held_row_bytes`]) is read once
//!   into memory and analysed as the whole-series form does (`analyse_held`, as
//!   [`super::analyse_imu`]).
//! - A longer one is read twice: a first read finds each channel's mean (the phase subtracts
//!   it, as the whole-series form does), the count and the median step, a second checks every
//!   step against that median and feeds each channel's [`AllanStream`]. Memory is that of the
//!   streams (the window of [`stream::EXACT_MAX_M`](crate::allan::stream::EXACT_MAX_M) phase
//!   points per channel; a longer log's phase goes to a temporary file), whatever the log's
//!   length.
//!
//! Either way every τ is the whole-series analysis's, bit for bit, and the errors are the same,
//! in the same order: a malformed record first, then a step outside the accepted band around
//! the median.

use rayon::prelude::*;

use super::held::{checked, held_read};
use super::{ChannelAnalysis, ImuAnalysis, ImuError, analyse_held};
use crate::allan::stream::{AllanStream, StreamingMean};
use crate::allan::{AllanError, analyse_grid};
use crate::input::csv::steps::{ACCEPTED_STEP_RATIO, StepMedian};
use crate::input::records::ImuRecords;
use crate::input::{LogError, LogProblem};

/// Samples of each channel handed to the streams at once.
const BATCH: usize = 1 << 16;

/// The memory a log may be held in by default, bytes: 4.2·10⁶ six-channel rows,
/// 2.9 hours at 400 Hz.
pub const DEFAULT_HOLD_BYTES: usize = 256 << 20;

/// Bytes a held row of `channels` channels takes: its stamp, its place in the log and a value
/// per channel (64 for six).
pub const fn held_row_bytes(channels: usize) -> usize {
    8 + 8 + 8 * channels
}

/// Why a streamed analysis stopped.
#[derive(Debug)]
pub enum StreamError {
    /// The log.
    Log(LogError),
    /// A channel the analysis cannot use.
    Channel(ImuError),
    /// The temporary file of a long log's phase (creating, writing or reading it).
    Spill(std::io::Error),
}

/// What the first read finds: each channel's mean and whether its samples differ, the count
/// and the median step, s.
type FirstRead = (Vec<f64>, Vec<bool>, usize, f64);

/// The first read: each channel's mean, whether its samples differ, and the median step, s, the
/// stamps and values checked.
fn first_read(records: &dyn ImuRecords) -> Result<FirstRead, LogError> {
    let mut means = vec![StreamingMean::default(); records.channels().len()];
    let mut first: Option<[f64; 6]> = None;
    let mut distinct = vec![false; records.channels().len()];
    let mut steps = StepMedian::new();
    let mut previous_s = None;
    records.read(&mut |r| {
        if let Some(step_s) = checked(records, r, &mut previous_s)? {
            steps.add(step_s);
        }
        let first = first.get_or_insert(r.values);
        for (k, (m, v)) in means.iter_mut().zip(&r.values).enumerate() {
            m.push(*v);
            distinct[k] |= *v != first[k];
        }
        Ok(())
    })?;
    let Some(median_s) = steps.median() else {
        let problem = LogProblem::TooFewRows {
            found: means.first().map_or(0, StreamingMean::count),
            needed: 2,
        };
        return Err(records.error(problem));
    };
    let samples = means.first().map_or(0, StreamingMean::count) as usize;
    let means = means.iter().map(StreamingMean::mean).collect();
    Ok((means, distinct, samples, median_s))
}

/// Analyses every channel of `records` at `confidence`: read once and held when the log takes
/// at most `hold_bytes` ([`held_row_bytes`] a row), else read twice, the phase of a log with τ
/// beyond the streams' window written to a temporary file in `spill_dir`.
///
/// # Errors
/// [`StreamError::Log`] for the first problem of the log (as the whole-series readers tell
/// it: a malformed row first, then a step outside the accepted band around the median),
/// [`StreamError::Channel`] naming the first channel the analysis cannot use,
/// [`StreamError::Spill`] for the temporary file.
pub fn analyse_records(
    records: &dyn ImuRecords,
    confidence: f64,
    spill_dir: &std::path::Path,
    hold_bytes: usize,
) -> Result<ImuAnalysis, StreamError> {
    let row_bytes = held_row_bytes(records.channels().len());
    let Some(held) = held_read(records, hold_bytes / row_bytes).map_err(StreamError::Log)? else {
        return analyse_streamed(records, confidence, spill_dir);
    };
    let (channels, median_s) = held.check_steps(records).map_err(StreamError::Log)?;
    analyse_held(channels, median_s, confidence).map_err(StreamError::Channel)
}

/// [`analyse_records`] reading the log twice, holding none of it.
fn analyse_streamed(
    records: &dyn ImuRecords,
    confidence: f64,
    spill_dir: &std::path::Path,
) -> Result<ImuAnalysis, StreamError> {
    let channels = records.channels().to_vec();
    let (means, distinct, count, median_s) = first_read(records).map_err(StreamError::Log)?;
    let (lo, hi) = (
        ACCEPTED_STEP_RATIO.0 * median_s,
        ACCEPTED_STEP_RATIO.1 * median_s,
    );
    let mut streams: Vec<AllanStream> = means
        .into_iter()
        .map(|mean| AllanStream::new(mean, count, spill_dir))
        .collect::<Result<_, _>>()
        .map_err(StreamError::Spill)?;
    // The second read on this thread, the streams on the others: batches handed over a queue
    // of two, so that reading and summing overlap.
    let (send, receive) = std::sync::mpsc::sync_channel::<Vec<Vec<f64>>>(2);
    let read = std::thread::scope(|scope| {
        let summing = scope.spawn(|| {
            for batch in receive {
                streams
                    .par_iter_mut()
                    .zip(batch.par_iter())
                    .for_each(|(s, b)| s.extend(b));
            }
        });
        let empty = || vec![Vec::with_capacity(BATCH); channels.len()];
        let mut batch = empty();
        let mut previous_s: Option<f64> = None;
        let read = records.read(&mut |r| {
            if let Some(p) = previous_s.replace(r.t_s) {
                let step_s = r.t_s - p;
                if !(lo..=hi).contains(&step_s) {
                    let problem = LogProblem::Gap {
                        previous_s: p,
                        t_s: r.t_s,
                        step_s,
                        ratio: step_s / median_s,
                        median_s,
                    };
                    return Err(records.error_at(r.at, problem));
                }
            }
            for (b, v) in batch.iter_mut().zip(&r.values) {
                b.push(*v);
            }
            if batch[0].len() == BATCH {
                // The receiver lives until every batch is sent.
                send.send(std::mem::replace(&mut batch, empty()))
                    .expect("the summing thread receives");
            }
            Ok(())
        });
        if read.is_ok() {
            send.send(batch).expect("the summing thread receives");
        }
        drop(send);
        summing.join().expect("the summing thread does not panic");
        read
    });
    read.map_err(StreamError::Log)?;
    let samples = streams.first().map_or(0, AllanStream::samples);
    let grids: Vec<_> = streams
        .into_par_iter()
        .map(AllanStream::finish)
        .collect::<Result<_, _>>()
        .map_err(StreamError::Spill)?;
    let analyses = grids
        .par_iter()
        .zip(channels.par_iter())
        .zip(distinct.par_iter())
        .map(|((grid, &channel), &distinct)| {
            analyse_channel(grid, channel, distinct, (samples, median_s), confidence)
        })
        .collect::<Result<_, _>>()
        .map_err(StreamError::Channel)?;
    Ok(ImuAnalysis {
        samples,
        sample_period_s: median_s,
        confidence,
        channels: analyses,
    })
}

/// One channel's analysis from its grid, for `samples` samples τ₀ = `tau0_s` apart; a channel
/// whose samples are not `distinct` (all one number) is refused as constant.
fn analyse_channel(
    grid: &[(usize, f64, Option<crate::allan::NoiseId>)],
    channel: crate::input::records::Channel,
    distinct: bool,
    (samples, tau0_s): (usize, f64),
    confidence: f64,
) -> Result<ChannelAnalysis, ImuError> {
    let analysis = if distinct {
        analyse_grid(grid, samples, tau0_s, confidence)
    } else {
        Err(AllanError::Constant)
    };
    analysis
        .map(|analysis| ChannelAnalysis { channel, analysis })
        .map_err(|reason| ImuError {
            column: channel.column(),
            reason,
        })
}
