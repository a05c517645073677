//! The three-axis Monte Carlo ensemble: N realizations of one drive, each with its own sensors
//! and its own EKF, whose covariance depends on its own estimate. Each realization's errors,
//! corrections and innovations at every fix are normalized by its own P and S
//! ([`crate::ensemble::normalized`]) and summed: the check catalogue reads the sums as it reads
//! the linear study's.
//!
//! The truth is computed once and shared (every realization drives the same road); each
//! realization's random stream depends only on the seed and its index, and the realizations are
//! folded in index order within blocks folded in order ([`super::blocks`]): the same numbers on
//! any thread count and from any split into shards, memory flat in N.

use std::ops::Range;

use nalgebra::{SVector, UnitQuaternion};
use rayon::prelude::*;

use crate::ensemble::normalized::{NormalizedFix, NormalizedSums};
use crate::ensemble::{EnsembleStats, ResidualLayout};

use super::blocks::{self, CHUNK};
use super::error_state::{
    ACCEL_BIAS, ATTITUDE, GYRO_BIAS, POSITION, STATES, VELOCITY, holds, start_of,
};
use super::filter::{Ekf, FilterError};
use super::gnss;
use super::mech::{Increment, Pva};
use super::sensors::Imu;
use super::setup::Scenario;
use super::state::Block;
use super::truth::Truth;
use crate::ensemble::Partition;
use crate::progress::{Cancel, Cancelled};

mod memory;
mod realization;
mod simulated;
pub use memory::memory_bytes;
pub use realization::{FixView, filter_realization, realization, start};
pub use simulated::{SimulatedGnss, SimulatedImu};

pub use super::names::MEASURED;

/// The normalized sums of the three-axis ensemble.
pub type Sums<const N: usize = STATES> = NormalizedSums<N, MEASURED>;

/// One realization's fixes, normalized by its own covariances, and its errors and σ's at the end.
#[derive(Clone, Debug, PartialEq)]
pub struct Normalized<const N: usize = STATES> {
    /// Every fix, normalized.
    pub fixes: Vec<NormalizedFix<N, MEASURED>>,
    /// The a posteriori error at the last fix.
    pub final_error: SVector<f64, N>,
    /// The filter's a posteriori σ at the last fix.
    pub final_sigma: SVector<f64, N>,
}

/// What the ensemble says of the calibration at the end of the drive, per error state.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration<const N: usize = STATES> {
    /// Realizations N.
    pub realizations: u64,
    /// The filter's σ at the last fix, root mean square over the ensemble.
    pub filter_sigma: [f64; N],
    /// The achieved error at the last fix, root mean square over the ensemble.
    pub achieved_rms: [f64; N],
    /// Realizations whose final |error| / σ is within the two-sided 95 % bound 1.96.
    pub within_95: [u64; N],
}

/// The ensemble's sums: the normalized ones the checks read, and the raw ones at the end.
#[derive(Clone, Debug, PartialEq)]
pub struct InsSums<const N: usize = STATES> {
    /// The normalized sums.
    pub normalized: Sums<N>,
    /// Σ e² at the last fix.
    pub sq_error: SVector<f64, N>,
    /// Σ σ² at the last fix.
    pub variance: SVector<f64, N>,
    /// Realizations whose final |e|/σ ≤ 1.96, per state.
    pub within_95: [u64; N],
}

impl<const N: usize> InsSums<N> {
    /// Adds one realization.
    pub fn add(&mut self, r: &Normalized<N>) {
        self.normalized.add(&r.fixes);
        self.sq_error += r.final_error.component_mul(&r.final_error);
        self.variance += r.final_sigma.component_mul(&r.final_sigma);
        for (k, w) in self.within_95.iter_mut().enumerate() {
            *w += u64::from((r.final_error[k] / r.final_sigma[k]).abs() <= Z95);
        }
    }

    /// Adds `other`, the sums of other realizations of the same ensemble.
    pub fn merge(&mut self, other: &InsSums<N>) {
        self.normalized.merge(&other.normalized);
        self.sq_error += other.sq_error;
        self.variance += other.variance;
        for (w, o) in self.within_95.iter_mut().zip(other.within_95) {
            *w += o;
        }
    }

    /// The statistics the checks read and the calibration, for the ensemble of `scenario`.
    pub fn outcome(&self, scenario: &Scenario) -> Outcome<N> {
        Outcome {
            stats: self.normalized.stats(constant_states(scenario)),
            calibration: self.calibration(),
        }
    }

    /// The calibration at the end of the drive.
    pub fn calibration(&self) -> Calibration<N> {
        let n = self.normalized.sums.count;
        let rms = |v: &SVector<f64, N>| std::array::from_fn(|k| (v[k] / n as f64).sqrt());
        Calibration {
            realizations: n,
            filter_sigma: rms(&self.variance),
            achieved_rms: rms(&self.sq_error),
            within_95: self.within_95,
        }
    }
}

