//! A log of at most the rows the caller lets it hold, read once in blocks
//! ([`ImuRecords::read_blocks`]) and held: its stamps and each channel's values, every stamp and
//! value checked as the record-by-record read checks them ([`checked`]), the errors the same
//! and in the same order. Each channel's values are held one place in, so that the channel's
//! phase is summed over them where they are ([`crate::allan::analyse_in_place`]).

use crate::input::csv::steps::{ACCEPTED_STEP_RATIO, StepMedian};
use crate::input::records::{Channel, ImuRecords, Record, RecordBlock};
use crate::input::{LogError, LogProblem};

/// The checks of one read: strictly increasing stamps, finite values.
pub(super) fn checked(
    records: &dyn ImuRecords,
    r: &Record,
    previous_s: &mut Option<f64>,
) -> Result<Option<f64>, LogError> {
    if let Some(p) = *previous_s
        && r.t_s <= p
    {
        let problem = LogProblem::NotIncreasing {
            t_s: r.t_s,
            previous_s: p,
        };
        return Err(records.error_at(r.at, problem));
    }
    for (c, v) in records.channels().iter().zip(&r.values) {
        if !v.is_finite() {
            let problem = LogProblem::NotFinite {
                column: c.column(),
                text: v.to_string(),
            };
            return Err(records.error_at(r.at, problem));
        }
    }
    Ok(previous_s.replace(r.t_s).map(|p| r.t_s - p))
}

/// [`checked`] of the first `take` records of `block`: the first problem, as record by record.
fn checked_block(
    records: &dyn ImuRecords,
    block: &RecordBlock,
    take: usize,
    previous_s: &mut Option<f64>,
) -> Result<(), LogError> {
    let (t, values) = (&block.t_s[..take], &block.values[..take]);
    let present = records.channels().len().min(6);
    // One pass that finds whether any record fails; the failing one is then found as
    // record by record.
    let mut bad = matches!((*previous_s, t.first()), (Some(p), Some(&t0)) if t0 <= p);
    for w in t.windows(2) {
        bad |= w[1] <= w[0];
    }
    if present == 6 {
        for v in values.as_flattened() {
            bad |= !v.is_finite();
        }
    } else {
        for row in values {
            for v in &row[..present] {
                bad |= !v.is_finite();
            }
        }
    }
    if bad {
        for (i, (&t_s, &values)) in t.iter().zip(values).enumerate() {
            let at = block.at + i as u64;
            checked(records, &Record { t_s, values, at }, previous_s)?;
        }
    }
    if let Some(&last) = t.last() {
        *previous_s = Some(last);
    }
    Ok(())
}

/// Each channel and its values one place in (the first place free), and the median step, s.
pub(super) type HeldChannels = (Vec<(Channel, Vec<f64>)>, f64);

/// A log held whole: its stamps, where each block of them starts (its row, its `at`), each
/// channel's values one place in (the first place free for the phase).
pub(super) struct Held {
    t_s: Vec<f64>,
    starts: Vec<(usize, u64)>,
    values: Vec<Vec<f64>>,
    channels: Vec<Channel>,
}

/// The log read once and held, its stamps and values checked; `None` once it has more than
/// `max_rows` rows (the read stops there).
///
/// # Errors
/// The reading's first problem, or the first stamp or value [`checked`] refuses.
pub(super) fn held_read(
    records: &dyn ImuRecords,
    max_rows: usize,
) -> Result<Option<Held>, LogError> {
    let channels = records.channels().to_vec();
    // The summary's count, if any, within what may be held: the columns never grow by copying.
    let rows = records.count_hint().map_or(0, |n| {
        usize::try_from(n).unwrap_or(usize::MAX).min(max_rows)
    });
    let column = || {
        let mut v = Vec::with_capacity(rows + 1);
        v.push(0.0);
        v
    };
    let mut held = Held {
        t_s: Vec::with_capacity(rows),
        starts: Vec::new(),
        values: channels.iter().map(|_| column()).collect(),
        channels,
    };
    let mut previous_s = None;
    let mut too_long = false;
    let read = records.read_blocks(&mut |b| {
        let take = b.len().min(max_rows - held.t_s.len());
        checked_block(records, b, take, &mut previous_s)?;
        let follows = held
            .starts
            .last()
            .is_some_and(|&(row, at)| at + (held.t_s.len() - row) as u64 == b.at);
        if take > 0 && !follows {
            held.starts.push((held.t_s.len(), b.at));
        }
        held.t_s.extend_from_slice(&b.t_s[..take]);
        for (k, h) in held.values.iter_mut().enumerate() {
            h.extend(b.values[..take].iter().map(|v| v[k]));
        }
        if take < b.len() {
            // Stops the read; the error itself is never shown.
            too_long = true;
            return Err(records.error(LogProblem::Changed));
        }
        Ok(())
    });
    match read {
        _ if too_long => Ok(None),
        Err(e) => Err(e),
        Ok(()) => Ok(Some(held)),
    }
}

impl Held {
    /// The line or message index of row `row`.
    fn at(&self, row: usize) -> u64 {
        let i = self.starts.partition_point(|&(r, _)| r <= row) - 1;
        let (first, at) = self.starts[i];
        at + (row - first) as u64
    }

    /// Each channel's values one place in (the first place free), and the median step, s;
    /// every step checked against the band around the median.
    ///
    /// # Errors
    /// [`LogProblem::TooFewRows`] for fewer than two rows, [`LogProblem::Gap`] at the first
    /// step outside the band.
    pub(super) fn check_steps(self, records: &dyn ImuRecords) -> Result<HeldChannels, LogError> {
        let mut steps = StepMedian::new();
        for w in self.t_s.windows(2) {
            steps.add(w[1] - w[0]);
        }
        let Some(median_s) = steps.median() else {
            let problem = LogProblem::TooFewRows {
                found: self.t_s.len() as u64,
                needed: 2,
            };
            return Err(records.error(problem));
        };
        let band = ACCEPTED_STEP_RATIO.0 * median_s..=ACCEPTED_STEP_RATIO.1 * median_s;
        for (k, w) in self.t_s.windows(2).enumerate() {
            let step_s = w[1] - w[0];
            if !band.contains(&step_s) {
                let problem = LogProblem::Gap {
                    previous_s: w[0],
                    t_s: w[1],
                    step_s,
                    ratio: step_s / median_s,
                    median_s,
                };
                return Err(records.error_at(self.at(k + 1), problem));
            }
        }
        Ok((
            self.channels.into_iter().zip(self.values).collect(),
            median_s,
        ))
    }
}
