//! stub
use super::PlotResult;
use crate::checks::{Check, ResidualPair};
use crate::ensemble::EnsembleStats;
pub fn residual_whiteness(
    _stats: &EnsembleStats,
    _check: &Check,
    _pair: &ResidualPair,
) -> PlotResult {
    Ok(String::new())
}
