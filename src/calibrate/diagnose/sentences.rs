//! The diagnosis in words: each sentence is chosen by a test of [`Diagnostics`] and carries that
//! test's numbers; none depends on where the logs came from.

use super::{BiasDiagnostics, Diagnostics, MeasurementDiagnostics, NisPerFix};
use crate::calibrate::nis::NisTest;
use crate::format::{percent, sig};

/// `x` to `digits` significant digits without trailing zeros: 6.00 → "6", 1600.0 → "1600".
fn num(x: f64, digits: usize) -> String {
    let s = sig(x, digits);
    if s.contains('×') || !s.contains('.') {
        return s;
    }
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Above this share of the predicted variance the GPS σ is the statistic a measurement's mean
/// square points to; below it, the integration's.
const GPS_SHARE_DOMINANT: f64 = 0.5;
/// Times of fixes outside the per-fix band named in a sentence.
const TIMES_NAMED: usize = 5;

/// The sentences for `d`, with the NIS test `nis` of the whole log, in the order a reader acts
/// on them: the NIS sum, each measurement's mean square and whiteness, the bias, the per-fix
/// count. One sentence says so when no test rejects.
pub fn findings(d: &Diagnostics, nis: &NisTest) -> Vec<String> {
    let mut out = Vec::new();
    out.extend(nis_sum(nis));
    for m in &d.measurements {
        out.extend(mean_square(m));
        out.extend(whiteness(m, d.fix_rate_hz, d.bias.bias_model));
    }
    out.extend(bias(&d.bias, d.false_alarm_rate));
    out.extend(per_fix(&d.nis_per_fix));
    if out.is_empty() {
        let lags = d
            .measurements
            .iter()
            .map(|m| m.whiteness.max_lag)
            .max()
            .unwrap_or(0);
        out.push(format!(
            "No diagnostic rejects at α = {}: the innovations are white at lags 1–{lags} and as \
             large as predicted, the per-fix NIS leave their band as often as chance explains, \
             and the bias is as steady as its model says.",
            percent(d.false_alarm_rate)
        ));
    } else if out.len() == 1 && nis.verdict != "pass" {
        out.push(
            "No single diagnostic points further: the innovations are white and each \
             measurement's mean square lies in its band, so the excess is spread thinly over \
             both; compare the filter's statistics with what the sensors' data sheets give."
                .to_string(),
        );
    }
    out
}

/// The NIS sum outside its band, in words.
fn nis_sum(n: &NisTest) -> Option<String> {
    if n.verdict == "pass" || n.fixes == 0 {
        return None;
    }
    let (side, what) = if n.sum > n.upper {
        (
            "above",
            "larger than the filter predicts: statistics it assumes are too small, or its \
             model misses an error the data have",
        )
    } else {
        (
            "below",
            "smaller than the filter predicts: statistics it assumes are too large",
        )
    };
    Some(format!(
        "The NIS sum {} is {side} its band [{}, {}]: the residuals are {what}.",
        num(n.sum, 5),
        num(n.lower, 5),
        num(n.upper, 5)
    ))
}

/// A measurement's mean square outside its band, with the statistic it points to.
fn mean_square(m: &MeasurementDiagnostics) -> Option<String> {
    let [lo, hi] = m.mean_square_band;
    let (larger, side) = match m.mean_square_place {
        "above" => (true, "larger"),
        "below" => (false, "smaller"),
        _ => return None,
    };
    let head = format!(
        "The {} innovations are {side} than predicted: their mean square in units of S is {} \
         (band [{}, {}]); ",
        m.measurement,
        num(m.mean_square, 3),
        num(lo, 3),
        num(hi, 3)
    );
    let suggested = m
        .gps_sigma_from_residuals
        .map(|s| format!("; the residuals suggest about {} {}", num(s, 2), m.unit));
    let pointer = if m.gps_share >= GPS_SHARE_DOMINANT {
        format!(
            "{} of that prediction is the GPS's, so {} = {} {} is too {}{}",
            percent(m.gps_share),
            m.gps_sigma_key,
            num(m.gps_sigma, 3),
            m.unit,
            if larger { "small" } else { "large" },
            suggested.unwrap_or_else(|| {
                "; the residuals are smaller than the integration's predicted spread alone, so \
                 filter.accel_noise_var_m2_s4 or a prior σ is too large as well"
                    .to_string()
            })
        )
    } else {
        format!(
            "only {} of that prediction is the GPS's, the rest the integration's, so \
             filter.accel_noise_var_m2_s4 (the accelerometer's white noise, vibration included) \
             or the bias's statistics are too {}",
            percent(m.gps_share),
            if larger { "small" } else { "large" }
        )
    };
    // Correlated residuals that are too large need not be the GPS's: the integration may drift
    // between fixes more than the filter assumes, and a larger GPS σ would hide that.
    let caveat = if larger && m.whiteness.verdict == "fail" && positively_correlated(m) {
        "; they are also correlated (see below), which a drifting integration explains as well \
         as a GPS σ that is too small"
    } else {
        ""
    };
    Some(format!("{head}{pointer}{caveat}."))
}

/// "1–3, 5, 7–8": sorted lags as runs.
pub fn lag_runs(lags: &[usize]) -> String {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &l in lags {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == l => *end = l,
            _ => runs.push((l, l)),
        }
    }
    runs.iter()
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}–{b}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Whether the lags outside their band are, on balance, positively correlated.
fn positively_correlated(m: &MeasurementDiagnostics) -> bool {
    let w = &m.whiteness;
    let sum: f64 = w
        .lags_outside
        .iter()
        .map(|&l| w.autocorrelation[l - 1])
        .sum();
    sum > 0.0
}

