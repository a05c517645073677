//! Helpers of the unit tests.

/// Runs `f` on another thread and fails when it has not returned within 10 s: a test of code
/// that must not hang on any input.
pub(crate) fn within_10_s<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(f()));
    rx.recv_timeout(std::time::Duration::from_secs(10))
        .expect("returned within 10 s")
}
