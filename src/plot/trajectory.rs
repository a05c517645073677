//! stub
use super::PlotResult;
use crate::realization::Realization;
pub fn trajectory(_r: &Realization) -> PlotResult {
    Ok(String::new())
}
