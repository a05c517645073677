//! The engines, and the sums of a range of realizations (a block): pass after pass of [`PASS`]
//! realizations, chunk after chunk within a pass; a chunk's lane groups are advanced fix by fix
//! and their lane sums added up at every fix, its residuals written into the pass's panels; a
//! pass's residual products are added to the tiles, unpacked into the sums when the range is done.

use super::epoch::{self, EpochGroup, EpochPlan};
use super::kernel::{LaneGroup, SampleGroup};
use super::lane_sums::LaneSums;
use super::sums::Accumulator;
use super::tiles::{self, PASS};
use super::{CHUNK, Ensemble};
use crate::config::TruthModel;
use crate::filter::FilterSchedule;
use crate::lanes::{LANES, Lanes};
use crate::model::Model;
use crate::simulation::stream_key;
use crate::state::ErrorState;

/// How an ensemble's realizations are simulated.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
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
pub(super) enum Prepared {
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

/// Scratch space of [`accumulate_into`], reused from call to call: the residual-product tiles of
/// the sums being made, the panels of a pass's stacked residuals, the lane sums and the single
/// pair's residuals.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    tiles: Vec<f64>,
    panels: Vec<f32>,
    lanes: LaneSums,
    /// Per lane group, the residuals at the fixes i and m of the single pair (see
    /// [`Accumulator::pair`]).
    pair: Vec<[[Lanes; ErrorState::MEAS]; 2]>,
}

crate::lanes::vectorized! {
    /// Sums realizations `range` of `ensemble` (its model, engine and seed) into `acc`, whose
    /// previous numbers are all overwritten, in passes of [`PASS`] realizations from
    /// `range.start` and chunks of [`CHUNK`] within a pass, in order. A chunk's realizations go
    /// in lane groups of [`LANES`], all advanced fix by fix: at each fix every lane adds its
    /// realization into its own sums, and the lanes are added up in lane order, onto the sums
    /// so far, when every group has passed the fix. A pass's residual products are then added
    /// in one sweep over its stacked residuals (see `tiles`).
    pub(super) fn accumulate_into(
        ensemble: &Ensemble<'_>,
        range: std::ops::Range<u64>,
        acc: &mut Accumulator,
        scratch: &mut Scratch,
    ) -> () => accumulate_lanes
}

#[inline(always)]
fn accumulate_lanes(
    ensemble: &Ensemble<'_>,
    range: std::ops::Range<u64>,
    acc: &mut Accumulator,
    scratch: &mut Scratch,
) {
    let (model, schedule) = (ensemble.model(), ensemble.schedule);
    acc.clear_but_products();
    let Scratch {
        tiles,
        panels,
        lanes,
        pair,
    } = scratch;
    // The first pass overwrites the tiles; with no pass at all they must read zero.
    tiles.resize(tiles::tiles_len(&acc.layout), 0.0);
    if range.is_empty() {
        tiles.fill(0.0);
    }
    lanes.set_weights(schedule);
    let m = ErrorState::MEAS * schedule.fixes.len();
    let key = stream_key(ensemble.seed, model.case());
    for pass_start in range.clone().step_by(PASS as usize) {
        let pass = pass_start..(pass_start + PASS).min(range.end);
        let count = (pass.end - pass.start).div_ceil(LANES as u64) as usize * LANES;
        // Every entry is written below but the padding beyond component m − 1, zeroed here.
        panels.resize(tiles::panels_len(m, count), 0.0);
        tiles::zero_padding(panels, m, count);
        for start in pass.clone().step_by(CHUNK as usize) {
            let chunk = start..(start + CHUNK).min(pass.end);
            let out = Panels {
                panels,
                first: (start - pass.start) as usize,
                count,
            };
            let sums = ChunkSums {
                schedule,
                acc: &mut *acc,
                lanes: &mut *lanes,
                out,
                pair: &mut *pair,
            };
            sum_chunk(&ensemble.prepared, model, key, chunk, sums);
        }
        tiles::add_products(&acc.layout, tiles, panels, count, pass_start == range.start);
    }
    acc.count = range.end - range.start;
    tiles::unpack(&acc.layout, tiles, &mut acc.residual_products);
}

