//! Measurements behind one trait: each source gives its innovation z, its rows of H over the
//! error-state blocks it touches, its noise variances R and the names of its components; the
//! filter updates by any of them through one Joseph-form update with a Cholesky gain
//! ([`super::filter::Ekf::update_by`]) and one χ² gate ([`Gate`]).
//!
//! This is OpenVINS's arrangement (`StateHelper::EKFUpdate` takes H, the residual and R from each
//! updater; each updater tests its residual with a χ² test) on nalgebra's static sizes: a
//! measurement writes its rows into a [`Rows`] of at most [`MAX_ROWS`], and the update dispatches
//! on their count to a fixed-size Joseph form. Several measurements at one time are stacked into
//! one update ([`Stacked`]): a GNSS fix is its position and its velocity together.

use nalgebra::{Matrix3, RowSVector, SMatrix, SVector, UnitQuaternion, Vector3};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use super::error_state::STATES;
use super::mech::Pva;
use crate::state::Variable;

/// The most rows one update can take (a fix's six, with room for a vehicle's constraints).
pub const MAX_ROWS: usize = 8;

/// What the filter's solution offers a measurement's model at the time of its update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct At<'a> {
    /// The navigation solution before the update.
    pub pva: &'a Pva,
    /// The GNSS antenna's lever arm in body axes, m.
    pub lever_arm_b_m: Vector3<f64>,
    /// The compensated angular rate of the last IMU step, body axes, rad/s (zero before the
    /// first step).
    pub rate_ib_b_rad_s: Vector3<f64>,
    /// The IMU's mounting in the vehicle, q_b^v (identity for a free body).
    pub mounting: UnitQuaternion<f64>,
}

/// A measurement's rows at the filter's solution: the innovation z = ẑ − z̃ (the solution's
/// prediction minus the measurement, so that z = Hδx − w with δx the estimate minus the truth),
/// H, the white noise's variances R (diagonal) and which of the source's components each row
/// measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Rows<const N: usize = STATES> {
    /// Rows filled.
    pub len: usize,
    /// z, first [`Rows::len`] entries.
    pub innovation: SVector<f64, MAX_ROWS>,
    /// H, first [`Rows::len`] rows.
    pub observation: SMatrix<f64, MAX_ROWS, N>,
    /// R's diagonal, first [`Rows::len`] entries.
    pub noise_variance: SVector<f64, MAX_ROWS>,
    /// Each row's component in words (north position, east velocity, …).
    pub components: [&'static Variable; MAX_ROWS],
}

/// The placeholder of an unfilled row's component.
const NONE: Variable = Variable {
    key: "",
    name: "",
    symbol: "",
    unit: "",
};

impl<const N: usize> Default for Rows<N> {
    fn default() -> Self {
        Rows {
            len: 0,
            innovation: SVector::zeros(),
            observation: SMatrix::zeros(),
            noise_variance: SVector::zeros(),
            components: [&NONE; MAX_ROWS],
        }
    }
}

impl<const N: usize> Rows<N> {
    /// Appends one row: innovation `z`, noise variance `r`, H's row `h`, component `name`.
    ///
    /// # Panics
    /// When [`MAX_ROWS`] rows are already filled (a measurement model's error, not input).
    pub fn push(&mut self, z: f64, r: f64, h: &RowSVector<f64, N>, name: &'static Variable) {
        assert!(
            self.len < MAX_ROWS,
            "more than {MAX_ROWS} rows in one update"
        );
        let i = self.len;
        self.innovation[i] = z;
        self.noise_variance[i] = r;
        self.components[i] = name;
        self.observation.set_row(i, h);
        self.len += 1;
    }

    /// Appends the rows of a three-component measurement that `measured` keeps: innovation `z`,
    /// noise variances `r`, H's 3×3 blocks `blocks` (each at its block's first column; the rest
    /// zero) and the components' names.
    ///
    /// # Panics
    /// As [`Rows::push`].
    pub fn push3(
        &mut self,
        (z, r): (&Vector3<f64>, &Vector3<f64>),
        blocks: &[(usize, Matrix3<f64>)],
        names: &'static [Variable; 3],
        measured: [bool; 3],
    ) {
        for k in (0..3).filter(|&k| measured[k]) {
            assert!(
                self.len < MAX_ROWS,
                "more than {MAX_ROWS} rows in one update"
            );
            let i = self.len;
            self.innovation[i] = z[k];
            self.noise_variance[i] = r[k];
            self.components[i] = &names[k];
            for (col, m) in blocks {
                self.observation
                    .fixed_view_mut::<1, 3>(i, *col)
                    .copy_from(&m.fixed_rows::<1>(k));
            }
            self.len += 1;
        }
    }

    /// The components of the rows filled.
    pub fn names(&self) -> &[&'static Variable] {
        &self.components[..self.len]
    }
}

/// One measurement, at one time.
pub trait Measurement<const N: usize = STATES> {
    /// Its time, s.
    fn t_s(&self) -> f64;
    /// Appends its rows at the filter's solution `at` to `rows`.
    fn rows(&self, at: &At, rows: &mut Rows<N>);
}

/// Measurements at one time updated together: their rows stacked in order.
pub struct Stacked<'a, const N: usize = STATES>(pub Vec<&'a dyn Measurement<N>>);

impl<const N: usize> Measurement<N> for Stacked<'_, N> {
    fn t_s(&self) -> f64 {
        self.0.first().map_or(f64::NAN, |m| m.t_s())
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        for m in &self.0 {
            m.rows(at, rows);
        }
    }
}

/// The χ² innovation gate: an update whose NIS νᵀS⁻¹ν exceeds the (1 − α) quantile of χ² with
/// as many degrees of freedom as rows is rejected, its innovation recorded and the filter left
/// as it was. Under the filter's model a consistent innovation is rejected with probability α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gate {
    /// The false-alarm rate α.
    pub false_alarm_rate: f64,
    /// The threshold for 1 … [`MAX_ROWS`] rows (index: rows − 1).
    thresholds: [f64; MAX_ROWS],
}

impl Gate {
    /// The gate rejecting a consistent innovation with probability `false_alarm_rate` (in
    /// (0, 1)).
    ///
    /// # Panics
    /// When `false_alarm_rate` is outside (0, 1): the caller's validation says which key.
    pub fn new(false_alarm_rate: f64) -> Self {
        assert!(
            false_alarm_rate > 0.0 && false_alarm_rate < 1.0,
            "the gate's false-alarm rate {false_alarm_rate} is outside (0, 1)"
        );
        Gate {
            false_alarm_rate,
            thresholds: std::array::from_fn(|k| {
                ChiSquared::new((k + 1) as f64)
                    .expect("positive degrees of freedom")
                    .inverse_cdf(1.0 - false_alarm_rate)
            }),
        }
    }

    /// The NIS threshold for `rows` rows (1 … [`MAX_ROWS`]).
    pub fn threshold(&self, rows: usize) -> f64 {
        self.thresholds[rows - 1]
    }
}
