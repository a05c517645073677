//! A three-dimensional drive made of segments — straight, speed change, turn, climb — with its
//! speed, heading and pitch, their first two derivatives, and the roll of a coordinated turn,
//! all in closed form at any time.
//!
//! Each change follows a raised-cosine (sin²) rate profile, so speed, heading, pitch and roll are
//! continuous with their first derivatives at every segment boundary: the specific force and the
//! angular rate the IMU sees are continuous, and within a segment they are analytic. The vehicle
//! moves along its body x axis (no sideslip, no angle of attack).

use std::f64::consts::PI;

/// Standard gravity, m/s², for the bank angle of a coordinated turn (a prescribed roll, not the
/// navigation's gravity model).
const BANK_GRAVITY_M_S2: f64 = 9.806_65;

/// One piece of a drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    /// Everything held, s.
    Straight {
        /// Duration, s.
        duration_s: f64,
    },
    /// The speed changes by `delta_m_s` (negative: braking).
    SpeedChange {
        /// Duration, s.
        duration_s: f64,
        /// Speed change, m/s.
        delta_m_s: f64,
    },
    /// The heading changes by `heading_change_rad` (positive: to the right), banked as a
    /// coordinated turn.
    Turn {
        /// Duration, s.
        duration_s: f64,
        /// Heading change, rad.
        heading_change_rad: f64,
    },
    /// The pitch rises to `pitch_rad` and returns to its value before (a hill).
    Climb {
        /// Duration, s.
        duration_s: f64,
        /// The largest pitch reached, rad (negative: a dip).
        pitch_rad: f64,
    },
}

impl Segment {
    /// Its duration, s.
    pub fn duration_s(&self) -> f64 {
        match *self {
            Segment::Straight { duration_s }
            | Segment::SpeedChange { duration_s, .. }
            | Segment::Turn { duration_s, .. }
            | Segment::Climb { duration_s, .. } => duration_s,
        }
    }
}

/// A quantity with its first two time derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Jet {
    /// The value.
    pub value: f64,
    /// Its rate.
    pub rate: f64,
    /// Its second derivative.
    pub accel: f64,
}

/// The drive's state at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Speed along the body x axis, m/s.
    pub speed: Jet,
    /// Heading (yaw) ψ, rad.
    pub yaw: Jet,
    /// Pitch θ, rad.
    pub pitch: Jet,
    /// Roll φ, rad.
    pub roll_rad: f64,
    /// Its rate φ̇, rad/s.
    pub roll_rate_rad_s: f64,
}

/// A drive: where each quantity starts and the segments that follow.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    /// Speed at t = 0, m/s.
    pub speed0_m_s: f64,
    /// Heading at t = 0, rad.
    pub yaw0_rad: f64,
    /// The segments in order.
    pub segments: Vec<Segment>,
}

/// ∫₀ᵗ of the unit-area raised cosine over [0, T] and its first two derivatives: the fraction of a
/// change made by time t, with its rate and acceleration.
///
/// # Formula
/// r(t) = (2/T) sin²(πt/T) (area 1), F(t) = t/T − sin(2πt/T)/(2π), F′ = r, F″ = (2π/T²) sin(2πt/T).
fn raised_cosine(t: f64, duration_s: f64) -> Jet {
    let x = t / duration_s;
    let w = 2.0 * PI * x;
    Jet {
        value: x - w.sin() / (2.0 * PI),
        rate: (1.0 - w.cos()) / duration_s,
        accel: 2.0 * PI * w.sin() / (duration_s * duration_s),
    }
}

/// A hill: 0 at both ends, 1 at the middle, with zero rate at both ends.
///
/// # Formula
/// h(t) = sin²(πt/T) = (1 − cos 2πt/T)/2, h′ = (π/T) sin(2πt/T), h″ = (2π²/T²) cos(2πt/T).
fn hill(t: f64, duration_s: f64) -> Jet {
    let w = 2.0 * PI * t / duration_s;
    Jet {
        value: 0.5 * (1.0 - w.cos()),
        rate: PI / duration_s * w.sin(),
        accel: 2.0 * PI * PI / (duration_s * duration_s) * w.cos(),
    }
}

impl Drive {
    /// The total duration, s.
    pub fn duration_s(&self) -> f64 {
        self.segments.iter().map(Segment::duration_s).sum()
    }

