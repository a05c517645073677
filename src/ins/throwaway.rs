//! A throwaway measurement that proves [`super::extra::sources`] is all a measurement takes
//! beside its own type: the down velocity, once a second, half-way between the fixes, with
//! σ = 1 m/s (the truth's when simulated; zero, a level road, on a log). Built only with
//! `--features throwaway-measurement`.

use nalgebra::RowSVector;

use super::driver::{Context, Source};
use super::error_state::VELOCITY;
use super::measurement::{At, Measurement, Rows};
use super::names::VARIABLES;

/// The measurement's σ, m/s.
const SIGMA_M_S: f64 = 1.0;

/// One down-velocity measurement.
struct Down {
    t_s: f64,
    v_d_m_s: f64,
}

impl<const N: usize> Measurement<N> for Down {
    fn t_s(&self) -> f64 {
        self.t_s
    }

    fn rows(&self, at: &At, rows: &mut Rows<N>) {
        let mut h = RowSVector::<f64, N>::zeros();
        h[VELOCITY + 2] = 1.0;
        let z = at.pva.velocity_ned_m_s.z - self.v_d_m_s;
        rows.push(z, SIGMA_M_S * SIGMA_M_S, &h, &VARIABLES[VELOCITY + 2]);
    }
}

/// The source: a measurement at every half second past a whole one, in (from, to].
pub struct DownVelocity {
    next_s: f64,
    to_s: f64,
}

impl DownVelocity {
    /// The measurements between `from_s` and `to_s`.
    pub fn between(from_s: f64, to_s: f64) -> Self {
        DownVelocity {
            next_s: (from_s - 0.5).floor() + 1.5,
            to_s,
        }
    }
}

impl<const N: usize, C: Context + ?Sized> Source<N, C> for DownVelocity {
    fn next_time(&self) -> Option<f64> {
        (self.next_s <= self.to_s).then_some(self.next_s)
    }

    fn take(&mut self, imu: &mut C) -> Box<dyn Measurement<N>> {
        let t_s = self.next_s;
        self.next_s += 1.0;
        let v_d_m_s = imu.truth().map_or(0.0, |p| p.velocity_ned_m_s.z);
        Box::new(Down { t_s, v_d_m_s })
    }
}
