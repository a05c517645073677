//! The error state as named blocks (OpenVINS's `ov_type::Type`: a variable is a typed block with
//! its place in the covariance): the navigation errors δr^n, δv^n, δψ, the bias errors δb_g, δb_a,
//! and the optional blocks: the scale-factor errors δs_g, δs_a and the IMU's mounting-angle
//! errors δμ in the vehicle. A [`Layout`] is the blocks a
//! configuration asks for, each at its offset; [`with_layout!`](crate::with_layout) is the one
//! dispatch from a layout to the filter's size `N`, a compile-time constant.
//!
//! Each supported size has exactly one layout ([`Layout::of`]), so generic code asks
//! `Layout::of::<N>()` where a block sits and whether it is there, and the compiler folds it.
//!
//! Adding a block: its [`Block`] variant with its components (`ins::names`), a layout in
//! [`LAYOUTS`] and an arm of [`with_layout!`](crate::with_layout), then its F and Q entries
//! (`error_state`, `discrete`), its prior (`setup`, `calibrate::imu::step`) and its correction
//! and output rows (`filter`, `ensemble`, `calibrate::imu::summary`).

use crate::state::Variable;

use super::names::VARIABLES;

/// A named block of the error state (three components each, in body axes or NED).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Block {
    /// δr^n: the position error, NED metres.
    Position,
    /// δv^n: the velocity error, NED m/s.
    Velocity,
    /// δψ: the attitude error, rad (Ĉ_b^n = (I + [δψ×])C_b^n).
    Attitude,
    /// δb_g: the gyro bias error, body axes, rad/s.
    GyroBias,
    /// δb_a: the accelerometer bias error, body axes, m/s².
    AccelBias,
    /// δs_g: the gyro scale factor error, body axes (optional).
    GyroScale,
    /// δs_a: the accelerometer scale factor error, body axes (optional).
    AccelScale,
    /// δμ: the error of the IMU's mounting in the vehicle, vehicle axes, rad
    /// (Ĉ_b^v = (I + \[δμ×\])C_b^v; optional: a car's, seen through its constraints).
    Mounting,
}

impl Block {
    /// Every block, in the order a layout holds them.
    pub const ALL: [Block; 8] = [
        Block::Position,
        Block::Velocity,
        Block::Attitude,
        Block::GyroBias,
        Block::AccelBias,
        Block::GyroScale,
        Block::AccelScale,
        Block::Mounting,
    ];

    /// The block's number of components.
    pub const fn size(self) -> usize {
        3
    }

    /// The block's components in words (three entries of `ins::names::VARIABLES`).
    pub fn variables(self) -> &'static [Variable] {
        let first = 3 * self as usize;
        &VARIABLES[first..first + self.size()]
    }

    /// The block's key in the JSON and the configuration.
    pub const fn key(self) -> &'static str {
        match self {
            Block::Position => "position",
            Block::Velocity => "velocity",
            Block::Attitude => "attitude",
            Block::GyroBias => "gyro_bias",
            Block::AccelBias => "accel_bias",
            Block::GyroScale => "gyro_scale",
            Block::AccelScale => "accel_scale",
            Block::Mounting => "mounting",
        }
    }
}

/// The error state's blocks in order, each starting where the one before ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    blocks: &'static [Block],
}

/// The supported layouts, one per size: the 15 core states (the first five blocks), with the
/// six scale factors 21, and a car's 18: the core and the mounting angles.
pub const LAYOUTS: [Layout; 3] = [
    Layout {
        blocks: Block::ALL.split_at(5).0,
    },
    Layout {
        blocks: Block::ALL.split_at(7).0,
    },
    Layout {
        blocks: &[
            Block::Position,
            Block::Velocity,
            Block::Attitude,
            Block::GyroBias,
            Block::AccelBias,
            Block::Mounting,
        ],
    },
];

impl Layout {
    /// The 15-state layout: navigation errors and the six biases.
    pub const CORE: Layout = LAYOUTS[0];
    /// The 21-state layout: the scale factors too.
    pub const WITH_SCALE: Layout = LAYOUTS[1];
    /// The 18-state layout of a car: the core and the IMU's mounting angles.
    pub const CAR: Layout = LAYOUTS[2];