/// A measurement's innovations that are not white, with what that points to: slow errors
/// (positive correlation) or a filter that overshoots (negative).
fn whiteness(m: &MeasurementDiagnostics, rate_hz: f64, bias_model: &str) -> Option<String> {
    let w = &m.whiteness;
    if w.verdict == "untestable" {
        return Some(format!(
            "Too few fixes to test the {} innovations' whiteness: it needs {} fixes.",
            m.measurement,
            super::FIXES_PER_LAG
        ));
    }
    let last = *w.lags_outside.last()?;
    let plural = if w.lags_outside.len() == 1 { "" } else { "s" };
    let rate = num(rate_hz, 3);
    let seconds = |lags: usize| num(lags as f64 / rate_hz, 3);
    let (span, thinned) = match (rate_hz > 0.0, last == w.max_lag) {
        (false, _) => (String::new(), String::new()),
        (true, true) => (
            format!(", fixes up to {} s apart", seconds(last)),
            format!(
                " (the correlation outlasts lag {last}, {} s)",
                seconds(last)
            ),
        ),
        (true, false) => (
            format!(", fixes up to {} s apart", seconds(last)),
            format!(" (one fix every {} s or less often)", seconds(last + 1)),
        ),
    };
    let key = m.gps_sigma_key;
    let drift = if bias_model == "constant" {
        "bias_model = \"random_walk\""
    } else {
        "a faster bias drift"
    };
    let small = m.mean_square_place == "below";
    let cause = match (positively_correlated(m), m.measurement) {
        (false, measurement) => format!(
            "successive corrections overshoot: the filter's process noise \
             (filter.accel_noise_var_m2_s4) is large against {key}, or the GPS {measurement} \
             errors alternate from fix to fix; consider a smaller filter.accel_noise_var_m2_s4"
        ),
        (true, "velocity") if small => format!(
            "the GPS velocity errors are not white at {rate} Hz, or the integration's error \
             varies slowly in a way the filter's model does not (a drifting bias, gravity \
             through a changing pitch); the residuals are small, so rather than the smaller \
             {key} their size suggests, take a lower fix rate{thinned} or {drift}"
        ),
        (true, "velocity") => format!(
            "the GPS velocity errors are not white at {rate} Hz, or the integration drifts \
             between fixes more than the filter assumes (white noise and vibration above \
             filter.accel_noise_var_m2_s4, a drifting bias, gravity through a changing pitch); \
             consider a larger filter.accel_noise_var_m2_s4, {drift}, a larger {key} or a \
             lower fix rate{thinned}"
        ),
        (true, measurement) if small => format!(
            "the GPS {measurement} errors are not white at {rate} Hz, and small from fix to fix \
             because the filter follows them; rather than the smaller {key} their size \
             suggests, take a lower fix rate{thinned}"
        ),
        (true, measurement) => format!(
            "the GPS {measurement} errors are not white at {rate} Hz; consider a larger {key} \
             or a lower fix rate{thinned}"
        ),
    };
    let sign = if positively_correlated(m) {
        ""
    } else {
        "negatively "
    };
    Some(format!(
        "The {} innovations are {sign}correlated at lag{plural} {} (ρ̂(1) = {}, band ±{}{span}): \
         {cause}.",
        m.measurement,
        lag_runs(&w.lags_outside),
        num(w.autocorrelation.first().copied().unwrap_or(0.0), 2),
        num(w.band.first().copied().unwrap_or(1.0), 2),
    ))
}

/// A bias that strays from its smoothed path more than its model allows.
fn bias(b: &BiasDiagnostics, alpha: f64) -> Option<String> {
    if b.verdict != "fail" {
        return None;
    }
    let advice = match b.bias_model {
        "constant" => "the bias drifts over the run; try bias_model = \"random_walk\"".to_string(),
        "random_walk" => format!(
            "the bias moves more than its random walk allows (the smoothed bias spans {} σ); \
             try a larger filter.bias_random_walk_m_s2_per_sqrt_s",
            num(b.smoothed_range_sigmas, 2)
        ),
        _ => format!(
            "the bias moves more than its Gauss–Markov model allows (the smoothed bias spans {} \
             σ); try a larger filter.bias_var_m2_s4 or a shorter filter.bias_correlation_time_s",
            num(b.smoothed_range_sigmas, 2)
        ),
    };
    Some(format!(
        "The filtered bias strays from the smoothed one by up to {} σ of their difference (at t \
         = {} s; a bias that follows the filter's model stays within {} σ at α = {}): {advice}.",
        num(b.departure_max_sigmas, 3),
        num(b.departure_t_s, 4),
        num(b.departure_bound_sigmas, 3),
        percent(alpha)
    ))
}

/// More fixes outside the per-fix NIS band than chance explains.
fn per_fix(p: &NisPerFix) -> Option<String> {
    if p.verdict != "fail" {
        return None;
    }
    let times: Vec<String> = p
        .outside_t_s
        .iter()
        .take(TIMES_NAMED)
        .map(|t| num(*t, 4))
        .collect();
    let more = if p.outside > TIMES_NAMED { ", …" } else { "" };
    Some(format!(
        "{} fixes lie outside the per-fix NIS band [{}, {}] ({} above, {} below) where chance \
         explains at most {} (about {} expected), at t = {}{more} s.",
        p.outside,
        num(p.lower, 3),
        num(p.upper, 3),
        p.above,
        p.below,
        p.outside_bound,
        num(p.expected_outside, 2),
        times.join(", ")
    ))
}

#[cfg(test)]
mod tests;
