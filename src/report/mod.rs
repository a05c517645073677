//! The HTML report.

use anyhow::Result;

use crate::cli::ReportArgs;

/// Runs the report command.
pub fn run(_args: &ReportArgs) -> Result<()> {
    anyhow::bail!("the report is not written yet")
}
