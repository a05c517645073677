//! The scale factors of a 21-state calibration (`error_states = 21`): their end values with
//! σ's, intervals and identifiability in ppm, the warnings of those the drive left
//! undetermined, and their smoothed columns of `estimates.csv`.
//!
//! A scale factor is seen only through the motion it multiplies (F's columns −C_b^n·diag(f^b) and
//! −C_b^n·diag(ω_ib^b), Groves §14.2.6): a gyro's through rotation about its axis, an
//! accelerometer's through specific force along it beyond what its bias absorbs. A level drive
//! without turns leaves the gyros' undetermined, and the vertical accelerometer's, which reads
//! gravity alone, is hard to tell from its bias; their σ's then stay near the prior and the
//! summary says so (`identifiable: false`).

use super::Settings;
use super::smoother::Smoothed;
use super::step::{FixRecord, scale_sigmas};
use super::triad::{IDENTIFIABLE_SIGMA_RATIO, Triad, triad};
use crate::ins::error_state::holds;
use crate::ins::state::Block;

/// One million: a scale factor in ppm.
const PPM: f64 = 1e6;

/// The gyro and accelerometer scale factors at the last record, ppm, when the filter has them.
pub fn end_triads<const N: usize>(
    last: Option<&FixRecord<N>>,
    s: &Settings,
) -> Option<(Triad, Triad)> {
    if !holds::<N>(Block::GyroScale) {
        return None;
    }
    let ppm = |v: [f64; 3]| v.map(|x| x * PPM);
    Some(match last {
        Some(r) => {
            let (sg, sa) = scale_sigmas(&r.covariance);
            (
                triad(
                    ppm(r.gyro_scale.into()),
                    ppm(sg),
                    [s.gyro_scale_factor_sigma_ppm; 3],
                ),
                triad(
                    ppm(r.accel_scale.into()),
                    ppm(sa),
                    [s.accel_scale_factor_sigma_ppm; 3],
                ),
            )
        }
        None => (
            triad([f64::NAN; 3], [f64::NAN; 3], [1.0; 3]),
            triad([f64::NAN; 3], [f64::NAN; 3], [1.0; 3]),
        ),
    })
}

/// A warning per sensor triad whose scale factors the drive left (partly) undetermined.
pub fn warnings(gyro: Option<&Triad>, accel: Option<&Triad>) -> Vec<String> {
    let axes = ["x", "y", "z"];
    [("gyro", gyro), ("accelerometer", accel)]
        .into_iter()
        .filter_map(|(name, t)| {
            let t = t?;
            let open: Vec<&str> = (0..3)
                .filter(|&i| !t.identifiable[i])
                .map(|i| axes[i])
                .collect();
            (!open.is_empty()).then(|| {
                format!(
                    "the {name} scale factors of axes {} are not determined: their σ at the end \
                     is more than {IDENTIFIABLE_SIGMA_RATIO} of the prior's (the drive did not \
                     move those axes enough to tell scale from bias and noise)",
                    open.join(", ")
                )
            })
        })
        .collect()
}

/// `estimates.csv`'s smoothed scale-factor columns after the 15-state ones (none without them).
pub fn header<const N: usize>() -> &'static str {
    if holds::<N>(Block::GyroScale) {
        ",smoothed_sgx_ppm,smoothed_sgy_ppm,smoothed_sgz_ppm,smoothed_sax_ppm,smoothed_say_ppm,\
smoothed_saz_ppm,smoothed_sigma_sgx_ppm,smoothed_sigma_sgy_ppm,smoothed_sigma_sgz_ppm,\
smoothed_sigma_sax_ppm,smoothed_sigma_say_ppm,smoothed_sigma_saz_ppm"
    } else {
        ""
    }
}

/// The smoothed scale factors and their σ's of `sm`, ppm, onto `row` (nothing without them).
pub fn extend_row<const N: usize>(row: &mut Vec<f64>, sm: &Smoothed<N>) {
    if !holds::<N>(Block::GyroScale) {
        return;
    }
    row.extend(sm.gyro_scale.iter().map(|x| x * PPM));
    row.extend(sm.accel_scale.iter().map(|x| x * PPM));
    let (sg, sa) = scale_sigmas(&sm.covariance);
    row.extend(sg.map(|x| x * PPM));
    row.extend(sa.map(|x| x * PPM));
}
