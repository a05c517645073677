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

/// A request to stop a long run, shared between the caller that makes it (a signal handler, the
/// Python package on Ctrl-C) and the run that polls it between pieces of work (an ensemble's
/// blocks, the Allan analysis's stretches). A plain flag: the library knows nothing of signals.
#[derive(Clone, Debug, Default)]
pub struct Cancel(std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Cancel {
    /// A flag not yet raised.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every run that polls this flag (or a clone of it) to stop.
    pub fn cancel(&self) {
        self.0.store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether [`Cancel::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once [`Cancel::cancel`] was called: `cancel.check()?` between pieces of
    /// work.
    ///
    /// # Errors
    /// [`Cancelled`] when the flag is raised.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

/// A run stopped by its [`Cancel`] flag before it finished; it has no result.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled before the run finished")]
pub struct Cancelled;
