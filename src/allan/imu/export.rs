//! The files of `accelcal allan --imu`, as bytes: `allan.json` (every channel, each sensor's
//! largest terms), `imu.yaml` (Kalibr / OpenVINS / VINS-Mono keys and a KF-GINS `imunoise`
//! block) and `noise.toml` (the three-axis study's `[imu]` keys). No IO.

use serde_json::{Map, Value, json};

use super::{ImuAnalysis, Largest, correlation_time_s, fitted_correlation_time, value_or_bound};
use crate::allan::export::{AllanRecord, GAUSS_MARKOV_PEAK_RATIO, num, ten_digits};
use crate::allan::{Analysis, Reading, Term};
use crate::format::sig;
use crate::input::records::{Channel, Sensor};

/// Degrees per radian.
const DEG_PER_RAD: f64 = 180.0 / std::f64::consts::PI;
/// Seconds per hour.
const S_PER_H: f64 = 3600.0;
/// m/s² per mGal (1 Gal = 1 cm/s²).
const M_S2_PER_MGAL: f64 = 1e-5;

/// The terms each sensor's summary gives.
const SUMMARY_TERMS: [Term; 3] = [
    Term::VelocityRandomWalk,
    Term::BiasInstability,
    Term::AccelerationRandomWalk,
];

/// One channel's record of `allan.json`: the one-column form's `allan.json` as it is for an
/// accelerometer; for a gyro the same numbers under the gyro's names and units (`_rad_s` for
/// `_m_s2` in σ(τ), the terms by [`Sensor::term_key`]).
pub fn channel_record(channel: Channel, a: &Analysis) -> Value {
    let mut v = serde_json::to_value(AllanRecord::new(a)).expect("serializable");
    if channel.sensor() == Sensor::Gyroscope
        && let Value::Object(record) = &mut v
    {
        let renamed: Map<String, Value> = std::mem::take(record)
            .into_iter()
            .map(|(k, v)| (k.replace("_m_s2", "_rad_s"), v))
            .collect();
        *record = renamed;
        if let Some(Value::Object(fit)) = record.get_mut("fit") {
            for term in Term::ALL {
                let from = Sensor::Accelerometer.term_key(term);
                let to = Sensor::Gyroscope.term_key(term);
                if let Some(value) = fit.remove(from) {
                    fit.insert(to.to_string(), value);
                }
                if let Some(Value::Array(model)) = fit.get_mut("model") {
                    for key in model.iter_mut().filter(|k| k.as_str() == Some(from)) {
                        *key = Value::from(to);
                    }
                }
            }
        }
    }
    v
}

fn largest_record(l: &Largest) -> Value {
    json!({
        "value": l.value,
        "upper_bound": l.upper_bound,
        "axis": l.channel.column(),
        "reading": l.reading.key(),
    })
}

/// `allan.json` of the IMU (without the log's name, so that a bag, its MCAP and its CSV export
/// give the same bytes): `channels` (each channel's record, [`channel_record`]) and
/// `sensors` (per sensor, each term's largest value across its axes, the axis it comes from,
/// whether it is an upper bound, and that axis's reading).
pub fn allan_json(imu: &ImuAnalysis) -> String {
    let channels: Map<String, Value> = imu
        .channels
        .iter()
        .map(|c| {
            (
                c.channel.column().to_string(),
                channel_record(c.channel, &c.analysis),
            )
        })
        .collect();
    let mut sensors = Map::new();
    for sensor in Sensor::ALL {
        let axes: Vec<&str> = imu.of(sensor).map(|c| c.channel.column()).collect();
        if axes.is_empty() {
            continue;
        }
        let mut s = Map::new();
        s.insert("axes".to_string(), json!(axes));
        for term in SUMMARY_TERMS {
            if let Some(l) = imu.largest(sensor, term) {
                s.insert(sensor.term_key(term).to_string(), largest_record(&l));
            }
        }
        sensors.insert(sensor.key().to_string(), Value::Object(s));
    }
    let record = json!({
        "samples": imu.samples,
        "sample_period_s": imu.sample_period_s,
        "confidence": imu.confidence,
        "channels": channels,
        "sensors": sensors,
    });
    let mut s = serde_json::to_string_pretty(&record).expect("serializable");
    s.push('\n');
    s
}

/// Which reading each channel's terms come from, as comment lines.
fn readings_comment(imu: &ImuAnalysis) -> String {
    let words: Vec<String> = imu
        .channels
        .iter()
        .map(|c| {
            let g = &c.analysis.fit.goodness;
            match c.analysis.reading {
                Reading::Fit => format!("{} fit (p = {})", c.channel.column(), sig(g.p_value, 2)),
                Reading::Ieee952 => format!(
                    "{} IEEE 952 off the curve (fit rejected, p = {})",
                    c.channel.column(),
                    sig(g.p_value, 2)
                ),
            }
        })
        .collect();
    format!(
        "# Readings (goodness of fit at α = 0.01; where the model fit is rejected the terms are\n\
         # read off the curve as IEEE Std 952 does): {}.\n",
        words.join(", ")
    )
}

