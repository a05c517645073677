//! The sentences of "A real drive in three axes", each chosen by the numbers the run measured:
//! which biases the drive determines and where Android's own gyro estimate lies against their
//! intervals; how far the attitude is from comma's pose in the filter's σ's, and whether the yaw
//! is determined; the NIS test and the whiteness and what they diagnose. What the estimated
//! statistics are and what they change: `real_drive_3d_noise`.

use super::calibration_imu_words::{listed, nis_words, whiteness_findings};
use super::rich::rich;
use crate::calibrate::imu::summary::Summary;
use crate::calibrate::imu::triad::{CONFIDENCE, Triad};
use crate::calibrate::robust::conditional_page_words;
use crate::format::{fixed, percent, sig};
use crate::stats::normal_bound;
use crate::study::drive3d::{AttitudeComparison, RealDrive3d, Run3d};
use statrs::distribution::{ContinuousCDF, Normal};

pub use super::real_drive_3d_noise::{key_words, keys_searched, noise_findings};

/// The angles' names, in the comparison's order.
pub const ANGLES: [&str; 3] = ["roll", "pitch", "yaw"];

/// `x` with its sign written: "+0.22", "−0.15".
pub fn signed(x: f64, decimals: usize) -> String {
    let s = fixed(x, decimals);
    if x > 0.0 && s.bytes().any(|b| (b'1'..=b'9').contains(&b)) {
        format!("+{s}")
    } else {
        s
    }
}

/// The probability that a normal variable lies within ±`k` σ of its mean.
///
/// # Formula
/// P(|x − μ| ≤ kσ) = 2Φ(k) − 1, Φ the standard normal CDF.
pub fn normal_within(k: f64) -> f64 {
    2.0 * Normal::standard().cdf(k) - 1.0
}

/// The fraction of `(difference, σ)` pairs with |difference| ≤ `k`·σ.
pub fn within(pairs: impl Iterator<Item = (f64, f64)>, k: f64) -> f64 {
    let (mut n, mut inside) = (0usize, 0usize);
    for (d, s) in pairs {
        n += 1;
        inside += usize::from(d.abs() <= k * s);
    }
    if n == 0 {
        f64::NAN
    } else {
        inside as f64 / n as f64
    }
}

/// The filtered difference of angle `k` against the reference, each with its σ.
pub fn filtered_pairs(a: &AttitudeComparison, k: usize) -> impl Iterator<Item = (f64, f64)> + '_ {
    a.filtered
        .iter()
        .zip(&a.filtered_sigma)
        .map(move |(d, s)| (d[k], s[k]))
}

/// The biases the drive left undetermined, as "the accelerometer bias x".
fn undetermined(s: &Summary) -> Vec<String> {
    let mut loose = Vec::new();
    for (t, what) in [
        (&s.gyro_bias_rad_s, "gyro"),
        (&s.accel_bias_m_s2, "accelerometer"),
    ] {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            if !t.identifiable[i] {
                loose.push(format!("the {what} bias {axis}"));
            }
        }
    }
    loose
}

/// The six biases with no configuration: which the drive determines, and Android's estimate
/// against the gyro biases' intervals.
pub fn bias_findings(d: &RealDrive3d) -> Vec<String> {
    let s = &d.plain.summary;
    let loose = undetermined(s);
    let mut out = vec![if loose.is_empty() {
        "The drive determines all six biases: each σ at the end is at most half of the σ its \
         prior and its random walk alone would leave."
            .to_string()
    } else {
        format!(
            "The drive determines {} of the 6 biases. It does not determine {}: each σ at the \
             end is more than half of the σ its prior and its random walk alone would leave, so \
             the table gives its interval and no value — the estimate is the prior's guess \
             moved a little, not a measurement.",
            6 - loose.len(),
            listed(&loose)
        )
    }];
    out.push(android_sentence(
        &s.gyro_bias_rad_s,
        &d.android_gyro_bias_rad_s,
    ));
    out
}

/// Android's own gyro bias estimate against the calibration's gyro biases.
fn android_sentence(g: &Triad, android: &[f64; 3]) -> String {
    let z = normal_bound(1.0 - CONFIDENCE);
    let off: Vec<(usize, f64)> = (0..3)
        .map(|i| (i, (g.value[i] - android[i]) / g.sigma[i]))
        .collect();
    let largest = (0..3)
        .map(|i| (g.value[i] - android[i]).abs())
        .fold(0.0, f64::max);
    let outside: Vec<String> = off
        .iter()
        .filter(|(_, r)| r.abs() > z)
        .map(|(i, r)| format!("{} ({} σ)", ["x", "y", "z"][*i], fixed(r.abs(), 1)))
        .collect();
    let common = format!(
        "The gyro biases come within {} rad/s ({} °/s) of Android's own estimate of the same \
         gyros",
        sig(largest, 2),
        sig(largest.to_degrees(), 2)
    );
    if outside.is_empty() {
        format!(
            "{common}, which lies inside every axis's {} interval.",
            percent(CONFIDENCE)
        )
    } else {
        format!(
            "{common}, but Android's value lies outside the {} interval on {}: either the \
             filter's σ's are too small for this drive or Android's estimate, made on the phone \
             while it logged, is off by that much.",
            percent(CONFIDENCE),
            listed(&outside)
        )
    }
}

