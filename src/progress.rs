//! Progress of long runs, reported through a trait the caller implements: the library knows
//! nothing of terminals.

/// Receives the progress of a long run. The command line draws a bar; tests pass [`Silent`].
pub trait Progress: Send {
    /// A run of `total` realizations, called `label`, starts.
    fn start(&mut self, _label: &str, _total: u64) {}
    /// A run of `total` steps counted in `unit` (plural, e.g. "ensemble draws") starts.
    fn start_in(&mut self, label: &str, total: u64, _unit: &str) {
        self.start(label, total);
    }
    /// `done` realizations of the current run are finished.
    fn advance(&mut self, _done: u64) {}
    /// The current run is finished.
    fn finish(&mut self) {}
}

/// Progress that is not shown.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {}