/// The two-sided 95 % bound of a standard normal score.
pub const Z95: f64 = 1.959_963_984_540_054;

/// The ensemble's statistics and its calibration figures.
#[derive(Clone, Debug)]
pub struct Outcome<const N: usize = STATES> {
    /// The statistics of the normalized quantities, for the checks.
    pub stats: EnsembleStats<N, MEASURED>,
    /// The calibration at the end.
    pub calibration: Calibration<N>,
}

/// The drive's truth at every IMU step, shared by the realizations.
pub struct Track {
    /// The state at the start.
    pub start: Pva,
    /// The true increments over each step and the state at its end.
    pub steps: Vec<(Increment, Pva)>,
}

impl Track {
    /// The truth of `scenario`'s drive.
    pub fn of(scenario: &Scenario) -> Self {
        let drive = scenario.drive();
        let truth = Truth::new(&drive, scenario.start, 1.0 / scenario.imu_rate_hz)
            .until(scenario.duration_s);
        let start = truth.pva();
        Track {
            start,
            steps: truth.collect(),
        }
    }
}

/// The error of `ekf` against the true state (`vehicle`: the drive's, the IMU's own unless it is
/// mounted in a vehicle), biases (and scale factors, mounting), in the error state's
/// coordinates.
pub fn error<const N: usize>(ekf: &Ekf<N>, vehicle: &Pva, imu: &Imu) -> SVector<f64, N> {
    let pva = &imu.pva_of(vehicle);
    let mut e = SVector::<f64, N>::zeros();
    e.fixed_rows_mut::<3>(POSITION)
        .copy_from(&gnss::ned_difference_m(&ekf.pva.position, &pva.position));
    e.fixed_rows_mut::<3>(VELOCITY)
        .copy_from(&(ekf.pva.velocity_ned_m_s - pva.velocity_ned_m_s));
    e.fixed_rows_mut::<3>(ATTITUDE)
        .copy_from(&(ekf.pva.attitude * pva.attitude.inverse()).scaled_axis());
    e.fixed_rows_mut::<3>(GYRO_BIAS)
        .copy_from(&(ekf.gyro_bias_rad_s - imu.gyro_bias_rad_s));
    e.fixed_rows_mut::<3>(ACCEL_BIAS)
        .copy_from(&(ekf.accel_bias_m_s2 - imu.accel_bias_m_s2));
    if holds::<N>(Block::GyroScale) {
        e.fixed_rows_mut::<3>(start_of::<N>(Block::GyroScale))
            .copy_from(&(ekf.gyro_scale - imu.gyro_scale));
        e.fixed_rows_mut::<3>(start_of::<N>(Block::AccelScale))
            .copy_from(&(ekf.accel_scale - imu.accel_scale));
    }
    if holds::<N>(Block::Mounting) {
        let truth = imu.mounting.unwrap_or_else(UnitQuaternion::identity);
        e.fixed_rows_mut::<3>(start_of::<N>(Block::Mounting))
            .copy_from(&(ekf.mounting * truth.inverse()).scaled_axis());
    }
    e
}

/// A realization that could not be filtered or normalized.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RealizationError {
    /// The filter stopped.
    #[error("realization {index}: {source}")]
    Filter {
        /// The realization.
        index: u64,
        /// Why.
        source: FilterError,
    },
    /// A covariance at a fix was not positive definite, or a fix had no velocity.
    #[error("realization {index}: the covariance at fix {fix} is not positive definite")]
    Covariance {
        /// The realization.
        index: u64,
        /// The fix.
        fix: usize,
    },
}

impl From<std::convert::Infallible> for RealizationError {
    fn from(never: std::convert::Infallible) -> Self {
        match never {}
    }
}

/// The fixes' times of `scenario`, s.
pub fn fix_times_s(scenario: &Scenario, track: &Track) -> Vec<f64> {
    (1..=track.steps.len() / scenario.imu_steps_per_fix)
        .map(|i| (i * scenario.imu_steps_per_fix) as f64 / scenario.imu_rate_hz)
        .collect()
}

/// The residual products the whiteness check reads by default: pairs of fixes at most this many
/// fixes apart. A GNSS error correlated over seconds, or a mis-modelled dynamics, shows within
/// tens of fixes; the Bonferroni bound of every pair of 600 fixes (6.5·10⁶ members) would dilute
/// it, and their products would cost as much as the filters.
pub const DEFAULT_MAX_LAG: usize = 30;

/// The residual products the whiteness check reads: pairs of fixes at most `max_lag` apart
/// ([`DEFAULT_MAX_LAG`] when `None`; a lag of the fixes' count or more keeps every pair).
pub fn layout(fixes: usize, max_lag: Option<usize>) -> ResidualLayout {
    ResidualLayout::with_width(fixes, MEASURED, Some(max_lag.unwrap_or(DEFAULT_MAX_LAG)))
}