/// The attitude against comma's pose: roll and pitch at the end and over the minute in the
/// filter's σ's, and the yaw, determined or not.
pub fn attitude_findings(r: &Run3d) -> Vec<String> {
    let a = &r.attitude;
    let Some(end) = a.filtered.last() else {
        return vec!["No fix of the calibration falls within comma's pose.".to_string()];
    };
    let end_sigma = a.filtered_sigma.last().copied().unwrap_or([f64::NAN; 3]);
    let one = [0, 1].map(|k| within(filtered_pairs(a, k), 1.0));
    let two = [0, 1].map(|k| within(filtered_pairs(a, k), 2.0));
    // Far above or below the normal's share within ±1σ (68 %): the fixes' differences are
    // correlated over the minute, so only a gross departure is named.
    let normal = format!(
        "a consistent filter's {} and {}",
        percent(normal_within(1.0)),
        percent(normal_within(2.0))
    );
    let spread = if one.iter().all(|f| *f > 0.9) {
        format!("more often than {normal}: the σ's are wider than these differences")
    } else if one.iter().any(|f| *f < 0.5) {
        format!("less often than {normal}: the differences are larger than the σ's")
    } else {
        format!("against {normal}")
    };
    let mut out = vec![format!(
        "At the end, roll and pitch differ from comma's pose by {}° and {}° ({} σ and {} σ of \
         the filter's). Over the {} fixes the filtered roll lies within ±1σ of it at {} of them \
         and within ±2σ at {}, the pitch at {} and {}, {spread}. comma's pose comes from the \
         same IMU with the camera and GNSS, so it is not independent, and its axes are the \
         camera's, not quite the IMU's.",
        signed(end[0], 2),
        signed(end[1], 2),
        fixed(end[0].abs() / end_sigma[0], 1),
        fixed(end[1].abs() / end_sigma[1], 1),
        a.t_s.len(),
        percent(one[0]),
        percent(two[0]),
        percent(one[1]),
        percent(two[1]),
    )];
    let att = &r.summary.attitude_deg;
    let yaw_off = format!(
        "{}° from comma's yaw ({} σ)",
        signed(end[2], 2),
        fixed(end[2].abs() / end_sigma[2], 1)
    );
    out.push(if att.yaw_identifiable {
        format!(
            "The yaw is determined by the drive: its σ at the end, {}°, is less than half of \
             the alignment's {}°, and it ends {yaw_off}.",
            sig(att.sigma_yaw, 2),
            sig(r.summary.alignment.sigma_yaw_deg, 2)
        )
    } else {
        format!(
            "The yaw is not determined by the drive: its σ at the end, {}°, is more than half \
             of the alignment's {}°, so it is the course at the alignment carried by the gyros, \
             not a measurement; it ends {yaw_off}.",
            sig(att.sigma_yaw, 2),
            sig(r.summary.alignment.sigma_yaw_deg, 2)
        )
    });
    out
}

/// The NIS test and the whiteness in words, as HTML, and whether the intervals are conditional.
pub fn test_findings(s: &Summary) -> Vec<String> {
    let mut out = vec![nis_words(s)];
    out.extend(whiteness_findings(s).iter().map(|w| rich(w)));
    out.extend(diagnosis(s).map(|d| rich(&d)));
    out.push(rich(&if s.intervals_conditional {
        format!(
            "Every σ and interval above {}: they hold only as far as the filter's model \
             describes this receiver, which these tests say it does not.",
            conditional_page_words(&s.rejected_by).replace('_', " ")
        )
    } else {
        "No test rejects the filter's model: the σ's and intervals above stand as they are."
            .to_string()
    }));
    out
}

/// What the NIS test and the position innovations' whiteness say together about the receiver:
/// a sum below its band with position innovations correlated from fix to fix is a receiver
/// that smooths its fixes (small fix-to-fix changes, a slow error); above its band with them,
/// a slow error the model lacks. `None` when the two do not combine so.
pub fn diagnosis(s: &Summary) -> Option<String> {
    let rho = s
        .whiteness
        .iter()
        .filter(|w| w.component.starts_with("position") && w.test.verdict == "fail")
        .filter_map(|w| w.test.autocorrelation.first().copied())
        .fold(f64::NAN, f64::max);
    if !rho.is_finite() {
        return None;
    }
    let n = &s.nis;
    if n.sum < n.lower {
        Some(format!(
            "Together the two tests describe a receiver that smooths its fixes: from one fix to \
             the next its position moves far less than a white error of the assumed σ would \
             (the NIS sum is {} of its band's lower end), while the error itself is slow \
             (ρ̂(1) up to {}). Neither larger nor smaller σ's make such an error white: the \
             filter follows it instead of averaging it out, and the intervals rest on a model \
             this receiver does not follow.",
            percent(n.sum / n.lower),
            sig(rho, 2)
        ))
    } else if n.sum > n.upper {
        Some(format!(
            "Together the two tests describe an error the model lacks: the innovations are \
             larger than S says (the NIS sum is {} times its band's upper end) and slow \
             (ρ̂(1) up to {}).",
            sig(n.sum / n.upper, 2),
            sig(rho, 2)
        ))
    } else {
        None
    }
}
