//! The integration of eq. (3) at the heart of a calibration: (p_c, v_c), where it starts (the
//! prior or the first fix), and the time a fix is applied at. The step itself is
//! [`Euler::step`], the simulation's.

use crate::state::step::Euler;

/// Integrated accelerometer (p_c, v_c), (m, m/s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integrated {
    /// p_c, m.
    pub pc_m: f64,
    /// v_c, m/s.
    pub vc_m_s: f64,
}

impl Integrated {
    /// eq. (3) over a step of `dt` with `half_dt2` = Δt²/2: [`Euler::step`], the simulation's.
    #[inline]
    pub fn advance(&mut self, a: f64, dt: f64, half_dt2: f64) {
        let euler = Euler {
            dt_s: dt,
            half_dt2_s2: half_dt2,
        };
        (self.pc_m, self.vc_m_s) = euler.step((self.pc_m, self.vc_m_s), a);
    }

    /// Whether both are finite.
    pub fn is_finite(&self) -> bool {
        self.pc_m.is_finite() && self.vc_m_s.is_finite()
    }

    /// Carried over a fraction `tau_s` of a step with the output `a` (itself at τ = 0).
    pub fn advanced(self, a: f64, tau_s: f64) -> Self {
        let mut out = self;
        if tau_s != 0.0 {
            let euler = Euler::new(tau_s);
            out.advance(a, euler.dt_s, euler.half_dt2_s2);
        }
        out
    }
}

/// Where the integration of eq. (3) starts: p_c(t₀), v_c(t₀) at the log's first sample t₀.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    /// The configured prior means (`[initial]`).
    Prior(Integrated),
    /// The first GPS fix (z_p, z_v) at `t_s`, carried back to t₀ by eq. (3) run backwards over
    /// Δ = t_fix − t₀ with the first sample's output a_c(t₀): v_c(t₀) = z_v − a_c(t₀)·Δ,
    /// p_c(t₀) = z_p − z_v·Δ + a_c(t₀)·Δ²/2, so that eq. (3) run forward from there with that
    /// output reaches the fix (exactly when the fix lies within the first step).
    FirstFix {
        /// Time of the fix, s.
        t_s: f64,
        /// z_p, m.
        position_m: f64,
        /// z_v, m/s.
        velocity_m_s: f64,
    },
}

impl Start {
    /// (p_c, v_c) at the first sample, at `t0_s` with the output `a0_m_s2`.
    pub fn at(&self, t0_s: f64, a0_m_s2: f64) -> Integrated {
        match *self {
            Start::Prior(start) => start,
            Start::FirstFix {
                t_s,
                position_m,
                velocity_m_s,
            } => {
                let dt = t_s - t0_s;
                Integrated {
                    pc_m: position_m - velocity_m_s * dt + 0.5 * a0_m_s2 * dt * dt,
                    vc_m_s: velocity_m_s - a0_m_s2 * dt,
                }
            }
        }
    }
}

/// The time a fix at `fix_t_s` is applied at, in the step from the sample at `sample_t_s`
/// (`last`: the log's last sample, which starts no step): its own, or the sample's for a fix
/// before the first sample or after the last (within half a median step, which
/// `Scan::of` checks).
pub fn update_time_s(fix_t_s: f64, sample_t_s: f64, last: bool) -> f64 {
    if last || fix_t_s < sample_t_s {
        sample_t_s
    } else {
        fix_t_s
    }
}
