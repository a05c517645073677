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

use nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};
use rayon::prelude::*;

use crate::ensemble::normalized::{FixInput, NormalizedFix, NormalizedSums, StageInput};
use crate::ensemble::{EnsembleStats, ResidualLayout};

use super::blocks::{self, CHUNK};
use super::earth::offset;
use super::error_state::{
    ACCEL_BIAS, ACCEL_SCALE, ATTITUDE, GYRO_BIAS, GYRO_SCALE, POSITION, STATES, VELOCITY, has_scale,
};
use super::filter::{Ekf, FilterError};
use super::gnss;
use super::logs::fix;
use super::mech::{Increment, Pva};
use super::sensors::Imu;
use super::setup::Study;
use super::truth::Truth;
use crate::ensemble::Partition;

mod memory;
pub use memory::memory_bytes;

/// The GNSS measurement's rows: position and velocity, NED.
pub const MEASURED: usize = 6;

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

    /// The statistics the checks read and the calibration, for the ensemble of `study`.
    pub fn outcome(&self, study: &Study) -> Outcome<N> {
        Outcome {
            stats: self.normalized.stats(constant_states(study)),
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
    /// The truth of `study`'s drive.
    pub fn of(study: &Study) -> Self {
        let drive = study.drive();
        let truth =
            Truth::new(&drive, study.start, 1.0 / study.imu_rate_hz).until(study.duration_s);
        let start = truth.pva();
        Track {
            start,
            steps: truth.collect(),
        }
    }
}

/// The error of `ekf` against the true state, biases (and scale factors), in the error state's
/// coordinates.
pub fn error<const N: usize>(ekf: &Ekf<N>, pva: &Pva, imu: &Imu) -> SVector<f64, N> {
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
    if has_scale(N) {
        e.fixed_rows_mut::<3>(GYRO_SCALE)
            .copy_from(&(ekf.gyro_scale - imu.gyro_scale));
        e.fixed_rows_mut::<3>(ACCEL_SCALE)
            .copy_from(&(ekf.accel_scale - imu.accel_scale));
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

/// What one realization's filter saw at one fix, after its update.
pub struct FixView<'a, const N: usize = STATES> {
    /// The fix's time, s.
    pub t_s: f64,
    /// The fix's index.
    pub fix: usize,
    /// The errors before and after the update, the correction, P and S.
    pub input: FixInput<N, MEASURED>,
    /// The filter after the update.
    pub ekf: &'a Ekf<N>,
    /// The true IMU now (its biases).
    pub imu: &'a Imu,
}

/// Realization `index`'s true IMU (its prior's draws taken from its stream) and its filter,
/// started from the truth plus a draw of its prior: position, velocity and attitude errors of
/// the study's initial σ's, the biases' prior from the filter's model.
pub fn start<const N: usize>(study: &Study, track: &Track, index: u64) -> (Imu, Ekf<N>) {
    let mut imu = study.imu(index);
    let s = &study.initial_sigma;
    let dr = imu.normals(&Vector3::new(s[0], s[1], s[2]));
    let dv = imu.normals(&Vector3::new(s[3], s[4], s[5]));
    let dpsi = imu.normals(&Vector3::new(s[6], s[7], s[8]));
    let start = Pva {
        position: offset(&track.start.position, &dr),
        velocity_ned_m_s: track.start.velocity_ned_m_s + dv,
        attitude: UnitQuaternion::from_scaled_axis(dpsi) * track.start.attitude,
    };
    let ekf = Ekf::new(
        start,
        study.prior_of::<N>(),
        study.filter_noise(),
        study.filter_decay(),
        study.filter_gnss.lever_arm_b_m,
    )
    .with_earth_rotation(study.filter_earth_rotation_rad_s);
    (imu, ekf)
}

/// Runs realization `index` of `study` over `track` — its filter started from the truth plus a
/// draw of its prior — calling `on_fix` after every update; returns the filter and the IMU at
/// the end.
///
/// # Errors
/// [`RealizationError`] when a covariance stops being positive definite, or `on_fix`'s.
pub fn filter_realization<const N: usize>(
    study: &Study,
    track: &Track,
    index: u64,
    mut on_fix: impl FnMut(&FixView<N>) -> Result<(), RealizationError>,
) -> Result<(Ekf<N>, Imu), RealizationError> {
    let drive = study.drive();
    let (mut imu, mut ekf) = start(study, track, index);
    let g = &study.filter_gnss;
    let filter = |source| RealizationError::Filter { index, source };
    let mut fixes = 0;
    for (k, (inc, pva)) in track.steps.iter().enumerate() {
        let raw = imu.read(inc);
        ekf.propagate(&raw);
        if (k + 1) % study.imu_steps_per_fix != 0 {
            continue;
        }
        let t = (k + 1) as f64 / study.imu_rate_hz;
        let mut reading = fix(study, &drive, &mut imu, t, pva);
        // The filter weighs the fix with the σ's it assumes.
        reading.position_sigma_m = g.position_sigma_m;
        reading.velocity_sigma_m_s = g.velocity_sigma_m_s;
        let (e_prior, p_prior) = (error(&ekf, pva, &imu), ekf.covariance);
        let innovation = ekf.update(&reading).map_err(filter)?;
        let e_post = error(&ekf, pva, &imu);
        if innovation.residual.len() != MEASURED {
            return Err(RealizationError::Covariance { index, fix: fixes });
        }
        let input = FixInput {
            prior: StageInput {
                error: e_prior,
                // Closed loop: the error state is reset to zero after every fix.
                estimate: SVector::zeros(),
                covariance: p_prior,
            },
            post: StageInput {
                error: e_post,
                // The correction the update applied, K·ν: the error's change (to first order).
                estimate: e_prior - e_post,
                covariance: ekf.covariance,
            },
            residual: SVector::from_fn(|j, _| innovation.residual[j]),
            residual_covariance: SMatrix::from_fn(|a, b| innovation.covariance[(a, b)]),
        };
        on_fix(&FixView {
            t_s: t,
            fix: fixes,
            input,
            ekf: &ekf,
            imu: &imu,
        })?;
        fixes += 1;
    }
    Ok((ekf, imu))
}

/// Realization `index`, its errors, corrections and innovations at every fix normalized by its
/// own covariances.
///
/// # Errors
/// [`RealizationError`] when a covariance stops being positive definite.
pub fn realization<const N: usize>(
    study: &Study,
    track: &Track,
    index: u64,
) -> Result<Normalized<N>, RealizationError> {
    let mut out = Vec::with_capacity(track.steps.len() / study.imu_steps_per_fix);
    let (ekf, imu) = filter_realization(study, track, index, |v| {
        let bad = RealizationError::Covariance { index, fix: v.fix };
        out.push(NormalizedFix::of(&v.input, v.fix).map_err(|_| bad)?);
        Ok(())
    })?;
    let end = track.steps.last().map_or(&track.start, |x| &x.1);
    let p = ekf.covariance;
    Ok(Normalized {
        fixes: out,
        final_error: error(&ekf, end, &imu),
        final_sigma: SVector::from_fn(|k, _| p[(k, k)].sqrt()),
    })
}

/// The fixes' times of `study`, s.
pub fn fix_times_s(study: &Study, track: &Track) -> Vec<f64> {
    (1..=track.steps.len() / study.imu_steps_per_fix)
        .map(|i| (i * study.imu_steps_per_fix) as f64 / study.imu_rate_hz)
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

/// Empty sums for `study`'s ensemble.
pub fn empty_sums<const N: usize>(study: &Study, track: &Track) -> InsSums<N> {
    let times = fix_times_s(study, track);
    let n = times.len();
    let layout = layout(n, study.residual_max_lag);
    InsSums {
        normalized: NormalizedSums::new(times, &layout, [0, n.saturating_sub(1)]),
        sq_error: SVector::zeros(),
        variance: SVector::zeros(),
        within_95: [0; N],
    }
}

/// The sums of each block of `range` of an ensemble of `study` cut as `blocks`, handed to
/// `on_block` in block order; `progress` is told how many realizations are done after every
/// chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn run_blocks<const N: usize>(
    study: &Study,
    track: &Track,
    blocks: &Partition,
    range: Range<u64>,
    mut progress: impl FnMut(u64),
    mut on_block: impl FnMut(u64, &InsSums<N>),
) -> Result<(), RealizationError> {
    let mut done = 0;
    for b in range {
        let mut sums = empty_sums(study, track);
        let indices = blocks.block_realizations(b);
        let mut first = indices.start;
        while first < indices.end {
            let last = (first + CHUNK).min(indices.end);
            let chunk: Vec<Result<Normalized<N>, RealizationError>> = (first..last)
                .into_par_iter()
                .map(|l| realization(study, track, l))
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

/// The sums of the whole ensemble of `realizations` realizations of `study`: its blocks folded
/// in block order; `progress` is told how many are done after every chunk.
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn sums<const N: usize>(
    study: &Study,
    track: &Track,
    realizations: u64,
    progress: impl FnMut(u64),
) -> Result<InsSums<N>, RealizationError> {
    let blocks = blocks::partition(realizations);
    let mut total = empty_sums(study, track);
    run_blocks(study, track, &blocks, 0..blocks.blocks, progress, |_, s| {
        total.merge(s);
    })?;
    Ok(total)
}

/// Which error states do not move between fixes: a bias whose truth and filter both hold it
/// constant, and the scale factors (constants in both).
pub fn constant_states<const N: usize>(study: &Study) -> [bool; N] {
    use super::sensors::BiasProcess::Constant;
    let (t, f) = (&study.truth_imu, &study.filter_imu);
    let gyro = matches!(t.gyro_bias, Constant { .. }) && matches!(f.gyro_bias, Constant { .. });
    let accel = matches!(t.accel_bias, Constant { .. }) && matches!(f.accel_bias, Constant { .. });
    std::array::from_fn(|k| {
        (GYRO_BIAS..GYRO_BIAS + 3).contains(&k) && gyro
            || (ACCEL_BIAS..ACCEL_BIAS + 3).contains(&k) && accel
            || k >= STATES
    })
}

/// The ensemble's statistics over `realizations` realizations of `study` (indices 0 to N − 1).
///
/// # Errors
/// The first realization's [`RealizationError`], in index order.
pub fn run<const N: usize>(
    study: &Study,
    track: &Track,
    realizations: u64,
) -> Result<Outcome<N>, RealizationError> {
    Ok(sums(study, track, realizations, |_| {})?.outcome(study))
}
