//! The Allan deviation of a static accelerometer log and the noise terms it measures.
//!
//! The pieces, one pure function each, in the order [`analyse`] runs them:
//! 1. [`deviation`]: the overlapping Allan deviation from cumulative sums, O(n) per τ, at
//!    octave-spaced τ = m·τ₀ (NIST SP 1065, eq. 11; equal to allantools' `oadev`);
//! 2. [`noise_id`]: the power-law noise at each τ from the lag-1 autocorrelation (Riley &
//!    Greenhall 2004);
//! 3. [`edf`]: the equivalent degrees of freedom of each estimate for that noise (Greenhall &
//!    Riley 2003) and its χ² interval (SP 1065, eq. 45);
//! 4. [`fit`](mod@fit): the terms Q, N, B, K, R by weighted least squares with every squared term
//!    ≥ 0 ([`nnls`]) over every τ with an EDF, with intervals from the exact covariance of the
//!    estimates across τ ([`covariance`]) and a test of the fit ([`goodness`]);
//! 5. [`reading`]: where the fit departs from the points, the features it lacks (a sinusoid, a
//!    trend), and the IEEE 952 reading off the curve that replaces the fit when the test rejects
//!    it;
//! 6. [`gauss_markov_fit`]: the Gauss–Markov σ and T_c fitted beside the terms, reported where
//!    a hump shows them (a test against the fit without), with intervals.
//!
//! [`stream`] computes step 1 on a log read piece by piece, in memory independent of its length
//! (with [`noise_stream`] for step 2), for `allan --imu` on long recordings; [`analyse_grid`]
//! runs steps 3–5 on its result.
//!
//! [`simulate`] draws synthetic static logs with known terms (for the tests, the report and the
//! benchmarks); [`export`] writes `allan.json`, `noise.toml` and `imu.yaml`; [`section`] measures
//! the coverage of the intervals the report shows. The page and its figure are drawn above this
//! module, by `report::allan` through `plot`.

pub mod covariance;
pub mod deviation;
pub mod edf;
pub mod export;
pub mod fit;
pub mod gauss_markov;
pub mod gauss_markov_fit;
pub mod goodness;
pub mod imu;
pub mod nnls;
pub mod noise_id;
pub mod noise_stream;
pub mod reading;
pub mod section;
pub mod select;
pub mod simulate;
pub mod spill;
pub mod stream;

use rayon::prelude::*;
use thiserror::Error;

use crate::progress::{Cancel, Cancelled};

pub use fit::{Fit, FitPoint, Term, TermEstimate};
pub use gauss_markov_fit::GaussMarkov;
pub use noise_id::NoiseId;
pub use reading::{Departure, Feature, Reading};

/// The nonzero Allan deviations σ̂(τ) the analysis accepts, in the log's units: the fit sums
/// squares of the variances and their model terms, which leave double precision (10^±308) for
/// deviations beyond about 10^±37; the bounds keep a margin of seven orders.
pub const ADEV_RANGE: (f64, f64) = (1e-30, 1e30);

/// The interval confidence when none is given: one standard deviation of a normal.
pub const DEFAULT_CONFIDENCE: f64 = 0.683;

/// Fewest samples an analysis accepts: the fit needs at least four τ with
/// [`noise_id::MIN_POINTS`] block means each.
pub const MIN_SAMPLES: usize = 8 * noise_id::MIN_POINTS;

