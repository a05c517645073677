//! A log read on one thread while its steps are taken on another: the text's parsing (about 45 %
//! of `calibrate --imu`'s time on a 103 MB log) beside the filter instead of before each step.
//! The steps, their order and every number are those of the plain reader; with one thread
//! (`RAYON_NUM_THREADS=1`) nothing is spawned.

use std::sync::mpsc::{Receiver, sync_channel};

use super::LogError;
use super::imu_csv::StepSource;
use super::records::ImuStep;

/// Steps handed over at a time.
const CHUNK: usize = 4096;
/// Chunks read ahead of the consumer at most (about 1.5 MB of steps).
const DEPTH: usize = 4;

/// A batch of steps, the first row's time once known, and how the log ended after them.
struct Chunk {
    steps: Vec<ImuStep>,
    first_s: Option<f64>,
    end: Option<Result<(), LogError>>,
}

/// The consumer's side: the chunks as one [`StepSource`].
struct Ahead {
    chunks: Receiver<Chunk>,
    steps: std::vec::IntoIter<ImuStep>,
    first_s: Option<f64>,
    end: Option<Result<(), LogError>>,
}

impl StepSource for Ahead {
    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        loop {
            if let Some(step) = self.steps.next() {
                return Ok(Some(step));
            }
            if let Some(end) = self.end.take() {
                self.end = Some(Ok(()));
                return end.map(|()| None);
            }
            let Ok(chunk) = self.chunks.recv() else {
                return Ok(None);
            };
            self.steps = chunk.steps.into_iter();
            self.first_s = chunk.first_s;
            self.end = chunk.end;
        }
    }

    fn first_s(&self) -> Option<f64> {
        self.first_s
    }
}

/// `consume` run on the steps of `source`, read on this thread while `consume` runs on another.
/// When `consume` returns before the log's end, the reading stops within `DEPTH` (4) chunks.
pub fn consume_beside<T: Send>(
    source: &mut dyn StepSource,
    consume: impl FnOnce(&mut dyn StepSource) -> T + Send,
) -> T {
    if rayon::current_num_threads() < 2 {
        return consume(source);
    }
    let (tx, rx) = sync_channel::<Chunk>(DEPTH);
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let mut ahead = Ahead {
                chunks: rx,
                steps: Vec::new().into_iter(),
                first_s: None,
                end: None,
            };
            consume(&mut ahead)
        });
        loop {
            let mut steps = Vec::with_capacity(CHUNK);
            let mut end = None;
            while steps.len() < CHUNK && end.is_none() {
                match source.next_step() {
                    Ok(Some(step)) => steps.push(step),
                    Ok(None) => end = Some(Ok(())),
                    Err(e) => end = Some(Err(e)),
                }
            }
            let last = end.is_some();
            let chunk = Chunk {
                steps,
                first_s: source.first_s(),
                end,
            };
            if tx.send(chunk).is_err() || last {
                break;
            }
        }
        drop(tx);
        worker
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::LogProblem;
    use crate::input::imu_csv::HeldSteps;
    use crate::input::records::Increment;
    use nalgebra::Vector3;

    fn steps(n: usize) -> Vec<ImuStep> {
        (0..n)
            .map(|k| ImuStep {
                line: k as u64 + 3,
                t_s: 0.01 * (k + 1) as f64,
                increment: Increment {
                    dtheta_rad: Vector3::new(k as f64, 0.0, 0.0),
                    dvel_m_s: Vector3::zeros(),
                    dt_s: 0.01,
                },
            })
            .collect()
    }

    fn all(source: &mut dyn StepSource) -> (Vec<ImuStep>, Option<f64>, Option<LogError>) {
        let mut out = Vec::new();
        loop {
            match source.next_step() {
                Ok(Some(s)) => out.push(s),
                Ok(None) => return (out, source.first_s(), None),
                Err(e) => return (out, source.first_s(), Some(e)),
            }
        }
    }

    #[test]
    fn the_consumer_sees_every_step_in_order() {
        for n in [0, 1, CHUNK - 1, CHUNK, 3 * CHUNK + 7] {
            let held = steps(n);
            let plain = all(&mut HeldSteps::new(&held));
            let beside = consume_beside(&mut HeldSteps::new(&held), all);
            assert_eq!(plain.0, beside.0, "n = {n}");
            assert_eq!(plain.1, beside.1, "n = {n}");
        }
    }

    /// A log whose row `bad` is not a number.
    struct Broken {
        inner: Vec<ImuStep>,
        next: usize,
        bad: usize,
    }

    impl StepSource for Broken {
        fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
            if self.next == self.bad {
                let problem = LogProblem::NotANumber {
                    column: "gx_rad_s",
                    text: "x".into(),
                };
                return Err(LogError::of_file("imu.csv", problem));
            }
            self.next += 1;
            Ok(self.inner.get(self.next - 1).copied())
        }

        fn first_s(&self) -> Option<f64> {
            (self.next > 0).then_some(0.0)
        }
    }

    #[test]
    fn an_error_arrives_after_the_good_steps_before_it() {
        let bad = CHUNK + 5;
        let broken = || Broken {
            inner: steps(2 * CHUNK),
            next: 0,
            bad,
        };
        let (good, _, error) = consume_beside(&mut broken(), all);
        assert_eq!(good.len(), bad);
        let plain = all(&mut broken());
        assert_eq!(error.map(|e| e.to_string()), plain.2.map(|e| e.to_string()));
        // A consumer that stops early stops the reading too.
        let taken = consume_beside(&mut broken(), |s| s.next_step().ok().flatten());
        assert_eq!(taken, Some(steps(1)[0]));
    }
}