/// Sums the realizations `chunk` of `model` under the stream key `key`, simulated by `prepared`,
/// into `sums`.
#[inline(always)]
fn sum_chunk(
    prepared: &Prepared,
    model: &Model,
    key: u64,
    chunk: std::ops::Range<u64>,
    sums: ChunkSums,
) {
    let groups = chunk.clone().step_by(LANES).map(|first| {
        let active = (chunk.end - first).min(LANES as u64) as usize;
        (first, active)
    });
    match (prepared, model.truth()) {
        (Prepared::Sample, TruthModel::Euler) => {
            let g = groups.map(|(f, a)| SampleGroup::<true>::new(model, key, f, a));
            sum_groups(g.collect(), sums);
        }
        (Prepared::Sample, TruthModel::Analytic) => {
            let g = groups.map(|(f, a)| SampleGroup::<false>::new(model, key, f, a));
            sum_groups(g.collect(), sums);
        }
        (Prepared::Epoch(plan), _) => {
            let key = epoch::epoch_key(key);
            let g = groups.map(|(f, a)| EpochGroup::new(plan, model, key, f, a));
            sum_groups(g.collect(), sums);
        }
    }
}

/// Where a chunk's sums go: the per-fix sums and the single pair's products of `acc` (through
/// the lane sums `lanes`), its residuals into the panels `out` and, for the single pair, `pair`.
struct ChunkSums<'s> {
    schedule: &'s FilterSchedule,
    acc: &'s mut Accumulator,
    lanes: &'s mut LaneSums,
    out: Panels<'s>,
    pair: &'s mut Vec<[[Lanes; ErrorState::MEAS]; 2]>,
}

/// Where a chunk's residuals go: the panels of a pass of `count` realizations, from the pass's
/// realization `first` on.
struct Panels<'a> {
    panels: &'a mut [f32],
    first: usize,
    count: usize,
}

/// Adds one chunk, the lane groups `groups`, to the per-fix sums and to the single residual
/// pair's products of `sums`, and writes its residuals into its panels, in single precision.
#[inline(always)]
fn sum_groups<G: LaneGroup>(mut groups: Vec<G>, sums: ChunkSums) {
    let ChunkSums {
        schedule,
        acc,
        lanes,
        out,
        pair,
    } = sums;
    let count = groups.len() * LANES;
    pair.resize(groups.len(), Default::default());
    let [pm, pi] = acc.pair;
    for (i, fix) in schedule.fixes.iter().enumerate() {
        for (g, group) in groups.iter_mut().enumerate() {
            let f = group.next_fix(i, fix);
            if g == 0 {
                lanes.add::<true>(i, &f);
            } else {
                lanes.add::<false>(i, &f);
            }
            let first = ErrorState::MEAS * i;
            for (c, r) in (first..first + ErrorState::MEAS).zip(&f.residual) {
                for k in 0..LANES {
                    let q = out.first + g * LANES + k;
                    out.panels[tiles::panel_index(c, q, out.count)] = r.0[k] as f32;
                }
            }
            // The residuals of the statement's single pair, kept in double precision.
            for (slot, fix_index) in [pi, pm].into_iter().enumerate() {
                if i == fix_index {
                    pair[g][slot] = f.residual;
                }
            }
        }
        lanes.finish_fix(i, &mut acc.fixes[i]);
    }
    for q in 0..count {
        let [at_i, at_m] = &pair[q / LANES];
        for (j, r_i) in at_i.iter().enumerate() {
            for (k, r_m) in at_m.iter().enumerate() {
                acc.pair_products[(j, k)] += r_i.0[q % LANES] * r_m.0[q % LANES];
            }
        }
    }
}