/// A log the analysis cannot use.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AllanError {
    /// Too few samples.
    #[error("the log has {found} samples; the Allan analysis needs at least {needed}")]
    TooFewSamples {
        /// Samples found.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
    /// Every sample is the same number.
    #[error("every sample is the same number: the Allan deviation is zero at every τ")]
    Constant,
    /// The samples differ, by too little for their second differences' squares in double
    /// precision.
    #[error(
        "the samples differ, but by so little that the Allan variance underflows double \
         precision (it is zero at every τ): expected every nonzero σ̂(τ) between {:e} and {:e} \
         in the log's units (rescale the log)",
        ADEV_RANGE.0,
        ADEV_RANGE.1
    )]
    Underflow,
    /// A deviation outside [`ADEV_RANGE`]: the fit's sums of squares leave double precision.
    #[error(
        "σ̂(τ) = {adev:e} at τ = {tau_s} s is outside the range the analysis computes in double \
         precision: expected every nonzero σ̂(τ) between {:e} and {:e} in the log's units \
         (rescale the log)",
        ADEV_RANGE.0,
        ADEV_RANGE.1
    )]
    OutOfRange {
        /// The deviation, in the log's units (infinite or NaN when it overflowed).
        adev: f64,
        /// Its τ, s.
        tau_s: f64,
    },
    /// The confidence is outside (0, 1).
    #[error("the confidence is {0}; expected a number strictly between 0 and 1")]
    Confidence(f64),
    /// A simulated log written as CSV text did not read back (a defect, not bad input).
    #[error("the simulated static log did not read back: {0}")]
    SimulatedLog(String),
    /// The analysis was stopped by its [`Cancel`] flag.
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// The Allan deviation at one τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllanPoint {
    /// Averaging factor m.
    pub m: usize,
    /// τ = m·τ₀, s.
    pub tau_s: f64,
    /// σ̂(τ), m/s².
    pub adev: f64,
    /// The noise identified at this τ, or (fewer than 30 block means) at the longest τ that
    /// had them.
    pub noise: Option<NoiseId>,
    /// Whether `noise` was identified at this τ itself.
    pub identified_here: bool,
    /// Equivalent degrees of freedom for the α of this τ in the non-increasing sequence nearest
    /// the identified ones ([`noise_id::non_increasing`]).
    pub edf: Option<f64>,
    /// The χ² interval of σ̂(τ), m/s².
    pub interval: Option<(f64, f64)>,
}

/// The analysis of one log.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// Samples n.
    pub samples: usize,
    /// τ₀, s.
    pub sample_period_s: f64,
    /// The confidence of every interval.
    pub confidence: f64,
    /// The deviation at every τ of the octave grid.
    pub points: Vec<AllanPoint>,
    /// The constrained fit.
    pub fit: Fit,
    /// Which reading [`Analysis::terms`] come from: the fit, or IEEE 952's off the curve when the
    /// goodness-of-fit test rejects the model.
    pub reading: Reading,
    /// The reported terms, in the order of the fit's.
    pub terms: Vec<TermEstimate>,
    /// How the fitted curve meets each point.
    pub departures: Vec<Departure>,
    /// Features of the curve the model does not have.
    pub features: Vec<Feature>,
    /// The Gauss–Markov term where a hump shows one ([`gauss_markov_fit`]).
    pub gauss_markov: GaussMarkov,
}

impl Analysis {
    /// The fit as it was before the constraint, on this analysis: unconstrained, over the τ with
    /// at least 30 block means only ([`fit::fit_unconstrained`]). Kept for the tests' negative
    /// controls.
    pub fn fit_before_constraint(&self, terms: &[Term]) -> Option<Fit> {
        let points: Vec<FitPoint> = self
            .points
            .iter()
            .filter(|p| p.identified_here)
            .filter_map(|p| {
                p.edf.map(|edf| FitPoint {
                    m: p.m,
                    tau_s: p.tau_s,
                    avar: p.adev * p.adev,
                    edf,
                })
            })
            .collect();
        fit::fit_unconstrained(
            &points,
            self.samples,
            self.sample_period_s,
            terms,
            self.confidence,
        )
    }

    /// The reported estimate of `term`, if fitted.
    pub fn term(&self, term: Term) -> Option<&TermEstimate> {
        self.terms.iter().find(|t| t.term == term)
    }

    /// The τ of the smallest deviation, s.
    pub fn tau_at_minimum_s(&self) -> f64 {
        self.points
            .iter()
            .min_by(|a, b| a.adev.total_cmp(&b.adev))
            .map_or(self.sample_period_s, |p| p.tau_s)
    }
}

/// The deviation, noise type, EDF and interval at every τ of the octave grid, from the phase
/// `x` (in samples) of n rate samples.
/// `cancel` is polled before each stretch of the deviation's pass and each τ's identification.
fn points(
    x: &[f64],
    tau0_s: f64,
    confidence: f64,
    cancel: &Cancel,
) -> Result<Vec<AllanPoint>, Cancelled> {
    let n = x.len() - 1;
    let factors = deviation::octave_factors(n);
    let avars = deviation::overlapping_avars_polled(x, &factors, cancel)?;
    let raw: Vec<(usize, f64, Option<NoiseId>)> = factors
        .par_iter()
        .zip(avars)
        .map(|(&m, avar)| {
            cancel.check()?;
            Ok((m, avar, noise_id::identify_phase(x, m)))
        })
        .collect::<Result<_, Cancelled>>()?;
    Ok(with_intervals(&raw, n, tau0_s, confidence))
}

