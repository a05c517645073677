//! The engines and the sums of one chunk: its lane groups advanced fix by fix, their lane sums
//! reduced per fix, its residual rows added to the packed triangle at the end.

use super::epoch::{self, EpochGroup, EpochPlan};
use super::kernel::{LaneGroup, SampleGroup};
use super::lane_sums::LaneSums;
use super::sums::{Accumulator, PANEL};
use crate::config::TruthModel;
use crate::filter::FilterSchedule;
use crate::lanes::LANES;
use crate::model::Model;
use crate::simulation::stream_key;

/// How an ensemble's realizations are simulated.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Every accelerometer sample drawn and integrated, as the problem statement describes it.
    #[default]
    Sample,
    /// One exact draw of the accelerometer noise's effect per GPS interval (see [`epoch`]): the
    /// same distribution at the fixes with about a tenth of the random numbers.
    Epoch,
}

impl Engine {
    /// The lowercase name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Sample => "sample",
            Engine::Epoch => "epoch",
        }
    }
}

impl std::fmt::Display for Engine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What an engine needs besides the model, built once per ensemble.
#[derive(Clone, Debug)]
pub enum Prepared {
    /// The per-sample engine needs nothing more.
    Sample,
    /// The epoch engine's plan.
    Epoch(EpochPlan),
}

impl Prepared {
    /// Prepares `engine` for `model` under `schedule`.
    pub fn new(engine: Engine, model: &Model, schedule: &FilterSchedule) -> Self {
        match engine {
            Engine::Sample => Prepared::Sample,
            Engine::Epoch => Prepared::Epoch(EpochPlan::new(model, schedule)),
        }
    }

    /// The engine.
    pub fn engine(&self) -> Engine {
        match self {
            Prepared::Sample => Engine::Sample,
            Prepared::Epoch(_) => Engine::Epoch,
        }
    }
}

/// Sums realizations `range` of `model` into a fresh accumulator, with the per-sample engine.
pub fn accumulate(
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    range: std::ops::Range<u64>,
) -> Accumulator {
    accumulate_with(&Prepared::Sample, model, schedule, seed, range)
}

crate::lanes::vectorized! {
    /// Sums realizations `range` of `model` into `acc` (emptied first) with the engine
    /// `prepared`; `rows` is scratch space. The realizations go in lane groups of [`LANES`]
    /// consecutive indices from `range.start`, all advanced fix by fix: at each fix every lane
    /// adds its realization into its own sums, and the lanes are added up in lane order when
    /// every group has passed the fix. The residual products of the chunk are summed in one
    /// pass over its stacked residuals.
    pub fn accumulate_into(
        prepared: &Prepared,
        model: &Model,
        schedule: &FilterSchedule,
        seed: u64,
        range: std::ops::Range<u64>,
        acc: &mut Accumulator,
        rows: &mut Vec<f64>,
    ) -> () => accumulate_lanes
}

/// Sums realizations `range` of `model` into a fresh accumulator with the engine `prepared`
/// (see [`accumulate_into`]).
pub fn accumulate_with(
    prepared: &Prepared,
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    range: std::ops::Range<u64>,
) -> Accumulator {
    let mut acc = Accumulator::new(&super::layout_of(model), model.residual_pair);
    accumulate_into(
        prepared,
        model,
        schedule,
        seed,
        range,
        &mut acc,
        &mut Vec::new(),
    );
    acc
}

#[inline(always)]
fn accumulate_lanes(
    prepared: &Prepared,
    model: &Model,
    schedule: &FilterSchedule,
    seed: u64,
    range: std::ops::Range<u64>,
    acc: &mut Accumulator,
    rows: &mut Vec<f64>,
) {
    let key = stream_key(seed, model.case());
    let groups = (range.start..range.end).step_by(LANES).map(|first| {
        let active = (range.end - first).min(LANES as u64) as usize;
        (first, active)
    });
    match (prepared, model.truth()) {
        (Prepared::Sample, TruthModel::Euler) => {
            let g = groups.map(|(f, a)| SampleGroup::<true>::new(model, key, f, a));
            sum_groups(g.collect(), schedule, acc, rows);
        }
        (Prepared::Sample, TruthModel::Analytic) => {
            let g = groups.map(|(f, a)| SampleGroup::<false>::new(model, key, f, a));
            sum_groups(g.collect(), schedule, acc, rows);
        }
        (Prepared::Epoch(plan), _) => {
            let key = epoch::epoch_key(key);
            let g = groups.map(|(f, a)| EpochGroup::new(plan, model, key, f, a));
            sum_groups(g.collect(), schedule, acc, rows);
        }
    }
    acc.count = range.end - range.start;
}

#[inline(always)]
fn sum_groups<G: LaneGroup>(
    mut groups: Vec<G>,
    schedule: &FilterSchedule,
    acc: &mut Accumulator,
    rows: &mut Vec<f64>,
) {
    let m = 2 * schedule.fixes.len();
    acc.clear_but_products();
    let count = groups.len() * LANES;
    let width = PANEL * count;
    // Every entry is written below but the padding beyond component m − 1, zeroed here.
    rows.resize(m.div_ceil(PANEL) * width, 0.0);
    if !m.is_multiple_of(PANEL) {
        let last = &mut rows[(m / PANEL) * width..];
        for q in 0..count {
            last[q * PANEL + m % PANEL..(q + 1) * PANEL].fill(0.0);
        }
    }
    let mut lanes = LaneSums::new(schedule);
    for (i, fix) in schedule.fixes.iter().enumerate() {
        for (g, group) in groups.iter_mut().enumerate() {
            let f = group.next_fix(i, fix);
            lanes.add(i, &f);
            // Components 2i and 2i + 1 of realization q = g·LANES + k, in panel layout.
            for (c, r) in [2 * i, 2 * i + 1].into_iter().zip(&f.residual) {
                let base = (c / PANEL) * width + g * LANES * PANEL + c % PANEL;
                for k in 0..LANES {
                    rows[base + k * PANEL] = r.0[k];
                }
            }
        }
        lanes.finish_fix(&mut acc.fixes[i]);
    }
    acc.set_residual_products(rows, count);
}