/// The comment after a key of `imu.yaml`: units, which axis, bound or estimate, discrete value.
fn key_comment(l: &Largest, unit: &str, discrete: f64, discrete_unit: &str) -> String {
    let bound = if l.upper_bound {
        ", an upper bound (not resolved)"
    } else {
        ""
    };
    format!(
        "  # {unit}; the largest of the axes, on {}{bound}; discrete at the log's rate: {} {discrete_unit}",
        l.channel.column(),
        sig(discrete, 4)
    )
}

/// `imu.yaml`: the four continuous-time keys of Kalibr, OpenVINS and VINS-Mono (each the
/// largest across the sensor's axes) with `update_rate`, and KF-GINS's `imunoise` block.
///
/// # Formula
/// Discrete equivalents at the rate f = 1/τ₀ (Kalibr wiki, "IMU Noise Model"; Trawny &
/// Roumeliotis 2005): white noise σ_d = σ·√f, random walk σ_bd = σ_b/√f.
/// KF-GINS units: ARW °/√h = rad/√s·(180/π)·60, VRW m/s/√h = m/s/√s·60; the bias a first-order
/// Gauss–Markov process, σ_b and τ_b fitted where a hump shows them
/// ([`crate::allan::gauss_markov_fit`]), else σ_b = B/0.6643 and τ_b = τ_min/1.89 (IEEE Std 952,
/// annex C).
pub fn imu_yaml(imu: &ImuAnalysis, source: &str) -> String {
    let rate_hz = 1.0 / imu.sample_period_s;
    let mut s = format!(
        "# IMU noise measured by `accelcal allan --imu` from {source}: {} samples per channel at\n\
         # {} Hz (τ₀ = {} s), {} % intervals.\n\
         # Continuous-time densities in SI units, as Kalibr, OpenVINS and VINS-Mono read them; each\n\
         # the largest across the sensor's axes (as those tools' users are told to take). Discrete\n\
         # equivalents at the log's rate f in the comments: noise σ·√f, random walk σ_b/√f.\n",
        imu.samples,
        sig(rate_hz, 6),
        sig(imu.sample_period_s, 6),
        sig(100.0 * imu.confidence, 3)
    );
    s.push_str(&readings_comment(imu));
    let keys: [(Sensor, Term, &str, &str, bool, &str); 4] = [
        (
            Sensor::Accelerometer,
            Term::VelocityRandomWalk,
            "accelerometer_noise_density",
            "m/s²/√Hz (= m/s/√s)",
            true,
            "m/s²",
        ),
        (
            Sensor::Accelerometer,
            Term::AccelerationRandomWalk,
            "accelerometer_random_walk",
            "m/s³/√Hz (= m/s²/√s)",
            false,
            "m/s²",
        ),
        (
            Sensor::Gyroscope,
            Term::VelocityRandomWalk,
            "gyroscope_noise_density",
            "rad/s/√Hz (= rad/√s)",
            true,
            "rad/s",
        ),
        (
            Sensor::Gyroscope,
            Term::AccelerationRandomWalk,
            "gyroscope_random_walk",
            "rad/s²/√Hz (= rad/s/√s)",
            false,
            "rad/s",
        ),
    ];
    for (sensor, term, key, unit, white, discrete_unit) in keys {
        match imu.largest(sensor, term) {
            Some(l) => {
                let discrete = if white {
                    l.value * rate_hz.sqrt()
                } else {
                    l.value / rate_hz.sqrt()
                };
                s.push_str(&format!(
                    "{key}: {}{}\n",
                    num(l.value),
                    key_comment(&l, unit, discrete, discrete_unit)
                ));
            }
            None => s.push_str(&format!(
                "# {key}: left out, the log has no {} column\n",
                sensor.key()
            )),
        }
    }
    s.push_str(&format!("update_rate: {}\n", num(ten_digits(rate_hz))));
    s.push_str(&kf_gins_block(imu));
    s
}

/// One KF-GINS vector: `f` of each axis of `sensor`, in axis order.
fn per_axis(imu: &ImuAnalysis, sensor: Sensor, f: AxisValue) -> String {
    let values: Vec<String> = imu.of(sensor).map(|c| num(f(&c.analysis))).collect();
    format!("[{}]", values.join(", "))
}

/// The term's value, else its upper bound.
fn value_of(a: &Analysis, term: Term) -> f64 {
    a.term(term).map_or(f64::NAN, |t| value_or_bound(t).0)
}

