//! stub
use super::PlotResult;
use crate::ensemble::EnsembleStats;
pub fn truth_models(_a: &EnsembleStats, _e: &EnsembleStats) -> PlotResult {
    Ok(String::new())
}
