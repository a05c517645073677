//! The update by a fix that measures only some velocity components: a receiver that reports no
//! vertical velocity, or none. The rows measured are taken out of the full six-row model and the
//! update is the same Joseph form with a Cholesky gain, on dynamic sizes.

use nalgebra::{DMatrix, DVector, SVector, Vector3};

use super::{Ekf, FilterError, Innovation};
use crate::ins::error_state::Square;
use crate::ins::gnss::{self, Fix};

impl<const N: usize> Ekf<N> {
    /// The update by `fix` measuring only the velocity components `measured` says (north, east,
    /// down; the position always): a receiver that reports no vertical velocity, or none.
    ///
    /// # Errors
    /// [`FilterError::Innovation`] when S is not positive definite.
    pub fn update_measured(
        &mut self,
        fix: &Fix,
        measured: [bool; 3],
    ) -> Result<Innovation<N>, FilterError> {
        if measured == [true; 3] || fix.velocity_ned_m_s.is_none() || measured == [false; 3] {
            let mut f = *fix;
            if measured == [false; 3] {
                f.velocity_ned_m_s = None;
            }
            return self.update(&f);
        }
        self.flush();
        self.fix_period_steps = Some(self.steps_since_update);
        self.steps_since_update = 0;
        let omega = self
            .before
            .map_or(Vector3::zeros(), |b| b.dtheta_rad / b.dt_s);
        let (position, velocity) = gnss::antenna(&self.pva, &self.lever_arm_b_m, &omega);
        let h6 = gnss::observation_of::<N>(&self.pva, &self.lever_arm_b_m, &omega);
        let v = fix.velocity_ned_m_s.unwrap_or_else(Vector3::zeros);
        let z6 = [
            gnss::ned_difference_m(&position, &fix.position).as_slice(),
            (velocity - v).as_slice(),
        ]
        .concat();
        let sr = &fix.position_sigma_m;
        let sv = &fix.velocity_sigma_m_s;
        let r6 = [sr.x, sr.y, sr.z, sv.x, sv.y, sv.z].map(|s| s * s);
        let rows: Vec<usize> = (0..6).filter(|&i| i < 3 || measured[i - 3]).collect();
        let h = DMatrix::from_fn(rows.len(), N, |i, j| h6[(rows[i], j)]);
        let z = DVector::from_fn(rows.len(), |i, _| z6[rows[i]]);
        let r = DVector::from_fn(rows.len(), |i, _| r6[rows[i]]);
        let p = DMatrix::from_column_slice(N, N, self.covariance.as_slice());
        let hp = &h * &p;
        let s = &hp * h.transpose() + DMatrix::from_diagonal(&r);
        let t_s = fix.t_s;
        let chol = s
            .clone()
            .cholesky()
            .ok_or(FilterError::Innovation { t_s })?;
        let k = chol.solve(&hp).transpose();
        let nis = z.dot(&chol.solve(&z));
        let dx = &k * &z;
        let i_kh = DMatrix::identity(N, N) - &k * &h;
        let kr = &k * DMatrix::from_diagonal(&r);
        let p_new = &i_kh * &p * i_kh.transpose() + kr * k.transpose();
        let p_new = (&p_new + p_new.transpose()) * 0.5;
        self.covariance = Square::<N>::from_column_slice(p_new.as_slice());
        let correction = SVector::<f64, N>::from_column_slice(dx.as_slice());
        self.correct(&correction);
        Ok(Innovation {
            t_s,
            residual: z,
            covariance: s,
            nis,
            correction,
        })
    }
}