/// The stationary σ of an axis's first-order Gauss–Markov bias: the fitted σ where the log
/// resolves the term ([`crate::allan::gauss_markov_fit`]), else the σ whose Allan deviation
/// peaks at the axis's B (or B's bound), B/0.6643 (IEEE Std 952, annex C).
fn gauss_markov_sigma(a: &Analysis) -> f64 {
    a.gauss_markov
        .sigma
        .filter(|_| a.gauss_markov.resolved)
        .unwrap_or_else(|| value_of(a, Term::BiasInstability) / GAUSS_MARKOV_PEAK_RATIO)
}

/// A number of one axis's analysis.
type AxisValue = fn(&Analysis) -> f64;

/// KF-GINS's `imunoise` block (its `kf-gins.yaml`: arw °/√h, vrw m/s/√h, gbstd °/h, abstd mGal,
/// corrtime h; one correlation time for every axis, the largest of the axes').
fn kf_gins_block(imu: &ImuAnalysis) -> String {
    let mut s = String::from(
        "# KF-GINS (i2Nav) `imunoise`: arw °/√h, vrw m/s/√h; gbstd °/h and abstd mGal the stationary\n\
         # σ of a first-order Gauss–Markov bias: the fitted σ where the axis's Allan variance shows\n\
         # the hump, else B/0.6643 (B an upper bound where unresolved); corrtime h, the largest\n\
         # fitted T_c of the axes that show a hump, else the largest τ_min/1.89 (a rule of thumb). Scale\n\
         # factors (gsstd, asstd) are not measured by a static log: set them from the datasheet.\n\
         imunoise:\n",
    );
    let rows: [(Sensor, &str, AxisValue); 4] = [
        (Sensor::Gyroscope, "arw", |a| {
            value_of(a, Term::VelocityRandomWalk) * DEG_PER_RAD * S_PER_H.sqrt()
        }),
        (Sensor::Accelerometer, "vrw", |a| {
            value_of(a, Term::VelocityRandomWalk) * S_PER_H.sqrt()
        }),
        (Sensor::Gyroscope, "gbstd", |a| {
            gauss_markov_sigma(a) * DEG_PER_RAD * S_PER_H
        }),
        (Sensor::Accelerometer, "abstd", |a| {
            gauss_markov_sigma(a) / M_S2_PER_MGAL
        }),
    ];
    for (sensor, key, f) in rows {
        if imu.of(sensor).next().is_some() {
            s.push_str(&format!("  {key}: {}\n", per_axis(imu, sensor, f)));
        }
    }
    // The fitted T_c where some axis resolves a hump (a rule of thumb elsewhere is not a
    // measurement to take the largest of), else the largest rule of thumb.
    let any_fitted = imu
        .channels
        .iter()
        .any(|c| fitted_correlation_time(&c.analysis));
    let longest = imu
        .channels
        .iter()
        .filter(|c| !any_fitted || fitted_correlation_time(&c.analysis))
        .max_by(|a, b| correlation_time_s(&a.analysis).total_cmp(&correlation_time_s(&b.analysis)));
    if let Some(c) = longest {
        let corrtime_s = correlation_time_s(&c.analysis);
        let note = if fitted_correlation_time(&c.analysis) {
            format!("fitted T_c of {}'s hump", c.channel.column())
        } else {
            format!(
                "not determined by the log: the rule of thumb τ_min/1.89 on {}, no hump resolved",
                c.channel.column()
            )
        };
        s.push_str(&format!(
            "  corrtime: {}  # {note}\n",
            num(corrtime_s / S_PER_H)
        ));
    }
    s
}

