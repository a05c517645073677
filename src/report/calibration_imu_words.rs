//! The sentences of a three-axis calibration's page, chosen by its numbers: the NIS sum above
//! or below its band and what that says of the GNSS σ's; the yaw and the biases the drive did
//! not determine; the innovations' whiteness (a correlated GNSS error).

use super::rich::rich;
use crate::calibrate::imu::summary::Summary;
use crate::format::{short, sig};

/// The NIS test in words, as HTML: what a sum above or below its band means.
pub fn nis_words(s: &Summary) -> String {
    let n = &s.nis;
    let expected = n.dof as f64 / (n.fixes.max(1) as f64);
    let band = format!(
        "its band [{}, {}] (mean {} per fix against the {} expected)",
        sig(n.lower, 5),
        sig(n.upper, 5),
        sig(n.mean, 3),
        sig(expected, 3)
    );
    let sum = sig(n.sum, 5);
    let text = if n.verdict == "pass" {
        format!(
            "The NIS sum, {sum}, lies in {band}: the innovations are as large as the filter predicts."
        )
    } else if n.sum > n.upper {
        format!(
            "The NIS sum, {sum}, is above {band}: the innovations are larger than the filter \
             predicts. The GNSS σ's assumed (gnss_position_sigma_m, gnss_velocity_sigma_m_s) are \
             too small, or the IMU's noise is larger than assumed, or the model misses something \
             (a lever arm, a time offset between the logs, a scale factor); the σ's of the \
             estimates are then too small."
        )
    } else {
        format!(
            "The NIS sum, {sum}, is below {band}: the innovations are smaller than the filter \
             predicts. The GNSS σ's assumed are too large for this receiver (where the GNSS \
             dominates S, scaling them by √(Σ NIS / Σ m_{{i}}) = {} would bring the mean to its \
             expectation), or the GNSS error is correlated from fix to fix and the filter \
             follows it; the σ's of the estimates are then too large, and a correlated error \
             makes them unreliable either way.",
            sig((n.sum / n.dof.max(1) as f64).sqrt(), 2)
        )
    };
    rich(&text)
}

/// "a", "a and b", "a, b and c".
pub(super) fn listed(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The sentences the numbers choose: the yaw, the undetermined biases, the innovations'
/// whiteness.
pub fn findings(s: &Summary) -> Vec<String> {
    let a = &s.attitude_deg;
    let yaw_prior = s.alignment.sigma_yaw_deg;
    let mut out = vec![if a.yaw_identifiable {
        format!(
            "The yaw is determined by the drive: its σ at the end, {}°, is less than half of \
             the alignment's {}°; the drive's turns and speed changes tell the heading better \
             than the course it started from.",
            sig(a.sigma_yaw, 2),
            sig(yaw_prior, 2)
        )
    } else {
        format!(
            "The yaw is not determined: its σ at the end, {}°, is more than half of the \
             alignment's {}°. The drive's turns and speed changes, if it has any, did not tell \
             the heading better than the gyros' noise lets it drift, so the yaw is about the \
             course at the alignment carried by the gyros, and the heading offset assumed \
             (heading_offset_sigma_deg) stays in its σ.",
            sig(a.sigma_yaw, 2),
            sig(yaw_prior, 2)
        )
    }];
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
    if loose.is_empty() {
        out.push(
            "All six biases are determined by the drive: each σ at the end is at most half of \
             the σ its prior and its random walk alone would leave."
                .to_string(),
        );
    } else {
        let tilt = !s.accel_bias_m_s2.identifiable[0] || !s.accel_bias_m_s2.identifiable[1];
        out.push(format!(
            "Not determined: {}. Each σ at the end is more than half of the σ its prior and \
             its random walk alone would leave, so the value in Table 1 is the prior's guess \
             moved a little, not a measurement.{}",
            listed(&loose),
            if tilt {
                " A horizontal accelerometer bias and a tilt of the attitude move the velocity \
                 alike until the heading changes: a drive without turns cannot tell them apart."
            } else {
                ""
            }
        ));
    }
    out.extend(scale_finding(s));
    out.extend(whiteness_findings(s));
    out
}

/// The scale factors in words, when estimated: which the drive determined and why the others
/// are not.
fn scale_finding(s: &Summary) -> Option<String> {
    let (g, a) = (
        s.gyro_scale_factor_ppm.as_ref()?,
        s.accel_scale_factor_ppm.as_ref()?,
    );
    let mut open = Vec::new();
    let mut shut = Vec::new();
    for (t, what) in [(g, "gyro"), (a, "accelerometer")] {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let name = format!("the {what} scale factor {axis}");
            if t.identifiable[i] {
                &mut shut
            } else {
                &mut open
            }
            .push(name);
        }
    }
    Some(if open.is_empty() {
        "All six scale factors are determined by the drive: each σ at the end is at most half          of its prior's."
            .to_string()
    } else {
        format!(
            "{}Not determined: {}. A scale factor shows only through the motion it multiplies —              a gyro's through turning about its axis, an accelerometer's through specific force              along it beyond what its bias takes up — so a drive without turns and at nearly              constant speed leaves it at its prior.",
            if shut.is_empty() {
                String::new()
            } else {
                format!("Determined by the drive: {}. ", listed(&shut))
            },
            listed(&open)
        )
    })
}