/// Empty sums for `scenario`'s ensemble.
pub fn empty_sums<const N: usize>(scenario: &Scenario, track: &Track) -> InsSums<N> {
    let times = fix_times_s(scenario, track);
    let n = times.len();
    let layout = layout(n, scenario.residual_max_lag);
    InsSums {
        normalized: NormalizedSums::new(times, &layout, [0, n.saturating_sub(1)]),
        sq_error: SVector::zeros(),
        variance: SVector::zeros(),
        within_95: [0; N],
    }
}

/// The sums of each block of `range` of an ensemble of `scenario` cut as `blocks`, handed to
/// `on_block` in block order; `progress` is told how many realizations are done after every
/// chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn run_blocks<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    blocks: &Partition,
    range: Range<u64>,
    progress: impl FnMut(u64),
    on_block: impl FnMut(u64, &InsSums<N>),
) -> Result<(), RealizationError> {
    match try_run_blocks(
        scenario,
        track,
        blocks,
        range,
        progress,
        on_block,
        &Cancel::new(),
    ) {
        Ok(()) => Ok(()),
        Err(Stopped::Realization(e)) => Err(e),
        Err(Stopped::Cancelled(never)) => unreachable!("{never}: the flag is never raised"),
    }
}

/// Why an ensemble that can be cancelled stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Stopped {
    /// A realization failed.
    #[error(transparent)]
    Realization(#[from] RealizationError),
    /// The flag was raised (Ctrl-C).
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// [`run_blocks`] polling `cancel` before every chunk: once it is raised, the run stops with
/// [`Stopped::Cancelled`] and no block after it is handed over.
///
/// # Errors
/// [`Stopped::Realization`] with the first realization's error, in index order;
/// [`Stopped::Cancelled`].
pub fn try_run_blocks<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    blocks: &Partition,
    range: Range<u64>,
    mut progress: impl FnMut(u64),
    mut on_block: impl FnMut(u64, &InsSums<N>),
    cancel: &Cancel,
) -> Result<(), Stopped> {
    let mut done = 0;
    for b in range {
        let mut sums = empty_sums(scenario, track);
        let indices = blocks.block_realizations(b);
        let mut first = indices.start;
        while first < indices.end {
            cancel.check()?;
            let last = (first + CHUNK).min(indices.end);
            let chunk: Vec<Result<Normalized<N>, RealizationError>> = (first..last)
                .into_par_iter()
                .map(|l| realization(scenario, track, l))
                .collect();
            for r in chunk {
                sums.add(&r?);
            }
            done += last - first;
            first = last;
            progress(done);
        }
        on_block(b, &sums);
    }
    Ok(())
}

/// The sums of the whole ensemble of `realizations` realizations of `scenario`: its blocks folded
/// in block order; `progress` is told how many are done after every chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn sums<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    realizations: u64,
    progress: impl FnMut(u64),
) -> Result<InsSums<N>, RealizationError> {
    let blocks = blocks::partition(realizations);
    let mut total = empty_sums(scenario, track);
    run_blocks(
        scenario,
        track,
        &blocks,
        0..blocks.blocks,
        progress,
        |_, s| {
            total.merge(s);
        },
    )?;
    Ok(total)
}

/// [`sums`] that stops when `cancel` is raised (polled before every chunk of [`CHUNK`]
/// realizations), as the one-axis ensemble's `try_sums` does.
///
/// # Errors
/// As [`try_run_blocks`].
pub fn try_sums<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    realizations: u64,
    progress: impl FnMut(u64),
    cancel: &Cancel,
) -> Result<InsSums<N>, Stopped> {
    let blocks = blocks::partition(realizations);
    let mut total = empty_sums(scenario, track);
    let all = 0..blocks.blocks;
    try_run_blocks(
        scenario,
        track,
        &blocks,
        all,
        progress,
        |_, s| total.merge(s),
        cancel,
    )?;
    Ok(total)
}

/// Which error states do not move between fixes: a bias whose truth and filter both hold it
/// constant, and the scale factors (constants in both).
pub fn constant_states<const N: usize>(scenario: &Scenario) -> [bool; N] {
    use super::sensors::BiasProcess::Constant;
    let (t, f) = (&scenario.truth_imu, &scenario.filter_imu);
    let gyro = matches!(t.gyro_bias, Constant { .. }) && matches!(f.gyro_bias, Constant { .. });
    let accel = matches!(t.accel_bias, Constant { .. }) && matches!(f.accel_bias, Constant { .. });
    std::array::from_fn(|k| {
        (GYRO_BIAS..GYRO_BIAS + 3).contains(&k) && gyro
            || (ACCEL_BIAS..ACCEL_BIAS + 3).contains(&k) && accel
            || k >= STATES
    })
}

/// The ensemble's statistics over `realizations` realizations of `scenario` (indices 0 to N − 1).
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn run<const N: usize>(
    scenario: &Scenario,
    track: &Track,
    realizations: u64,
) -> Result<Outcome<N>, RealizationError> {
    Ok(sums(scenario, track, realizations, |_| {})?.outcome(scenario))
}
