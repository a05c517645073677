//! The members of each check: one statistic per fix, stage and component, computed from the
//! ensemble statistics through [`Statistics`], whatever the state's size. Each distinct random
//! quantity is a member once: a constant state (for the error state, the bias: the last row of Φ
//! is (0, 0, 1) and Q has no bias term) does not move between fixes, so its a priori error and
//! estimate at fix i > 0 are the a posteriori ones of fix i − 1 and are not counted again.

use crate::ensemble::{StageView, Statistics};
use crate::filter::Stage;

/// Normalized residual correlation z = √N · Σ r_a r_b / √(Σ r_a² Σ r_b²) of stacked residual
/// components a and b (component M·i + j is component j of the residual at fix i).
///
/// # Formula
/// z = √N · m_ab / √(m_aa · m_bb), m the residual second moments (1/N) Σ r_a r_b.
///
/// NaN when the ensemble did not keep that pair (see [`crate::ensemble::ResidualLayout`]).
pub fn residual_z(stats: &dyn Statistics, a: usize, b: usize) -> f64 {
    let m = |a, b| stats.residual_moment(a, b).unwrap_or(f64::NAN);
    z_score(stats.realizations(), m(a, b), m(a, a), m(b, b))
}

/// √N · m_ab / √(m_aa · m_bb).
pub fn z_score(n: u64, m_ab: f64, m_aa: f64, m_bb: f64) -> f64 {
    (n as f64).sqrt() * m_ab / (m_aa * m_bb).sqrt()
}

/// Calls `g(fix, stage, statistics of the stage)` for every fix and stage, in fix order.
pub fn per_stage(stats: &dyn Statistics, g: &mut dyn FnMut(usize, Stage, &StageView)) {
    for i in 0..stats.fix_count() {
        for stage in Stage::ALL {
            g(i, stage, &stats.stage(i, stage));
        }
    }
}

/// Calls `g(fix, stage, state k, statistics of the stage)` for every state of every stage at
/// every fix that is a member of its own (not a constant state's a priori copy).
pub fn per_state(stats: &dyn Statistics, g: &mut dyn FnMut(usize, Stage, usize, &StageView)) {
    let states = stats.dims().states;
    per_stage(stats, &mut |i, stage, s| {
        for k in (0..states).filter(|&k| !stats.is_copy(i, stage, k)) {
            g(i, stage, k, s);
        }
    });
}