/// The points of the octave grid from each τ's (m, σ̂², the noise of its own block means) for n
/// samples: the noise carried from the longest τ identified where fewer than 30 block means
/// remain, the EDF for that noise and the χ² interval at `confidence`.
fn with_intervals(
    raw: &[(usize, f64, Option<NoiseId>)],
    n: usize,
    tau0_s: f64,
    confidence: f64,
) -> Vec<AllanPoint> {
    let mut out: Vec<AllanPoint> = raw
        .iter()
        .map(|&(m, avar, noise)| AllanPoint {
            m,
            tau_s: m as f64 * tau0_s,
            adev: avar.sqrt(),
            noise,
            identified_here: noise.is_some(),
            edf: None,
            interval: None,
        })
        .collect();
    // The EDF's α: the non-increasing sequence nearest the identified α̂, each weighted by its
    // count of block means (r₁'s variance is about 1/L). A sum of power laws has a log spectrum
    // convex in log f, so its local exponent never rises with τ: a rise is the identification's
    // chance error (from 30 block means r₁ has a standard deviation of 0.18, and a white noise
    // read as flicker phase claims 16 times its EDF), pooled with its neighbours.
    let (estimates, counts): (Vec<f64>, Vec<f64>) = out
        .iter()
        .filter_map(|p| p.noise.map(|id| (id.alpha_estimate, (n / p.m) as f64)))
        .unzip();
    let mut monotone = noise_id::non_increasing(&estimates, &counts).into_iter();
    let (mut last, mut last_alpha) = (None, None);
    for p in &mut out {
        if p.identified_here {
            last_alpha = monotone.next().map(|a| a.round_ties_even() as i32);
        } else {
            p.noise = last;
        }
        last = p.noise;
        let Some(alpha) = last_alpha else { continue };
        // Greenhall's EDF covers α from −2 (random walk) to +2 (white phase).
        let alpha = alpha.clamp(-2, 2);
        p.edf = edf::greenhall_edf(alpha, 2, p.m as f64, (n + 1) as f64, true);
        p.interval = p
            .edf
            .map(|e| edf::chi_squared_interval(p.adev, e, confidence));
    }
    out
}

/// The terms fitted: N, B and K always, Q when the shortest τ shows phase noise (α ≥ 1).
fn fitted_terms(points: &[AllanPoint]) -> Vec<Term> {
    let phase_noise = points
        .first()
        .and_then(|p| p.noise)
        .is_some_and(|id| id.alpha >= 1);
    Term::ALL
        .into_iter()
        .filter(|&t| t != Term::Quantization || phase_noise)
        .collect()
}

/// Analyses the rate samples `y` (m/s²) taken τ₀ = `tau0_s` apart: the overlapping Allan
/// deviation at octave τ with χ² intervals at `confidence`, and the fitted noise terms. The fit
/// uses every τ with an EDF (the noise carried from the longest τ with 30 block means where fewer
/// remain), each with the weight its EDF gives it.
///
/// # Errors
/// [`AllanError`] for fewer than [`MIN_SAMPLES`] samples, a constant log or a confidence
/// outside (0, 1).
pub fn analyse(y: &[f64], tau0_s: f64, confidence: f64) -> Result<Analysis, AllanError> {
    analyse_cancellable(y, tau0_s, confidence, &Cancel::new())
}

/// [`analyse`] that stops when `cancel` is raised: it is polled after the phase, before each
/// stretch of the deviation's pass and before each τ's noise identification, so a raised flag
/// ends the call within one of those pieces (each O(n / threads) at most).
///
/// # Errors
/// As [`analyse`], and [`AllanError::Cancelled`] when `cancel` was raised first.
pub fn analyse_cancellable(
    y: &[f64],
    tau0_s: f64,
    confidence: f64,
    cancel: &Cancel,
) -> Result<Analysis, AllanError> {
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Confidence(confidence));
    }
    if y.len() < MIN_SAMPLES {
        return Err(AllanError::TooFewSamples {
            found: y.len(),
            needed: MIN_SAMPLES,
        });
    }
    // Distinctness is compared, not read off a variance that may underflow.
    if y.iter().all(|&v| v == y[0]) {
        return Err(AllanError::Constant);
    }
    let x = deviation::phase(y);
    cancel.check()?;
    let points = points(&x, tau0_s, confidence, cancel)?;
    analyse_points(points, y.len(), tau0_s, confidence)
}