/// The `[imu]` keys of one sensor's bias in `noise.toml`: a Gauss–Markov process with the fitted
/// σ and T_c when some axis's Allan variance resolves the hump (the axis of the largest σ); else
/// as the one-column `noise.toml` chooses its model: a random walk with K when the largest K is
/// resolved, else a Gauss–Markov process when some axis resolves B (T_c then the rule of thumb
/// τ_min/1.89, not determined by the log), else a random walk with K's bound.
fn bias_keys(imu: &ImuAnalysis, sensor: Sensor, prefix: &str, unit: &str, k_unit: &str) -> String {
    let hump = imu
        .of(sensor)
        .filter(|c| fitted_correlation_time(&c.analysis))
        .max_by(|a, b| gauss_markov_sigma(&a.analysis).total_cmp(&gauss_markov_sigma(&b.analysis)));
    if let Some(c) = hump {
        let g = &c.analysis.gauss_markov;
        let (tc, lo, hi) = (
            correlation_time_s(&c.analysis),
            g.correlation_time_lower_s.unwrap_or(f64::NAN),
            g.correlation_time_upper_s.unwrap_or(f64::NAN),
        );
        let short = if tc < 1.0 {
            "# T_c is below the 1 s the study accepts: the study refuses this file until it is set.\n"
        } else {
            ""
        };
        return format!(
            "# A Gauss–Markov bias fitted to the hump of {}'s Allan variance: σ = {} {} [{}, {}],\n\
             # T_c = {} s [{}, {}] ({} % intervals).\n{short}\
             {prefix}_bias_model = \"gauss_markov\"\n{prefix}_bias_sigma_{unit} = {}\n\
             {prefix}_bias_correlation_time_s = {}\n",
            c.channel.column(),
            sig(gauss_markov_sigma(&c.analysis), 4),
            sensor.rate_unit(),
            sig(g.sigma_lower.unwrap_or(f64::NAN), 3),
            sig(g.sigma_upper, 3),
            sig(tc, 4),
            sig(lo, 3),
            sig(hi, 3),
            sig(100.0 * imu.confidence, 3),
            num(gauss_markov_sigma(&c.analysis)),
            num(tc)
        );
    }
    let (Some(k), Some(b)) = (
        imu.largest(sensor, Term::AccelerationRandomWalk),
        imu.largest(sensor, Term::BiasInstability),
    ) else {
        return String::new();
    };
    if k.upper_bound && !b.upper_bound {
        let a = imu
            .channels
            .iter()
            .find(|c| c.channel == b.channel)
            .map(|c| &c.analysis);
        let tau_b = a.map_or(f64::NAN, correlation_time_s);
        let sigma_b = b.value / GAUSS_MARKOV_PEAK_RATIO;
        // The three-axis study accepts τ_b from 1 s (config::ins::validate).
        let short = if tau_b < 1.0 {
            "# τ_b is below the 1 s the study accepts: the minimum is a vibration's, not a bias's\n\
             # (is the log static?); the study refuses this file until it is set.\n"
        } else {
            ""
        };
        format!(
            "# B = {} {} on {} dominates: a Gauss–Markov bias, σ_b = B/{GAUSS_MARKOV_PEAK_RATIO}, τ_b = τ_min/1.89\n\
             # (a rule of thumb: no axis's Allan variance resolves a hump, the log does not determine τ_b).\n{short}\
             {prefix}_bias_model = \"gauss_markov\"\n{prefix}_bias_sigma_{unit} = {}\n\
             {prefix}_bias_correlation_time_s = {}\n",
            sig(b.value, 4),
            sensor.term_unit(Term::BiasInstability),
            b.channel.column(),
            num(sigma_b),
            num(tau_b)
        )
    } else {
        let note = if k.upper_bound {
            " (an upper bound: no axis resolves it)"
        } else {
            ""
        };
        format!(
            "# A random walk of the bias, K the largest of the axes, on {}{note}.\n\
             {prefix}_bias_model = \"random_walk\"\n{prefix}_bias_random_walk_{k_unit} = {}\n",
            k.channel.column(),
            num(k.value)
        )
    }
}

/// `noise.toml`: the `[imu]` keys of the three-axis study (`accelcal config --model ins`) the log
/// measures, each the largest across the sensor's axes. The log's rate is left as a comment: the
/// study's GNSS rate must divide its `imu_rate_hz`.
pub fn noise_toml(imu: &ImuAnalysis, source: &str) -> String {
    let mut s = format!(
        "# The three-axis IMU's noise measured by `accelcal allan --imu` from {source}: the [imu]\n\
         # keys of `accelcal config --model ins`, each the largest across the sensor's axes. The\n\
         # log's rate is {} Hz (imu_rate_hz is left to the study). The one-axis keys of each\n\
         # accelerometer axis are in noise_<column>.toml beside this file.\n",
        num(ten_digits(1.0 / imu.sample_period_s))
    );
    s.push_str(&readings_comment(imu));
    s.push_str("model = \"ins\"\n\n[imu]\n");
    if let Some(n) = imu.largest(Sensor::Gyroscope, Term::VelocityRandomWalk) {
        s.push_str(&format!("gyro_arw_rad_per_sqrt_s = {}\n", num(n.value)));
    }
    if let Some(n) = imu.largest(Sensor::Accelerometer, Term::VelocityRandomWalk) {
        s.push_str(&format!("accel_vrw_m_s_per_sqrt_s = {}\n", num(n.value)));
    }
    s.push_str(&bias_keys(
        imu,
        Sensor::Gyroscope,
        "gyro",
        "rad_s",
        "rad_s_per_sqrt_s",
    ));
    s.push_str(&bias_keys(
        imu,
        Sensor::Accelerometer,
        "accel",
        "m_s2",
        "m_s2_per_sqrt_s",
    ));
    s
}

/// The file of an accelerometer axis's one-axis keys (`calibrate --config`).
pub fn axis_toml_file(channel: Channel) -> String {
    format!("noise_{}.toml", channel.column())
}

#[cfg(test)]
#[path = "export_tests.rs"]
mod tests;
