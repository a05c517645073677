//! The sentences of "A real drive in three axes" on the statistics estimated from the drive,
//! each chosen by the numbers: which keys the drive determines (value and profile-likelihood
//! interval) and which it leaves open, how the NIS test and the whiteness move with them, and
//! how far the biases move in their σ's.

use super::calibration_imu_words::listed;
use crate::calibrate::imu::noise::{ImuKey, KeyEstimate, NoiseEstimate};
use crate::calibrate::imu::summary::Summary;
use crate::format::{fixed, sig};
use crate::study::drive3d::RealDrive3d;

/// The whiteness verdicts that differ between the runs, as a clause: "; the velocity north
/// innovations' whiteness turns from pass to fail".
fn whiteness_change(p: &Summary, e: &Summary) -> String {
    let changed: Vec<String> = p
        .whiteness
        .iter()
        .filter_map(|wp| {
            let we = e.whiteness.iter().find(|w| w.component == wp.component)?;
            (we.test.verdict != wp.test.verdict).then(|| {
                format!(
                    "the {} innovations' whiteness turns from {} to {}",
                    wp.component.replace('_', " "),
                    wp.test.verdict,
                    we.test.verdict
                )
            })
        })
        .collect();
    if changed.is_empty() {
        ", with every whiteness verdict as it was".to_string()
    } else {
        format!("; {}", listed(&changed))
    }
}

/// A key's estimate in words: its value and interval, or what the drive leaves open.
pub fn key_words(k: &KeyEstimate) -> String {
    match (k.identifiable, k.lower, k.upper) {
        (true, Some(lo), Some(hi)) => {
            let (v, lo, hi) = crate::format::interval(k.value, lo, hi, 3);
            format!("{v} [{lo}, {hi}]")
        }
        (_, Some(lo), None) => format!("not determined: only a lower bound, ≥ {}", sig(lo, 3)),
        (_, None, Some(hi)) => format!("not determined: only an upper bound, ≤ {}", sig(hi, 3)),
        _ => format!(
            "not determined: bounded at neither end of the search [{}, {}]",
            sig(k.search_bounds[0], 2),
            sig(k.search_bounds[1], 2)
        ),
    }
}

/// What estimating the statistics gave and changed: the keys, the NIS test, the biases.
pub fn noise_findings(d: &RealDrive3d) -> Vec<String> {
    let (p, e) = (&d.plain.summary, &d.estimated.summary);
    let Some(est) = &e.noise_estimate else {
        return Vec::new();
    };
    let mut out = vec![keys_sentence(est, p)];
    let moved = if e.nis.verdict == p.nis.verdict {
        format!("its verdict stays {}", e.nis.verdict)
    } else {
        format!(
            "its verdict turns from {} to {}",
            p.nis.verdict, e.nis.verdict
        )
    };
    let side = |s: &Summary| {
        if s.nis.sum < s.nis.lower {
            "below"
        } else if s.nis.sum > s.nis.upper {
            "above"
        } else {
            "inside"
        }
    };
    out.push(format!(
        "With the estimate the NIS sum moves from {} to {} ({} its band [{}, {}]) and {moved}{}.",
        sig(p.nis.sum, 4),
        sig(e.nis.sum, 4),
        side(e),
        sig(e.nis.lower, 4),
        sig(e.nis.upper, 4),
        whiteness_change(p, e)
    ));
    out.push(bias_change(p, e));
    out
}

/// The keys the drive determines, each with its interval and against the default `p` assumed,
/// then those it leaves open.
fn keys_sentence(est: &NoiseEstimate, p: &Summary) -> String {
    let open: Vec<&str> = est
        .keys
        .iter()
        .filter(|k| !k.identifiable)
        .map(|k| k.key)
        .collect();
    let found: Vec<String> = est
        .keys
        .iter()
        .filter(|k| k.identifiable)
        .filter_map(|k| {
            let key = ImuKey::parse(k.key)?;
            let start = key.get(&p.assumptions);
            let (name, unit) = key.words().rsplit_once(", ")?;
            Some(format!(
                "{name} is {} {unit}{}",
                key_words(k),
                if start > 0.0 {
                    format!(", {} times the default", sig(k.value / start, 2))
                } else {
                    String::new()
                }
            ))
        })
        .collect();
    let n = est.keys.len();
    let determined = if found.is_empty() {
        String::new()
    } else {
        format!(
            "The drive determines {}: {} ({} evaluations of the likelihood). ",
            match (n, found.len()) {
                (1, _) => "the statistic searched".to_string(),
                (n, f) if f == n => format!("each of the {n} statistics searched"),
                (n, f) => format!("{f} of the {n} statistics searched"),
            },
            listed(&found),
            est.evaluations
        )
    };
    let left_open = if open.is_empty() {
        String::new()
    } else {
        format!(
            "{} not determine {}: an interval end reaches the search's bound, so the value used \
             is where the search stopped, not a measurement.",
            if found.is_empty() {
                "The drive does"
            } else {
                "It does"
            },
            listed(&open.iter().map(|k| k.to_string()).collect::<Vec<_>>())
        )
    };
    format!("{determined}{left_open}").trim_end().to_string()
}

/// The largest change of a bias between the two runs, in its σ, and any bias whose
/// determination changed.
fn bias_change(p: &Summary, e: &Summary) -> String {
    let mut largest = (0.0f64, String::new());
    let mut flipped = Vec::new();
    for (tp, te, what, unit) in [
        (&p.gyro_bias_rad_s, &e.gyro_bias_rad_s, "gyro", "rad/s"),
        (
            &p.accel_bias_m_s2,
            &e.accel_bias_m_s2,
            "accelerometer",
            "m/s²",
        ),
    ] {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let change = te.value[i] - tp.value[i];
            let r = change.abs() / tp.sigma[i];
            if r > largest.0 || largest.1.is_empty() {
                largest = (
                    r,
                    format!("the {what} bias {axis}, by {} {unit}", sig(change, 2)),
                );
            }
            if tp.identifiable[i] != te.identifiable[i] {
                flipped.push(format!(
                    "the {what} bias {axis} becomes {}",
                    if te.identifiable[i] {
                        "determined"
                    } else {
                        "undetermined"
                    }
                ));
            }
        }
    }
    let size = if largest.0 < 1.0 {
        "within its σ, the biases do not depend on these statistics"
    } else {
        "beyond its σ, the biases depend on the statistics assumed"
    };
    format!(
        "The bias that moves most is {}, {} times its σ with no configuration: {size}{}.",
        largest.1,
        fixed(largest.0, 2),
        if flipped.is_empty() {
            String::new()
        } else {
            format!("; {}", listed(&flipped))
        }
    )
}

/// The search's keys in words, for the section's opening: "the fixes' velocity σ".
pub fn keys_searched(keys: &[KeyEstimate]) -> String {
    let words: Vec<String> = keys
        .iter()
        .map(|k| {
            ImuKey::parse(k.key).map_or(k.key.to_string(), |key| {
                key.words()
                    .rsplit_once(", ")
                    .map_or(key.words(), |(w, _)| w)
                    .to_string()
            })
        })
        .collect();
    listed(&words)
}
