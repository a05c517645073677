//! What the user should know before trusting a calibration's numbers.

use crate::state::ErrorState;

use super::summary::FixReport;

/// How far, in σ of its innovation, the first fix may lie from the prior's prediction before
/// the prior is said to disagree with it (a consistent prior is beyond 5σ with probability
/// 5.7·10⁻⁷ per component).
pub const PRIOR_DISAGREEMENT_SIGMAS: f64 = 5.0;

/// The warnings about the prior p_c(0), v_c(0) and its σ's: the first fix's residual
/// r = δz − H·δx̂⁻ in units of its σ = √S_kk, per measured component, beyond
/// [`PRIOR_DISAGREEMENT_SIGMAS`]. Such a prior moves the estimates without a sign of it in
/// their σ (a velocity prior 900σ off flipped the bias's sign).
pub fn prior_warnings(first: Option<&FixReport>) -> Vec<String> {
    const _: () = assert!(ErrorState::MEAS == 2, "one key per measured component");
    let Some(fix) = first else {
        return Vec::new();
    };
    let keys = [
        ("position", "initial.position_mean_m", "m"),
        ("velocity", "initial.velocity_mean_m_s", "m/s"),
    ];
    (0..ErrorState::MEAS)
        .filter_map(|k| {
            let z = fix.residual[k] / fix.residual_sigma[k];
            let (name, key, unit) = keys[k];
            (z.abs() > PRIOR_DISAGREEMENT_SIGMAS).then(|| {
                format!(
                    "the prior disagrees with the first fix (t = {} s): its {name} residual is \
                     {} {unit}, {}σ of its predicted spread; check {key} and its σ (the \
                     estimates lean on this prior)",
                    fix.t_s,
                    crate::format::sig(fix.residual[k], 4),
                    crate::format::sig(z, 3)
                )
            })
        })
        .collect()
}