    /// The layout of `states` error states (`filter.error_states`), if one is supported.
    pub const fn with_states(states: usize) -> Option<Layout> {
        let mut i = 0;
        while i < LAYOUTS.len() {
            if LAYOUTS[i].dim() == states {
                return Some(LAYOUTS[i]);
            }
            i += 1;
        }
        None
    }

    /// The layout of an error state of `N`; fails to compile (or panics) for a size no layout
    /// has.
    pub const fn of<const N: usize>() -> Layout {
        match Layout::with_states(N) {
            Some(l) => l,
            None => panic!("no error-state layout of this size"),
        }
    }

    /// The number of error states.
    pub const fn dim(self) -> usize {
        let mut n = 0;
        let mut i = 0;
        while i < self.blocks.len() {
            n += self.blocks[i].size();
            i += 1;
        }
        n
    }

    /// The blocks, in order.
    pub const fn blocks(self) -> &'static [Block] {
        self.blocks
    }

    /// Where `block` starts, if the layout holds it.
    pub const fn offset(self, block: Block) -> Option<usize> {
        let mut at = 0;
        let mut i = 0;
        while i < self.blocks.len() {
            if self.blocks[i] as usize == block as usize {
                return Some(at);
            }
            at += self.blocks[i].size();
            i += 1;
        }
        None
    }

    /// Whether the layout holds `block`.
    pub const fn has(self, block: Block) -> bool {
        self.offset(block).is_some()
    }

    /// Each state's component in words, in the state's order.
    pub fn variables(self) -> impl Iterator<Item = &'static Variable> {
        self.blocks.iter().flat_map(|b| b.variables().iter())
    }

    /// [`Layout::variables`] gathered, for what takes the names as one slice.
    pub fn variable_list(self) -> Vec<Variable> {
        self.variables().copied().collect()
    }
}

/// Runs `$body` with `$n` the error state's size of `$layout` as a `const usize`: the one place
/// the supported sizes meet the code generic over them.
///
/// ```
/// use accelcal::ins::state::Layout;
/// fn dim<const N: usize>() -> usize { N }
/// assert_eq!(accelcal::with_layout!(Layout::WITH_SCALE, N => dim::<N>()), 21);
/// ```
#[macro_export]
macro_rules! with_layout {
    ($layout:expr, $n:ident => $body:expr) => {{
        let layout: $crate::ins::state::Layout = $layout;
        if layout == $crate::ins::state::Layout::WITH_SCALE {
            const $n: usize = $crate::ins::state::Layout::WITH_SCALE.dim();
            $body
        } else if layout == $crate::ins::state::Layout::CAR {
            const $n: usize = $crate::ins::state::Layout::CAR.dim();
            $body
        } else {
            debug_assert_eq!(layout, $crate::ins::state::Layout::CORE);
            const $n: usize = $crate::ins::state::Layout::CORE.dim();
            $body
        }
    }};
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_each_layout_and_name_every_state() {
        for layout in LAYOUTS {
            let mut at = 0;
            for &b in layout.blocks() {
                assert_eq!(layout.offset(b), Some(at), "{b:?}");
                at += b.size();
            }
            assert_eq!(at, layout.dim());
            assert_eq!(Layout::with_states(layout.dim()), Some(layout));
            let keys: Vec<_> = layout.variables().map(|v| v.key).collect();
            assert_eq!(keys.len(), layout.dim());
            for &b in layout.blocks() {
                let first = keys[layout.offset(b).unwrap()];
                assert!(first.starts_with(b.key()), "{first} under {}", b.key());
            }
        }
        assert_eq!(Layout::CORE.dim(), 15);
        assert_eq!(Layout::WITH_SCALE.dim(), 21);
        assert_eq!(Layout::CAR.dim(), 18);
        assert_eq!(Layout::CAR.offset(Block::Mounting), Some(15));
        assert_eq!(Layout::with_states(24), None);
        assert!(!Layout::CORE.has(Block::GyroScale));
        assert_eq!(Layout::WITH_SCALE.offset(Block::AccelScale), Some(18));
    }

    #[test]
    fn the_dispatch_reaches_each_size() {
        fn dim<const N: usize>() -> usize {
            N
        }
        for layout in LAYOUTS {
            assert_eq!(crate::with_layout!(layout, N => dim::<N>()), layout.dim());
        }
    }
}
