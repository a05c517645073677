//! The engines and the sums of one chunk: its lane groups advanced fix by fix, their lane sums
//! reduced per fix, its residual rows added to the packed triangle at the end.

use super::CHUNK;
use super::epoch::{self, EpochGroup, EpochPlan};
use super::kernel::{LaneGroup, SampleGroup};
use super::lane_sums::LaneSums;
use super::sums::Accumulator;
use super::tiles;
use crate::config::TruthModel;
use crate::filter::FilterSchedule;
use crate::lanes::{LANES, Lanes};
use crate::model::Model;
use crate::simulation::stream_key;

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

/// Scratch space of [`accumulate_into`], reused from call to call: the residual-product tiles of
/// the sums being made, the panels of a chunk's stacked residuals and the lane sums.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    tiles: Vec<f64>,
    panels: Vec<f32>,
    lanes: LaneSums,
    /// Per lane group, the residuals at the fixes i and m of the single pair (see
    /// [`Accumulator::pair`]).
    pair: Vec<[[Lanes; 2]; 2]>,
}

crate::lanes::vectorized! {
    /// Sums realizations `range` of `model` into `acc` (emptied first) with the engine
    /// `prepared`, in chunks of [`CHUNK`] consecutive indices from `range.start`, in order.
    /// A chunk's realizations go in lane groups of [`LANES`], all advanced fix by fix: at each
    /// fix every lane adds its realization into its own sums, and the lanes are added up in lane
    /// order, onto the sums so far, when every group has passed the fix. The chunk's residual
    /// products are then added in one pass over its stacked residuals (see `ensemble::tiles`).
    pub fn accumulate_into(
        prepared: &Prepared,
        model: &Model,
        schedule: &FilterSchedule,
        seed: u64,
        range: std::ops::Range<u64>,
        acc: &mut Accumulator,
        scratch: &mut Scratch,
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
        &mut Scratch::default(),
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
    scratch: &mut Scratch,
) {
    acc.clear_but_products();
    let Scratch {
        tiles,
        panels,
        lanes,
        pair,
    } = scratch;
    // The first chunk overwrites the tiles; with no chunk at all they must read zero.
    tiles.resize(tiles::tiles_len(&acc.layout), 0.0);
    if range.is_empty() {
        tiles.fill(0.0);
    }
    lanes.set_weights(schedule);
    let m = 2 * schedule.fixes.len();
    let key = stream_key(seed, model.case());
    for pass_start in range.clone().step_by(tiles::PASS as usize) {
        let pass = pass_start..(pass_start + tiles::PASS).min(range.end);
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
            let groups = chunk.clone().step_by(LANES).map(|first| {
                let active = (chunk.end - first).min(LANES as u64) as usize;
                (first, active)
            });
            match (prepared, model.truth()) {
                (Prepared::Sample, TruthModel::Euler) => {
                    let g = groups.map(|(f, a)| SampleGroup::<true>::new(model, key, f, a));
                    sum_groups(g.collect(), schedule, acc, lanes, out, pair);
                }
                (Prepared::Sample, TruthModel::Analytic) => {
                    let g = groups.map(|(f, a)| SampleGroup::<false>::new(model, key, f, a));
                    sum_groups(g.collect(), schedule, acc, lanes, out, pair);
                }
                (Prepared::Epoch(plan), _) => {
                    let key = epoch::epoch_key(key);
                    let g = groups.map(|(f, a)| EpochGroup::new(plan, model, key, f, a));
                    sum_groups(g.collect(), schedule, acc, lanes, out, pair);
                }
            }
        }
        tiles::add_products(&acc.layout, tiles, panels, count, pass_start == range.start);
    }
    acc.count = range.end - range.start;
    tiles::unpack(&acc.layout, tiles, &mut acc.residual_products);
}

/// Where a chunk's residuals go: the panels of a pass of `count` realizations, from the pass's
/// realization `first` on.
struct Panels<'a> {
    panels: &'a mut [f32],
    first: usize,
    count: usize,
}

/// Adds one chunk, the lane groups `groups`, to the per-fix sums of `acc` and to its single
/// residual pair's products, and writes its residuals into `out`, in single precision.
#[inline(always)]
fn sum_groups<G: LaneGroup>(
    mut groups: Vec<G>,
    schedule: &FilterSchedule,
    acc: &mut Accumulator,
    lanes: &mut LaneSums,
    out: Panels,
    pair: &mut Vec<[[Lanes; 2]; 2]>,
) {
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
            for (c, r) in [2 * i, 2 * i + 1].into_iter().zip(&f.residual) {
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
