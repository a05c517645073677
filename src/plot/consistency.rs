//! stub
use super::PlotResult;
use crate::checks::Check;
use crate::ensemble::EnsembleStats;
pub fn consistency(_stats: &EnsembleStats, _nees: &Check, _nis: &Check) -> PlotResult {
    Ok(String::new())
}
