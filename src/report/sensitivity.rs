//! The report's section on the sensitivity to the assumed statistics: the figure of actual
//! against claimed σ, the table of detection probabilities, and words chosen from the numbers.

use super::RenderError;
use super::figures::figure;
use super::outline::{Figure, Numbers, Table};
use super::prose::and_list;
use super::view::{DetectionCell, DetectionRow, SensitivityView};
use crate::checks::CheckId;
use crate::ensemble::Engine;
use crate::format::{count, fixed, short, sig};
use crate::plot::{self, SensitivitySeries};
use crate::sensitivity::{AssumedStatistic, Sensitivity, SensitivityCase};
use crate::state::ErrorState;

/// Whether check `id` surely detects case `c`: its detection probability is at least 0.95 by a
/// bound that holds with 95 % confidence (exact, sampled or measured).
fn sure(c: &SensitivityCase, id: CheckId) -> bool {
    c.detection_interval(id).is_some_and(|(lo, _)| lo >= 0.95)
}

/// Whether check `id` surely misses case `c`: its detection probability is below 0.05 by such a
/// bound.
fn missed(c: &SensitivityCase, id: CheckId) -> bool {
    c.detection_interval(id).is_some_and(|(_, hi)| hi < 0.05)
}

fn cases_of(s: &Sensitivity, p: AssumedStatistic) -> Vec<&SensitivityCase> {
    let mut v: Vec<&SensitivityCase> = s.cases.iter().filter(|c| c.parameter == p).collect();
    v.sort_by(|a, b| a.factor.total_cmp(&b.factor));
    v
}

fn parameters(s: &Sensitivity) -> Vec<AssumedStatistic> {
    AssumedStatistic::ALL
        .into_iter()
        .filter(|p| s.cases.iter().any(|c| c.parameter == *p))
        .collect()
}

