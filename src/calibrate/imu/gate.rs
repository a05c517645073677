//! What the χ² innovation gate did on a recording (`[filter] innovation_gate = true`): each
//! rejected fix with its line, time, NIS against the threshold, and the component whose
//! normalized innovation is largest, beside the count that chance alone explains (α of the
//! fixes tested, under the filter's model).

use serde::Serialize;

use super::Settings;
use super::step::{COMPONENTS, FixRecord};
use crate::ins::measurement::Gate;

/// One fix the gate rejected.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RejectedFix {
    /// The fix's line in the GNSS log.
    pub line: u64,
    /// Its time, s.
    pub t_s: f64,
    /// Its NIS.
    pub nis: f64,
    /// The gate's threshold for its rows.
    pub threshold: f64,
    /// The component of the largest |ν|/√S (`position_n`, …, `velocity_d`).
    pub component: &'static str,
    /// That component's |ν|/√S.
    pub normalized: f64,
}

/// The gate's record in `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GateRecord {
    /// Whether the gate tested the fixes.
    pub enabled: bool,
    /// Its false-alarm rate α per fix.
    pub false_alarm_rate: f64,
    /// The fixes it tested.
    pub tested: usize,
    /// α × tested: the rejections a filter whose model holds makes by chance.
    pub expected_by_chance: f64,
    /// The fixes it rejected, in time order.
    pub rejected: Vec<RejectedFix>,
}

/// The gate's record of the fixes `records` filtered under `s`.
pub fn record<const N: usize>(records: &[FixRecord<N>], s: &Settings) -> GateRecord {
    let gate = s.innovation_gate.then(|| Gate::new(s.false_alarm_rate));
    let rejected = records
        .iter()
        .filter(|r| !r.accepted)
        .map(|r| {
            let (i, normalized) = (0..6)
                .filter(|&i| r.innovation[i].is_finite())
                .map(|i| (i, (r.innovation[i] / r.innovation_sigma[i]).abs()))
                .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
            RejectedFix {
                line: r.line,
                t_s: r.t_s,
                nis: r.nis,
                threshold: gate.map_or(f64::INFINITY, |g| g.threshold(r.rows)),
                component: COMPONENTS[i],
                normalized,
            }
        })
        .collect();
    let tested = if s.innovation_gate { records.len() } else { 0 };
    GateRecord {
        enabled: s.innovation_gate,
        false_alarm_rate: s.false_alarm_rate,
        tested,
        expected_by_chance: s.false_alarm_rate * tested as f64,
        rejected,
    }
}
