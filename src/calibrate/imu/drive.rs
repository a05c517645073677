//! The recording as the driver's sources ([`crate::ins::driver`]): the IMU log's steps (the one
//! that holds the filter's start handed over first) and the GNSS log's fixes, each weighed with
//! the log's σ's or the assumptions'; the observer records every update.

use nalgebra::SVector;

use super::Settings;
use super::step::{FixRecord, LinearRecord, fix_of};
use crate::input::LogError;
use crate::input::imu_csv::StepSource;
use crate::input::records::{GnssRow, ImuStep};
use crate::ins::driver::{Context, Due, ImuSource, Observer, Source, Update};
use crate::ins::error_state::Square;
use crate::ins::extra::GNSS;
use crate::ins::filter::Ekf;
use crate::ins::gnss::FixUpdate;
use crate::ins::measurement::Measurement;
use crate::ins::names::MEASUREMENTS;

/// The IMU log's steps from the one that holds the filter's start on.
pub(super) struct LogSteps<'a> {
    /// The step read before the driver took over.
    pub(super) first: Option<ImuStep>,
    /// The rest.
    pub(super) source: &'a mut dyn StepSource,
}

impl Context for LogSteps<'_> {
    fn truth(&self) -> Option<&crate::ins::mech::Pva> {
        None
    }

    fn normal(&mut self) -> f64 {
        0.0
    }
}

impl ImuSource for LogSteps<'_> {
    type Error = LogError;

    fn next_step(&mut self) -> Result<Option<ImuStep>, LogError> {
        match self.first.take() {
            Some(s) => Ok(Some(s)),
            None => self.source.next_step(),
        }
    }
}

/// The GNSS log's fixes from `next` on, up to `end`.
pub(super) struct LogFixes<'a> {
    /// The fixes, their times moved by the receiver's offset.
    pub(super) rows: &'a [GnssRow],
    /// The next fix.
    pub(super) next: usize,
    /// One past the last fix to give.
    pub(super) end: usize,
    /// The assumptions (σ's where the log gives none).
    pub(super) settings: &'a Settings,
    /// Fixes without each velocity component.
    pub(super) missing: [usize; 3],
}

impl<const N: usize, C: ?Sized> Source<N, C> for LogFixes<'_> {
    fn next_time(&self) -> Option<f64> {
        (self.next < self.end).then(|| self.rows[self.next].t_s)
    }

    fn take(&mut self, _: &mut C) -> Box<dyn Measurement<N>> {
        let (fix, measured) = fix_of(&self.rows[self.next], self.settings);
        for (m, &k) in self.missing.iter_mut().zip(&measured) {
            *m += usize::from(!k);
        }
        self.next += 1;
        Box::new(FixUpdate { fix, measured })
    }
}

/// Records each fix's update: the filter's estimates, P before and after, Φ since the last fix,
/// the innovation per component and, when tracked, what a linearized likelihood needs.
pub(super) struct Recorder<'a, const N: usize> {
    /// The fixes.
    pub(super) rows: &'a [GnssRow],
    /// The first fix the source gives.
    pub(super) first: usize,
    /// One record per fix.
    pub(super) records: Vec<FixRecord<N>>,
    /// The update in progress: P before it, Φ and the linear record.
    before: Option<(Square<N>, Square<N>, Option<Box<LinearRecord<N>>>)>,
}

impl<'a, const N: usize> Recorder<'a, N> {
    /// A recorder of the fixes `rows` from `first` on.
    pub(super) fn new(rows: &'a [GnssRow], first: usize, records: Vec<FixRecord<N>>) -> Self {
        Recorder {
            rows,
            first,
            records,
            before: None,
        }
    }
}

impl<const N: usize, C: ?Sized> Observer<N, C> for Recorder<'_, N> {
    type Error = LogError;

    fn before(&mut self, f: &mut Ekf<N>, _: &C, due: &Due) -> Result<(), LogError> {
        if due.source != GNSS {
            // Another source's update: carried inside the transition to the next fix.
            return Ok(());
        }
        let prior_covariance = f.covariance;
        let transition = f.take_transition().unwrap_or_else(Square::<N>::identity);
        let linear = f.take_noise_parts().map(|noise_parts| {
            Box::new(LinearRecord {
                noise_parts,
                view: f.linear_view(),
            })
        });
        self.before = Some((prior_covariance, transition, linear));
        Ok(())
    }

    fn after(&mut self, f: &Ekf<N>, _: &C, due: &Due, update: Update<N>) -> Result<(), LogError> {
        if due.source != GNSS {
            return Ok(());
        }
        let (Update::Tested(nu), Some((prior_covariance, transition, linear))) =
            (update, self.before.take())
        else {
            return Ok(());
        };
        let (mut innovation, mut innovation_sigma) = ([f64::NAN; 6], [f64::NAN; 6]);
        for (k, name) in nu.components.iter().enumerate() {
            let i = MEASUREMENTS
                .iter()
                .position(|m| m == *name)
                .expect("a GNSS component");
            innovation[i] = nu.residual[k];
            innovation_sigma[i] = nu.covariance[(k, k)].sqrt();
        }
        let row = &self.rows[self.first + due.index];
        self.records.push(FixRecord {
            line: row.line,
            t_s: row.t_s,
            pva: f.pva,
            gyro_bias_rad_s: f.gyro_bias_rad_s,
            accel_bias_m_s2: f.accel_bias_m_s2,
            gyro_scale: f.gyro_scale,
            accel_scale: f.accel_scale,
            covariance: f.covariance,
            prior_covariance,
            transition,
            correction: if nu.accepted {
                nu.correction
            } else {
                SVector::zeros()
            },
            innovation,
            innovation_sigma,
            nis: nu.nis,
            log_det_s: nu
                .covariance
                .clone()
                .cholesky()
                .map_or(f64::NAN, |c| 2.0 * c.l().diagonal().map(f64::ln).sum()),
            rows: nu.components.len(),
            accepted: nu.accepted,
            linear,
        });
        Ok(())
    }
}