fn capitalized(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

fn findings(s: &Sensitivity) -> Vec<String> {
    let params = parameters(s);
    let tuned_bias = s.tuned_sigma_final[ErrorState::BIAS];
    // How much each assumption moves the actual bias σ at the last fix.
    let bias_change = |p: AssumedStatistic| {
        cases_of(s, p)
            .iter()
            .map(|c| (c.actual_sigma_final[ErrorState::BIAS] / tuned_bias - 1.0).abs())
            .fold(0.0, f64::max)
    };
    let (matter, wash): (Vec<AssumedStatistic>, Vec<AssumedStatistic>) =
        params.iter().partition(|p| bias_change(**p) > 0.01);
    let titles = |ps: &[AssumedStatistic]| {
        and_list(&ps.iter().map(|p| p.title().to_string()).collect::<Vec<_>>())
    };
    let lo = s.plan.factors.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = s.plan.factors.iter().cloned().fold(0.0, f64::max);
    let mut out = Vec::new();
    if !matter.is_empty() {
        out.push(format!(
            "For the bias estimate, the {} matter: assumed between {} and {} times their true value, they raise the actual bias σ at the last fix by up to {} % over the {} m/s² of the filter that assumes the truth (column “actual / tuned”).{}",
            titles(&matter),
            short(lo),
            short(hi),
            fixed(100.0 * matter.iter().map(|p| bias_change(*p)).fold(0.0, f64::max), 0),
            sig(tuned_bias, 2),
            if wash.is_empty() {
                String::new()
            } else {
                format!(
                    " The {} wash out: the data override them, and the actual bias σ moves by less than 1 %.",
                    titles(&wash)
                )
            }
        ));
    }
    // Conservative or overconfident, from the expected NEES at the last fix.
    let classify = |pred: &dyn Fn(f64) -> bool| -> Vec<String> {
        s.cases
            .iter()
            .filter(|c| pred(c.expected_nees_final))
            .map(|c| format!("{} × {}", c.parameter.title(), short(c.factor)))
            .collect()
    };
    let (conservative, overconfident) = (classify(&|n| n < 2.97), classify(&|n| n > 3.03));
    out.push(format!(
        "A filter that assumes more noise than there is claims a larger σ than it reaches: it is conservative, with an expected NEES below 3 at the last fix ({}). One that assumes less is overconfident, its expected NEES above 3 ({}). The other mistunings leave the final NEES within 1 % of 3: their effect is over by the end of the run, though the early fixes see it.",
        if conservative.is_empty() { "none".to_string() } else { and_list(&conservative) },
        if overconfident.is_empty() { "none".to_string() } else { and_list(&overconfident) },
    ));
    // Which checks see each mistuning at the mildest factor on either side.
    let mut seen = Vec::new();
    for p in &params {
        let cs = cases_of(s, *p);
        let below = cs.iter().rev().find(|c| c.factor < 1.0);
        let above = cs.iter().find(|c| c.factor > 1.0);
        let mut sides = Vec::new();
        for c in [below, above].into_iter().flatten() {
            let ids: Vec<String> = CheckId::ALL
                .iter()
                .filter(|&&id| sure(c, id))
                .map(|id| id.title().to_string())
                .collect();
            sides.push(format!(
                "× {}: {}",
                short(c.factor),
                if ids.is_empty() {
                    "no check surely".to_string()
                } else {
                    and_list(&ids)
                }
            ));
        }
        seen.push(format!("{} ({})", p.title(), sides.join("; ")));
    }
    out.push(format!(
        "The checks sure to detect each mistuning at the mildest factor on either side — with probability at least 0.95 by a bound that holds with 95 % confidence: the exact closed-form bound, or the Clopper–Pearson bound of the sampled ensembles, or of the Monte Carlo ensembles for the residual whiteness — are the first to see it as the assumption drifts: {}.",
        seen.join("; ")
    ));
    out
}

fn cell(c: &SensitivityCase, id: CheckId) -> DetectionCell {
    let level = if sure(c, id) {
        "high"
    } else if missed(c, id) {
        "low"
    } else {
        "mid"
    };
    DetectionCell {
        predicted: c.predicted[id.index()].map_or_else(|| "—".to_string(), |p| fixed(p, 2)),
        measured: match &c.detected {
            Some(d) => {
                let failed = (d[id.index()] * c.ensembles as f64).round() as u64;
                format!("{}/{}", count(failed), count(c.ensembles))
            }
            None => "—".to_string(),
        },
        level: level.to_string(),
    }
}

/// The section's view, its figure numbered from `numbers`.
///
/// # Errors
/// [`RenderError`] when the figure cannot be drawn.
pub fn view(s: &Sensitivity, numbers: &Numbers) -> Result<SensitivityView, RenderError> {
    let series: Vec<SensitivitySeries> = parameters(s)
        .into_iter()
        .map(|p| SensitivitySeries {
            label: capitalized(p.title()),
            points: cases_of(s, p)
                .iter()
                .map(|c| {
                    (
                        c.factor,
                        std::array::from_fn(|k| c.actual_sigma_final[k] / c.claimed_sigma_final[k]),
                    )
                })
                .collect(),
        })
        .collect();
    let figure = figure(
        "fig-sensitivity",
        numbers.figure(Figure::Sensitivity),
        "Actual against claimed accuracy of a mistuned filter",
        "The actual σ of each state's error at the last fix divided by the σ the filter claims, when the filter assumes one statistic's standard deviation times the factor and the truth keeps its value (the Euler-integrated truth, point samples). Exact: from the actual covariance recursion, no random numbers. Above 1 the filter is overconfident, below 1 conservative; the priors' lines lie on 1, hidden under one another, because the data override them by the end of the run.",
        plot::sigma_ratio(&series),
    )?;
    let rows = s
        .cases
        .iter()
        .map(|c| DetectionRow {
            parameter: capitalized(c.parameter.title()),
            factor: short(c.factor),
            expected_nees: fixed(c.expected_nees_final, 2),
            bias_ratio: fixed(
                c.actual_sigma_final[ErrorState::BIAS] / c.claimed_sigma_final[ErrorState::BIAS],
                3,
            ),
            bias_vs_tuned: fixed(
                c.actual_sigma_final[ErrorState::BIAS] / s.tuned_sigma_final[ErrorState::BIAS],
                3,
            ),
            cells: CheckId::ALL.iter().map(|&id| cell(c, id)).collect(),
        })
        .collect();
    Ok(SensitivityView {
        figure,
        table_number: numbers.table(Table::Detection),
        checks: CheckId::ALL
            .iter()
            .map(|c| capitalized(c.title()))
            .collect(),
        rows,
        realizations: count(s.plan.realizations),
        ensembles: count(s.plan.ensembles),
        draws: count(s.cases.first().map_or(0, |c| c.draws)),
        sampled: s.cases.first().is_some_and(|c| c.draws > 0),
        engine_words: match s.plan.engine {
            Engine::Sample => "per-sample engine (every accelerometer sample drawn and integrated)",
            Engine::Epoch => "epoch engine (one exact draw of the accelerometer noise's effect per GPS interval, the same distribution at the fixes as sample by sample)",
        }
        .to_string(),
        ensembles_words: match s.plan.ensembles {
            0 => "no Monte Carlo ensemble".to_string(),
            1 => "one independent Monte Carlo ensemble".to_string(),
            k => format!("{} independent Monte Carlo ensembles", count(k)),
        },
        findings_html: findings(s)
            .into_iter()
            .map(|f| super::rich::rich(&f.replace(" %", "\u{202F}%")))
            .collect(),
    })
}
