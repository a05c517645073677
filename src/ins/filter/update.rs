//! The update by any measurement ([`Measurement`]): its rows at the solution, the χ² gate, the
//! Joseph form P⁺ = (I − KH)P(I − KH)ᵀ + KRKᵀ with the gain K = PHᵀS⁻¹ from a Cholesky factor of
//! S = HPHᵀ + R (no explicit inverse), and the closed-loop correction. One fixed-size update per
//! row count: the rows are copied into a matrix of exactly their size.

use nalgebra::allocator::Allocator;
use nalgebra::{
    DMatrix, DVector, DefaultAllocator, Dim, OMatrix, OVector, SMatrix, SVector, Vector3,
};

use super::{Ekf, FilterError, Innovation};
use crate::ins::error_state::Square;
use crate::ins::measurement::{At, Gate, MAX_ROWS, Measurement, Rows};

impl<const N: usize> Ekf<N> {
    /// The compensated angular rate of the last IMU step, body axes, rad/s (zero before the
    /// first step): what a lever arm's velocity needs.
    pub fn rate_ib_b_rad_s(&self) -> Vector3<f64> {
        self.before
            .map_or(Vector3::zeros(), |b| b.dtheta_rad / b.dt_s)
    }

    /// The update by `m` (the pending steps first propagated), tested by `gate` when given: an
    /// innovation the gate rejects leaves the solution, the estimates and P as they were, and
    /// comes back with [`Innovation::accepted`] false and no correction.
    ///
    /// # Errors
    /// [`FilterError::Innovation`] when S is not positive definite.
    pub fn update_by(
        &mut self,
        m: &dyn Measurement<N>,
        gate: Option<&Gate>,
    ) -> Result<Innovation<N>, FilterError> {
        self.flush();
        // Two updates at one time leave the period between the earlier ones.
        if self.steps_since_update > 0 {
            self.fix_period_steps = Some(self.steps_since_update);
        }
        self.steps_since_update = 0;
        let mut rows = Rows::<N>::default();
        let at = At {
            pva: &self.pva,
            lever_arm_b_m: self.lever_arm_b_m,
            rate_ib_b_rad_s: self.rate_ib_b_rad_s(),
            mounting: self.mounting,
        };
        m.rows(&at, &mut rows);
        let t_s = m.t_s();
        let threshold = |n: usize| gate.map_or(f64::INFINITY, |g| g.threshold(n));
        macro_rules! sized {
            ($($r:literal)*) => {
                match rows.len {
                    $($r => self.joseph::<$r>(&rows, t_s, threshold($r)),)*
                    0 => Ok(Innovation {
                        t_s,
                        residual: DVector::zeros(0),
                        covariance: DMatrix::zeros(0, 0),
                        nis: 0.0,
                        correction: SVector::zeros(),
                        components: Vec::new(),
                        accepted: true,
                    }),
                    n => unreachable!("{n} rows: at most {MAX_ROWS}"),
                }
            };
        }
        sized!(1 2 3 4 5 6 7 8)
    }

    /// The Joseph update by the first `R` of `rows`, unless the NIS exceeds `threshold`: on
    /// matrices of their static sizes, or with `dynamic` on dynamic ones (whose products of
    /// more than 5×5 nalgebra hands to `matrixmultiply`, another order of additions: a fix
    /// without all its velocity components has always been updated so, and keeps its numbers).
    fn joseph<const R: usize>(
        &mut self,
        rows: &Rows<N>,
        t_s: f64,
        threshold: f64,
    ) -> Result<Innovation<N>, FilterError> {
        let components = rows.names().to_vec();
        let bad = FilterError::Innovation { t_s };
        let (dx, p_new, s, nis) = if R == 4 || R == 5 {
            let h = DMatrix::from_fn(R, N, |i, j| rows.observation[(i, j)]);
            let z = DVector::from_fn(R, |i, _| rows.innovation[i]);
            let r = DVector::from_fn(R, |i, _| rows.noise_variance[i]);
            let p = DMatrix::from_column_slice(N, N, self.covariance.as_slice());
            let (dx, p_new, s, nis) = joseph_form(&p, &h, &z, &r, threshold).ok_or(bad)?;
            (
                SVector::<f64, N>::from_column_slice(dx.as_slice()),
                p_new.map(|p| Square::<N>::from_column_slice(p.as_slice())),
                s,
                nis,
            )
        } else {
            let h: SMatrix<f64, R, N> = rows.observation.fixed_rows::<R>(0).into_owned();
            let z: SVector<f64, R> = rows.innovation.fixed_rows::<R>(0).into_owned();
            let r: SVector<f64, R> = rows.noise_variance.fixed_rows::<R>(0).into_owned();
            let (dx, p_new, s, nis) =
                joseph_form(&self.covariance, &h, &z, &r, threshold).ok_or(bad)?;
            (
                dx,
                p_new,
                DMatrix::from_column_slice(R, R, s.as_slice()),
                nis,
            )
        };
        let residual = DVector::from_column_slice(&rows.innovation.as_slice()[..R]);
        let accepted = p_new.is_some();
        if let Some(p_new) = p_new {
            self.covariance = p_new;
            self.correct(&dx);
        }
        Ok(Innovation {
            t_s,
            residual,
            covariance: s,
            nis,
            correction: dx,
            components,
            accepted,
        })
    }
}

/// The Joseph form over any sizes: from P, H, the innovation z and R's diagonal r, the
/// estimated errors K·z (zero when rejected), the new P (`None` when the NIS exceeds
/// `threshold`), S and the NIS; `None` when S is not positive definite.
#[allow(clippy::type_complexity)]
fn joseph_form<R: Dim, C: Dim>(
    p: &OMatrix<f64, C, C>,
    h: &OMatrix<f64, R, C>,
    z: &OVector<f64, R>,
    r: &OVector<f64, R>,
    threshold: f64,
) -> Option<(
    OVector<f64, C>,
    Option<OMatrix<f64, C, C>>,
    OMatrix<f64, R, R>,
    f64,
)>
where
    DefaultAllocator: Allocator<R, C> + Allocator<C, R> + Allocator<R, R> + Allocator<C, C>,
    DefaultAllocator: Allocator<R> + Allocator<C>,
{
    let (_, cols) = h.shape_generic();
    let hp = h * p;
    let s = &hp * h.transpose() + OMatrix::<f64, R, R>::from_diagonal(r);
    let chol = s.clone().cholesky()?;
    let nis = z.dot(&chol.solve(z));
    if nis > threshold {
        return Some((OVector::zeros_generic(cols, nalgebra::U1), None, s, nis));
    }
    // K = P Hᵀ S⁻¹, from S Kᵀ = H P.
    let k = chol.solve(&hp).transpose();
    let dx = &k * z;
    let i_kh = OMatrix::<f64, C, C>::identity_generic(cols, cols) - &k * h;
    let kr = &k * OMatrix::<f64, R, R>::from_diagonal(r);
    let p_new = &i_kh * p * i_kh.transpose() + kr * k.transpose();
    Some((dx, Some((&p_new + p_new.transpose()) * 0.5), s, nis))
}
