//! The calibration page's part of `calibrate --estimate-noise`: a table of the estimated
//! statistics with their intervals, and the likelihood profile of each. A statistic the drive does
//! not determine is shown by the one bound it has, never by the value where the search stopped.
//! The words are shared with the report's section ([`super::noise`]).

use askama::Template;
use serde::Serialize;

use super::figures::figure;
use super::view::FigureView;
use super::{RenderError, rich};
use crate::format::{count, fixed, interval, percent, sig};
use crate::likelihood::{Key, KeyEstimate, NoiseEstimate};
use crate::plot::{self, ProfileSeries};

/// A key's symbol in the report's notation, `σ_{p}`.
pub(super) fn symbol(key: Key) -> String {
    match key.symbol().split_once('_') {
        Some((a, b)) => format!("{a}_{{{b}}}"),
        None => key.symbol().to_string(),
    }
}

/// A value of `key` with its unit, three significant digits.
pub(super) fn with_unit(x: f64, key: Key) -> String {
    format!("{} {}", sig(x, 3), key.unit())
}

/// What a drive says of a statistic, in words: its value and interval when identifiable, else
/// the one bound it gives (never the bare value).
pub fn estimate_words(k: &KeyEstimate) -> String {
    match (k.identifiable, k.lower > 0.0, k.upper) {
        (true, _, Some(u)) => {
            let (value, lower, upper) = interval(k.value, k.lower, u, 3);
            let unit = k.key.unit();
            format!("{value} {unit} [{lower}, {upper} {unit}]")
        }
        (_, false, Some(u)) => format!(
            "not identifiable: only an upper bound, {} ≤ {}",
            symbol(k.key),
            with_unit(u, k.key)
        ),
        (_, true, None) => format!(
            "not identifiable: only a lower bound, {} ≥ {}",
            symbol(k.key),
            with_unit(k.lower, k.key)
        ),
        _ => "not identifiable: the drive bounds it at neither end of the search".to_string(),
    }
}

/// The interval as text, an open end written as 0 or ∞; closed ends with the digits that
/// tell them from each other and from the estimate ([`interval`]).
pub(super) fn interval_words(k: &KeyEstimate) -> String {
    let (_, lo, hi) = interval(k.value, k.lower, k.upper.unwrap_or(f64::INFINITY), 3);
    let lower = if k.lower > 0.0 { lo } else { "0".to_string() };
    let upper = if k.upper.is_some() {
        hi
    } else {
        "∞".to_string()
    };
    format!("[{lower}, {upper}]")
}

/// The search's range as text.
pub(super) fn search_words(k: &KeyEstimate) -> String {
    format!(
        "[{}, {}]",
        sig(k.search_bounds[0], 2),
        sig(k.search_bounds[1], 2)
    )
}

/// The profile figure's series of `e`, with the truth of each key when known.
pub fn profile_series(e: &NoiseEstimate, truth: Option<&[f64]>) -> Vec<ProfileSeries> {
    e.keys
        .iter()
        .enumerate()
        .map(|(j, k)| ProfileSeries {
            title: format!("{}, {}: profile likelihood", symbol(k.key), k.key.name()),
            name: symbol(k.key),
            unit: k.key.unit().to_string(),
            points: k.profile.clone(),
            value: k.value,
            lower: (k.lower > 0.0).then_some(k.lower),
            upper: k.upper,
            bounds: (k.search_bounds[0], k.search_bounds[1]),
            truth: truth.and_then(|t| t.get(j).copied()),
        })
        .collect()
}

/// One estimated statistic on the calibration page.
#[derive(Clone, Debug, Serialize)]
pub struct EstimateRow {
    /// The statistic's symbol, as HTML.
    pub symbol_html: String,
    /// Its `[filter]` key.
    pub key: String,
    /// The estimate with its interval, or the one bound a non-identifiable statistic has.
    pub estimate_html: String,
    /// The interval, an open end written 0 or ∞.
    pub interval: String,
    /// The search's range.
    pub search: String,
    /// Whether the drive determines it.
    pub identifiable: bool,
}

/// The calibration page's part: the estimates, their intervals and profiles.
#[derive(Clone, Debug, Serialize, Template)]
#[template(path = "noise_estimate.html")]
pub struct EstimateView {
    /// The intervals' confidence.
    pub confidence: String,
    /// ℓ at the maximum.
    pub log_likelihood: String,
    /// Evaluations of ℓ.
    pub evaluations: String,
    /// One row per statistic.
    pub rows: Vec<EstimateRow>,
    /// The profiles.
    pub profile: FigureView,
}

/// The calibration page's view of `e`, its profile figure numbered `figure_number`.
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn.
pub fn estimate_view(e: &NoiseEstimate, figure_number: usize) -> Result<EstimateView, RenderError> {
    let profile = figure(
        "fig-noise-profile",
        figure_number,
        "Likelihood profile of each estimated statistic",
        &format!(
            "−2Δℓ of the GPS innovations against each statistic's value, every point the maximum over the other statistics: the points the interval's search evaluated and three more on each side, inside the interval and beyond its end (dots), joined by straight lines. The interval is where the profile lies below the χ²₁ quantile {} ({} confidence); an end that reaches the search's bound is open, and the statistic is then not identifiable from this drive.",
            fixed(e.deviance_threshold, 2),
            percent(e.confidence)
        ),
        plot::likelihood_profile(&profile_series(e, None), e.deviance_threshold),
    )?;
    Ok(EstimateView {
        confidence: percent(e.confidence),
        log_likelihood: fixed(e.log_likelihood, 3),
        evaluations: count(e.evaluations),
        rows: e
            .keys
            .iter()
            .map(|k| EstimateRow {
                symbol_html: rich::rich(&symbol(k.key)),
                key: k.key.name().to_string(),
                estimate_html: rich::rich(&estimate_words(k)),
                interval: interval_words(k),
                search: search_words(k),
                identifiable: k.identifiable,
            })
            .collect(),
        profile,
    })
}

/// The calibration page's part for `e` as HTML: a table of the estimates and the profile
/// figure (numbered `figure_number`), with the report's CSS classes.
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn or the template filled.
pub fn estimate_html(e: &NoiseEstimate, figure_number: usize) -> Result<String, RenderError> {
    Ok(estimate_view(e, figure_number)?.render()?)
}