/// [`analyse`] of the rate samples held one place in: `held` is [_, y_0, …, y_{n−1}] (the first
/// place free), and the phase is summed where the samples are, the same bits as [`analyse`]
/// of y.
///
/// # Errors
/// As [`analyse`].
pub fn analyse_in_place(
    mut held: Vec<f64>,
    tau0_s: f64,
    confidence: f64,
) -> Result<Analysis, AllanError> {
    let y = held.get(1..).unwrap_or_default();
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Confidence(confidence));
    }
    if y.len() < MIN_SAMPLES {
        return Err(AllanError::TooFewSamples {
            found: y.len(),
            needed: MIN_SAMPLES,
        });
    }
    if y.iter().all(|&v| v == y[0]) {
        return Err(AllanError::Constant);
    }
    let n = y.len();
    deviation::phase_in_place(&mut held);
    let points = points(&held, tau0_s, confidence, &Cancel::new())?;
    analyse_points(points, n, tau0_s, confidence)
}

/// Analyses the rate samples of a log read once ([`stream::AllanStream`]): `grid` holds each
/// octave τ's (m, σ̂², the noise of its block means) for `samples` samples τ₀ = `tau0_s` apart.
/// The rest is [`analyse`]'s: the same analysis wherever the grid holds the same numbers. A
/// constant log is the caller's to tell (it compares the samples, as [`analyse`] does): a grid
/// zero at every τ is [`AllanError::Underflow`] here.
///
/// # Errors
/// As [`analyse`].
pub fn analyse_grid(
    grid: &[(usize, f64, Option<NoiseId>)],
    samples: usize,
    tau0_s: f64,
    confidence: f64,
) -> Result<Analysis, AllanError> {
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AllanError::Confidence(confidence));
    }
    if samples < MIN_SAMPLES {
        return Err(AllanError::TooFewSamples {
            found: samples,
            needed: MIN_SAMPLES,
        });
    }
    let points = with_intervals(grid, samples, tau0_s, confidence);
    analyse_points(points, samples, tau0_s, confidence)
}

/// The fit and its reading on the points of a log of `samples` samples, which are not all
/// equal (the callers compare them): points zero at every τ are an underflow.
fn analyse_points(
    points: Vec<AllanPoint>,
    samples: usize,
    tau0_s: f64,
    confidence: f64,
) -> Result<Analysis, AllanError> {
    if points.iter().all(|p| p.adev == 0.0) {
        return Err(AllanError::Underflow);
    }
    let (low, high) = ADEV_RANGE;
    if let Some(p) = points
        .iter()
        .find(|p| p.adev != 0.0 && !(low..=high).contains(&p.adev))
    {
        return Err(AllanError::OutOfRange {
            adev: p.adev,
            tau_s: p.tau_s,
        });
    }
    let fit_points: Vec<FitPoint> = points
        .iter()
        .filter(|p| p.adev > 0.0)
        .filter_map(|p| {
            p.edf.map(|edf| FitPoint {
                m: p.m,
                tau_s: p.tau_s,
                avar: p.adev * p.adev,
                edf,
            })
        })
        .collect();
    let terms = fitted_terms(&points);
    let fit = select::fit_selected(&fit_points, samples, tau0_s, &terms, confidence)
        .ok_or(AllanError::Constant)?;
    let gauss_markov =
        gauss_markov_fit::fit_gauss_markov(&fit_points, samples, tau0_s, &fit.model, confidence);
    let departures = reading::departures(&points, &fit);
    let features = reading::features(&points, &departures, &fit);
    let (reading, terms) = if fit.goodness.rejected {
        let read = reading::ieee952(&points, &terms, samples, confidence);
        (Reading::Ieee952, read)
    } else {
        (Reading::Fit, fit.terms.clone())
    };
    Ok(Analysis {
        samples,
        sample_period_s: tau0_s,
        confidence,
        points,
        fit,
        reading,
        terms,
        departures,
        features,
        gauss_markov,
    })
}
