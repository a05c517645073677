//! The blocks of an ensemble run in parallel: one worker per thread takes the next block, sums it
//! into one [`Accumulator`] and hands it over; finished blocks reach the caller in block order.
//!
//! A worker waits rather than run more than a window of blocks ahead of the oldest unfinished
//! one (see [`window`]), so the memory of the sums in flight is bounded whatever N. The sums of a
//! block that has been handed over are reused by a later block, which overwrites every number.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard};

use super::engine::{Scratch, accumulate_into};
use super::layout::ResidualLayout;
use super::sums::{Accumulator, FixSums};
use super::{Ensemble, Partition};
use crate::progress::{Cancel, Cancelled};

/// Memory the sums of the blocks in flight may take together, bytes.
const WINDOW_BYTES: u64 = 256 << 20;

/// Blocks a worker may run ahead of the oldest unfinished one, per thread: one being summed and
/// one finished and waiting for its turn, so that a slow block does not stall the others.
const BLOCKS_AHEAD_PER_THREAD: u64 = 2;

/// Bytes of one block in flight: its sums (the per-fix sums and the residual products) and, about
/// as large as the products, its worker's single-precision tiles (see `tiles`).
fn block_bytes(layout: &ResidualLayout) -> u64 {
    let floats = <FixSums>::MEMORY_FLOATS * layout.fixes() + 2 * layout.len();
    (std::mem::size_of::<f64>() * floats).max(1) as u64
}

/// How many blocks may be in flight: [`BLOCKS_AHEAD_PER_THREAD`] per thread, fewer when their sums
/// would exceed [`WINDOW_BYTES`], but at least one per thread.
fn window(layout: &ResidualLayout) -> u64 {
    let threads = rayon::current_num_threads() as u64;
    (BLOCKS_AHEAD_PER_THREAD * threads)
        .min((WINDOW_BYTES / block_bytes(layout)).max(threads))
        .max(1)
}

/// Finished blocks waiting for their turn, and the callbacks that take them in block order.
struct Emitter<P, B> {
    /// The next block to hand over.
    next: u64,
    waiting: std::collections::BTreeMap<u64, Accumulator>,
    /// Sums handed over, kept for the next blocks: a block overwrites every number of them.
    spare: Vec<Accumulator>,
    /// Realizations handed over.
    done: u64,
    /// A worker panicked: the others stop instead of waiting for its block.
    failed: bool,
    progress: P,
    on_block: B,
}

impl<P: FnMut(u64), B: FnMut(u64, &Accumulator)> Emitter<P, B> {
    /// Hands over, in order, every finished block whose turn has come; whether any was.
    fn hand_over_ready(&mut self) -> bool {
        let first = self.next;
        while let Some(acc) = self.waiting.remove(&self.next) {
            self.done += acc.count;
            (self.on_block)(self.next, &acc);
            self.spare.push(acc);
            self.next += 1;
        }
        if self.next == first {
            return false;
        }
        (self.progress)(self.done);
        true
    }
}

/// What the workers share.
struct Shared<'e, 'a, P, B> {
    ensemble: &'e Ensemble<'a>,
    partition: Partition,
    layout: ResidualLayout,
    window: u64,
    /// The next block to claim.
    claimed: AtomicU64,
    /// The end of the blocks to run.
    end: u64,
    emitter: Mutex<Emitter<P, B>>,
    /// Signalled when blocks are handed over or a worker fails.
    turn: Condvar,
    /// Polled before each block is claimed: once raised, no further block starts.
    cancel: Option<&'e Cancel>,
}

/// Set in each worker: if the worker panics, it marks the run failed, lets no further block be
/// taken and wakes the waiting workers, so that every worker ends and `rayon::broadcast` hands
/// the panic to the caller (rather than the others waiting forever for the lost block).
struct Abort<'s, 'e, 'a, P, B>(&'s Shared<'e, 'a, P, B>);

impl<P, B> Drop for Abort<'_, '_, '_, P, B> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.claimed.store(self.0.end, Ordering::SeqCst);
            self.0.lock().failed = true;
            self.0.turn.notify_all();
        }
    }
}

impl<P, B> Shared<'_, '_, P, B> {
    fn lock(&self) -> MutexGuard<'_, Emitter<P, B>> {
        self.emitter.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl<P: FnMut(u64), B: FnMut(u64, &Accumulator)> Shared<'_, '_, P, B> {
    fn cancelled(&self) -> bool {
        self.cancel.is_some_and(Cancel::is_cancelled)
    }

    /// One worker: claims blocks until none is left (or a worker failed), sums each, hands it over.
    fn work(&self) {
        let _abort = Abort(self);
        let mut scratch = Scratch::default();
        while let Some((b, mut acc)) = self.claim() {
            let range = self.partition.block_realizations(b);
            accumulate_into(self.ensemble, range, &mut acc, &mut scratch);
            let mut e = self.lock();
            if e.failed {
                return;
            }
            e.waiting.insert(b, acc);
            if e.hand_over_ready() {
                drop(e);
                self.turn.notify_all();
            }
        }
    }

    /// The next block and the sums to add it into, once it is within the window of the oldest
    /// unfinished block; `None` when every block is claimed or a worker failed.
    fn claim(&self) -> Option<(u64, Accumulator)> {
        let b = self.claimed.fetch_add(1, Ordering::Relaxed);
        if b >= self.end {
            return None;
        }
        if self.cancelled() {
            // Block b will not be handed over: wake the workers waiting for it, under the lock
            // so that none misses the call between its test and its wait.
            let _e = self.lock();
            self.turn.notify_all();
            return None;
        }
        // Every block before b is claimed by a running worker, so the wait ends (or a worker
        // failed, and the run with it).
        let mut e = self
            .turn
            .wait_while(self.lock(), |e| {
                !e.failed && !self.cancelled() && b >= e.next + self.window
            })
            .unwrap_or_else(|e| e.into_inner());
        if e.failed || self.cancelled() {
            drop(e);
            self.turn.notify_all();
            return None;
        }
        let acc = e
            .spare
            .pop()
            .unwrap_or_else(|| Accumulator::new(&self.layout, self.ensemble.model().residual_pair));
        Some((b, acc))
    }
}

/// Runs the blocks of `ensemble`'s shard in parallel and hands each block's sums to `on_block`
/// as it is finished, in block order; `progress` is called with the number of realizations
/// handed over so far. With `cancel`, no block starts once it is raised (the blocks being summed
/// are finished, so a run stops within one block's time).
///
/// # Errors
/// [`Cancelled`] when `cancel` stopped the run before its last block was handed over.
pub(super) fn run_blocks(
    ensemble: &Ensemble,
    cancel: Option<&Cancel>,
    progress: impl FnMut(u64) + Send,
    on_block: impl FnMut(u64, &Accumulator) + Send,
) -> Result<(), Cancelled> {
    let blocks: Range<u64> = ensemble.block_range();
    let layout = ensemble.layout();
    let shared = Shared {
        ensemble,
        partition: ensemble.partition(),
        window: window(&layout),
        layout,
        claimed: AtomicU64::new(blocks.start),
        end: blocks.end,
        emitter: Mutex::new(Emitter {
            next: blocks.start,
            waiting: Default::default(),
            spare: Vec::new(),
            done: 0,
            failed: false,
            progress,
            on_block,
        }),
        turn: Condvar::new(),
        cancel,
    };
    rayon::broadcast(|_| shared.work());
    if shared.lock().next < blocks.end {
        return Err(Cancelled);
    }
    Ok(())
}