    /// The motion at time `t` (s from the start; clamped to the drive).
    pub fn motion(&self, t: f64) -> Motion {
        let mut speed = Jet {
            value: self.speed0_m_s,
            ..Jet::default()
        };
        let mut yaw = Jet {
            value: self.yaw0_rad,
            ..Jet::default()
        };
        let mut pitch = Jet::default();
        let mut start = 0.0;
        for seg in &self.segments {
            let d = seg.duration_s();
            let local = (t - start).clamp(0.0, d);
            let inside = t >= start && t < start + d;
            match *seg {
                Segment::Straight { .. } => {}
                Segment::SpeedChange { delta_m_s, .. } => {
                    add(&mut speed, raised_cosine(local, d), delta_m_s, inside)
                }
                Segment::Turn {
                    heading_change_rad, ..
                } => add(
                    &mut yaw,
                    raised_cosine(local, d),
                    heading_change_rad,
                    inside,
                ),
                Segment::Climb { pitch_rad, .. } => {
                    add(&mut pitch, hill(local, d), pitch_rad, inside)
                }
            }
            start += d;
        }
        let (roll_rad, roll_rate_rad_s) = bank(&speed, &yaw, &pitch);
        Motion {
            roll_rad,
            roll_rate_rad_s,
            speed,
            yaw,
            pitch,
        }
    }
}

/// Adds `scale` times the profile `f` to `q`: its value always (a finished change stays), its
/// derivatives only while the segment lasts.
fn add(q: &mut Jet, f: Jet, scale: f64, inside: bool) {
    q.value += scale * f.value;
    if inside {
        q.rate += scale * f.rate;
        q.accel += scale * f.accel;
    }
}

/// The roll of a coordinated turn, tan φ = s·ψ̇·cos θ / g₀, and its rate (rad, rad/s).
fn bank(speed: &Jet, yaw: &Jet, pitch: &Jet) -> (f64, f64) {
    let (sp, cp) = pitch.value.sin_cos();
    let u = speed.value * yaw.rate * cp / BANK_GRAVITY_M_S2;
    let du = (speed.rate * yaw.rate * cp + speed.value * yaw.accel * cp
        - speed.value * yaw.rate * sp * pitch.rate)
        / BANK_GRAVITY_M_S2;
    // φ = atan u, φ′ = u′/(1 + u²).
    (u.atan(), du / (1.0 + u * u))
}

/// The default drive's segments: 600 s from rest that accelerate, brake, turn both ways, climb
/// and dip, so that every accelerometer and gyro axis is excited (what makes all six biases
/// observable from GNSS).
const DEFAULT_SEGMENTS: [Segment; 28] = {
    use Segment::{Climb, SpeedChange, Straight, Turn};
    [
        Straight { duration_s: 30.0 },
        SpeedChange {
            duration_s: 10.0,
            delta_m_s: 12.0,
        },
        Straight { duration_s: 20.0 },
        Turn {
            duration_s: 12.0,
            heading_change_rad: deg(90.0),
        },
        Straight { duration_s: 15.0 },
        Climb {
            duration_s: 30.0,
            pitch_rad: deg(6.0),
        },
        SpeedChange {
            duration_s: 8.0,
            delta_m_s: 6.0,
        },
        Straight { duration_s: 25.0 },
        Turn {
            duration_s: 20.0,
            heading_change_rad: deg(-180.0),
        },
        Straight { duration_s: 20.0 },
        SpeedChange {
            duration_s: 10.0,
            delta_m_s: -10.0,
        },
        Turn {
            duration_s: 15.0,
            heading_change_rad: deg(135.0),
        },
        Straight { duration_s: 25.0 },
        Climb {
            duration_s: 25.0,
            pitch_rad: deg(-5.0),
        },
        SpeedChange {
            duration_s: 10.0,
            delta_m_s: 14.0,
        },
        Straight { duration_s: 40.0 },
        Turn {
            duration_s: 18.0,
            heading_change_rad: deg(-120.0),
        },
        Straight { duration_s: 30.0 },
        SpeedChange {
            duration_s: 12.0,
            delta_m_s: -17.0,
        },
        Straight { duration_s: 15.0 },
        Turn {
            duration_s: 10.0,
            heading_change_rad: deg(75.0),
        },
        SpeedChange {
            duration_s: 10.0,
            delta_m_s: 10.0,
        },
        Climb {
            duration_s: 20.0,
            pitch_rad: deg(4.0),
        },
        Straight { duration_s: 30.0 },
        Turn {
            duration_s: 16.0,
            heading_change_rad: deg(160.0),
        },
        Straight { duration_s: 25.0 },
        SpeedChange {
            duration_s: 14.0,
            delta_m_s: -15.0,
        },
        Straight { duration_s: 55.0 },
    ]
};

impl Drive {
    /// The default drive (its segments in [`DEFAULT_SEGMENTS`]), starting at rest heading 30°.
    pub fn default_drive() -> Self {
        Drive {
            speed0_m_s: 0.0,
            yaw0_rad: deg(30.0),
            segments: DEFAULT_SEGMENTS.to_vec(),
        }
    }
}

/// Degrees to radians, in a constant.
const fn deg(x: f64) -> f64 {
    x * (PI / 180.0)
}
