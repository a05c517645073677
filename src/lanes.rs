//! Arithmetic on [`LANES`] realizations at once: [`Lanes`] is an array of `f64` whose operators
//! act lane by lane, written as plain loops over fixed-size arrays that the compiler turns into
//! vector instructions. [`Real`] lets one formula serve a single realization (`f64`) and a lane
//! group (`Lanes`) with the same operations in the same order, so both give the same bits.
// Lane loops index several arrays by the lane k; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Mul, Neg, Sub};

/// Realizations advanced together.
pub const LANES: usize = 8;

/// One `f64` per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lanes(pub [f64; LANES]);

/// The number types a formula can be written over: `f64` and [`Lanes`].
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// The same value in every lane.
    fn splat(v: f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
}

impl Real for Lanes {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Lanes([v; LANES])
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, o: Lanes) -> Lanes {
                let mut out = [0.0; LANES];
                for k in 0..LANES {
                    out[k] = self.0[k] $op o.0[k];
                }
                Lanes(out)
            }
        }
    };
}

lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        let mut out = [0.0; LANES];
        for k in 0..LANES {
            out[k] = -self.0[k];
        }
        Lanes(out)
    }
}

impl std::ops::AddAssign for Lanes {
    #[inline(always)]
    fn add_assign(&mut self, o: Lanes) {
        for k in 0..LANES {
            self.0[k] += o.0[k];
        }
    }
}

impl Lanes {
    /// The lanes' sum, in a fixed order: lane k + 4 added to lane k, then lane k + 2, then lane
    /// 1 (a tree three additions deep rather than a chain of dependent ones).
    #[inline(always)]
    pub fn sum(self) -> f64 {
        let v = self.0;
        let h: [f64; 4] = [v[0] + v[4], v[1] + v[5], v[2] + v[6], v[3] + v[7]];
        let q = [h[0] + h[2], h[1] + h[3]];
        q[0] + q[1]
    }
}

/// Defines `$vis fn $name(args) -> ret` that runs `$body(args)` compiled for the processor's
/// 256-bit vector unit (AVX2) when it has one, and as plain x86-64 code otherwise; `$body` and
/// everything hot it calls must be `#[inline(always)]` so that it is compiled into each variant.
/// The lane loops then advance four lanes per instruction. Only the instruction selection
/// changes: the operations, their order and so the results are the same either way (Rust never
/// contracts a product and a sum into a fused multiply-add on its own).
macro_rules! vectorized {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty => $body:path) => {
        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) -> $ret {
                    $body($($arg),*)
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the processor supports AVX2, checked just above.
                    return unsafe { avx2($($arg),*) };
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use vectorized;