/// The whiteness tests in words: a correlated GNSS position error, a velocity model that misses
/// something slow, or white innovations.
pub(super) fn whiteness_findings(s: &Summary) -> Vec<String> {
    let failed = |prefix: &str| -> (Vec<String>, f64) {
        let w: Vec<_> = s
            .whiteness
            .iter()
            .filter(|w| w.component.starts_with(prefix) && w.test.verdict == "fail")
            .collect();
        let rho = w
            .iter()
            .filter_map(|w| w.test.autocorrelation.first().copied())
            .fold(f64::NAN, f64::max);
        (
            w.iter().map(|w| w.component.replace('_', " ")).collect(),
            rho,
        )
    };
    let (position, rho_p) = failed("position");
    let (velocity, rho_v) = failed("velocity");
    let mut out = Vec::new();
    if !position.is_empty() {
        out.push(format!(
            "The {} innovations are correlated from fix to fix (ρ̂(1) up to {}): the GNSS \
             position error is not white — a receiver's own filter, multipath and the \
             atmosphere make it slow — while the filter takes each fix's error as independent. \
             Each fix then carries less news than the filter credits it with, and the σ's of \
             the biases are too small.",
            listed(&position),
            sig(rho_p, 2)
        ));
    }
    if !velocity.is_empty() {
        out.push(format!(
            "The {} innovations are not white (ρ̂(1) up to {}): an error the model lacks — a \
             correlated GNSS velocity error, a scale factor, vibration — moves them slowly.",
            listed(&velocity),
            sig(rho_v, 2)
        ));
    }
    if position.is_empty() && velocity.is_empty() {
        let untestable = s.whiteness.iter().any(|w| w.test.verdict == "untestable");
        out.push(if untestable {
            "Too few fixes to test every component's innovations for whiteness.".to_string()
        } else {
            format!(
                "Every measured component's innovations are white at α = {} per test.",
                short(s.assumptions.false_alarm_rate)
            )
        });
    }
    out
}

/// What the χ² innovation gate did, in a sentence or two: off (and how to turn it on), or how
/// many fixes it rejected against the count chance explains, and the first of them.
pub fn gate_words(s: &Summary) -> String {
    let g = &s.gate;
    if !g.enabled {
        return "No innovation was gated: every fix updated the filter ([filter] \
                innovation_gate = true tests each fix's NIS against the χ² quantile at α and \
                leaves out those above it)."
            .to_string();
    }
    let n = g.rejected.len();
    let head = format!(
        "The χ² gate at α = {} tested {} fixes and rejected {n} (chance explains {}); the \
         rejected fixes are left out of the filter and of the tests above.",
        g.false_alarm_rate,
        g.tested,
        sig(g.expected_by_chance, 3)
    );
    let listed: Vec<String> = g
        .rejected
        .iter()
        .take(5)
        .map(|r| {
            format!(
                "line {} at {} s (NIS {} above {}, largest in {} at {}σ)",
                r.line,
                sig(r.t_s, 6),
                sig(r.nis, 3),
                sig(r.threshold, 3),
                r.component.replace('_', " "),
                sig(r.normalized, 3)
            )
        })
        .collect();
    match n {
        0 => head,
        _ => format!(
            "{head} {}: {}{}.",
            if n > 5 { "The first five" } else { "They" },
            listed.join("; "),
            if n > 5 {
                "; all in summary.json's gate"
            } else {
                ""
            }
        ),
    }
}
