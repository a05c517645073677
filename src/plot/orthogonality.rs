//! stub
use super::PlotResult;
use crate::checks::Check;
use crate::ensemble::EnsembleStats;
pub fn orthogonality(_stats: &EnsembleStats, _check: &Check) -> PlotResult {
    Ok(String::new())
}
