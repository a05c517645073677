//! The checks on sums normalized per realization (what an extended Kalman filter's ensemble
//! needs, every realization having its own P) give the linear study's numbers when every
//! realization shares one P: the same members, each within round-off of the shared-P value, and
//! the same verdicts. A negative control: normalizing by a P that is wrong for some realizations
//! moves the members.

use accelcal::checks::{Budget, CATALOGUE, MemberId, evaluate};
use accelcal::config::Config;
use accelcal::ensemble::normalized::{FixInput, NormalizedFix, NormalizedSums, StageInput};
use accelcal::ensemble::{Engine, Ensemble, Statistics};
use accelcal::filter::FilterSchedule;
use accelcal::model::Model;
use accelcal::simulation::{FixState, Observer, run_realization};

const N: u64 = 300;
const SEED: u64 = 3;

struct Keep(Vec<FixState>);
impl Observer for Keep {
    fn fix(&mut self, f: &FixState) {
        self.0.push(*f);
    }
}

fn study() -> (Model, FilterSchedule) {
    let mut c = Config::default();
    c.profile.duration_s = 4.0;
    let m = Model::new(&c).unwrap();
    let s = FilterSchedule::new(&m.timeline, &m.filter_stats).unwrap();
    (m, s)
}

/// The normalized sums of realizations 0..N, each fix's covariances scaled by `scale(l)`.
fn normalized(
    m: &Model,
    s: &FilterSchedule,
    layout: &accelcal::ensemble::ResidualLayout,
    pair: [usize; 2],
    scale: impl Fn(u64) -> f64,
) -> NormalizedSums<3, 2> {
    let times: Vec<f64> = s.fixes.iter().map(|f| f.time_s).collect();
    let mut sums = NormalizedSums::new(times, layout, pair);
    for l in 0..N {
        let mut keep = Keep(Vec::new());
        run_realization(m, s, SEED, l, &mut keep);
        let k = scale(l);
        let fixes: Vec<NormalizedFix<3, 2>> = keep
            .0
            .iter()
            .zip(&s.fixes)
            .enumerate()
            .map(|(i, (f, c))| {
                let input = FixInput {
                    prior: StageInput {
                        error: f.delta_x - f.prior,
                        estimate: f.prior,
                        covariance: c.p_prior * k,
                    },
                    post: StageInput {
                        error: f.delta_x - f.post,
                        estimate: f.post,
                        covariance: c.p_post * k,
                    },
                    residual: f.residual,
                    residual_covariance: c.s * k,
                };
                NormalizedFix::of(&input, i).unwrap()
            })
            .collect();
        sums.add(&fixes);
    }
    sums
}

fn members(stats: &dyn Statistics, check: usize) -> Vec<(MemberId, f64)> {
    let mut out = Vec::new();
    (CATALOGUE[check].for_each_member)(stats, &mut |v, id| out.push((id, v)));
    out
}

#[test]
fn shared_p_normalized_sums_give_the_linear_checks_numbers() {
    let (m, s) = study();
    let e = Ensemble::new(&m, &s)
        .with_engine(Engine::Sample)
        .with_seed(SEED)
        .with_realizations(N);
    let shared = e.run(|_| {}).stats;
    let sums = normalized(&m, &s, &e.layout(), shared.pair, |_| 1.0);
    let own = sums.stats(shared.constant);
    let mut compared = 0;
    for (c, def) in CATALOGUE.iter().enumerate() {
        let (a, b) = (members(&shared, c), members(&own, c));
        assert_eq!(a.len(), b.len(), "{}: member count", def.title);
        // The per-sample engine sums residual products in single precision (a pass's sum is
        // within 7.7·10⁻⁶ of its scale); everything else is double precision in another order.
        let tolerance = if def.title == "residual whiteness" {
            1e-3
        } else {
            1e-9
        };
        for ((ia, va), (ib, vb)) in a.iter().zip(&b) {
            assert_eq!(ia, ib, "{}: members in the same order", def.title);
            assert!(
                (va - vb).abs() <= tolerance * va.abs().max(1.0),
                "{}: {ia:?} shared {va}, normalized {vb}",
                def.title
            );
            compared += 1;
        }
    }
    assert!(compared > 1000, "only {compared} members compared");
    let budget = Budget::study(0.01);
    let (va, vb) = (evaluate(&shared, &budget), evaluate(&own, &budget));
    for (ca, cb) in va.checks.iter().zip(&vb.checks) {
        assert_eq!(
            (ca.verdict, ca.failures),
            (cb.verdict, cb.failures),
            "{}",
            ca.definition.title
        );
    }
}

#[test]
fn a_covariance_wrong_for_half_the_realizations_moves_the_members() {
    // Negative control: the odd realizations' P and S said to be 4× too large (σ 2×). Their
    // normalized errors shrink by half, and the NEES, NIS and variance checks see it.
    let (m, s) = study();
    let e = Ensemble::new(&m, &s)
        .with_engine(Engine::Sample)
        .with_seed(SEED)
        .with_realizations(N);
    let shared = e.run(|_| {}).stats;
    let wrong = normalized(&m, &s, &e.layout(), shared.pair, |l| {
        if l % 2 == 1 { 4.0 } else { 1.0 }
    })
    .stats(shared.constant);
    let verdicts = evaluate(&wrong, &Budget::study(0.01));
    let failed: Vec<&str> = verdicts.failed().map(|c| c.definition.title).collect();
    for title in ["NEES", "NIS", "variance"] {
        assert!(
            failed.contains(&title),
            "{title} passed; failed: {failed:?}"
        );
    }
    // The ensemble average NEES at the last fix: 3·(1 + 1/4)/2 = 1.875 expected, not 3.
    let last = wrong.fixes.last().unwrap();
    assert!(
        (last.post.nees_avg - 1.875).abs() < 0.4,
        "{}",
        last.post.nees_avg
    );
}
