//! The driver's χ² gate and outage mask on simulated drives, against their own statistics:
//!
//! - fixes moved by 30σ are every one rejected and named, and the biases stay within a quarter of
//!   their σ of the clean run's (ungated, the moved fixes drag them further: the control);
//! - on clean drives a gate at α rejects a share of fixes in the binomial band of α, both sides
//!   (a filter that assumes the receiver twice as good, or twice as bad, falls outside: the
//!   controls);
//! - through a 60 s GNSS outage the position σ grows, and the position error's NEES at the
//!   outage's end over 200 realizations lies in its χ² band (a truth whose accelerometers are
//!   ten times noisier than the filter assumes falls outside: the control).

mod common;

use accelcal::config::ins::InsConfig;
use accelcal::ins::driver::{Driver, Due, Observer, Outage, Source, Update};
use accelcal::ins::earth::offset;
use accelcal::ins::ensemble::{SimulatedGnss, SimulatedImu, Track, error, start};
use accelcal::ins::error_state::{ACCEL_BIAS, GYRO_BIAS, POSITION, STATES, Square};
use accelcal::ins::filter::Ekf;
use accelcal::ins::gnss::FixUpdate;
use accelcal::ins::measurement::{Gate, Measurement};
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::fix;
use common::imu::band;
use nalgebra::{SVector, Vector3};
use rayon::prelude::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The tests' false-alarm rate, each.
const ALPHA: f64 = 0.01;

/// A study of the default drive's first `duration_s` seconds.
fn study(duration_s: f64, edit: impl FnOnce(&mut InsConfig)) -> Scenario {
    let mut c = InsConfig::default();
    c.drive.duration_s = duration_s;
    edit(&mut c);
    Scenario::from_config(&c).expect("a valid scenario")
}

/// The simulated receiver with every `every`-th fix (from fix `offset`) moved north by
/// `sigmas` of its north σ.
struct Moved {
    inner: SimulatedGnss,
    every: usize,
    offset: usize,
    sigmas: f64,
}

impl Source<STATES, SimulatedImu<'_>> for Moved {
    fn next_time(&self) -> Option<f64> {
        Source::<STATES, SimulatedImu<'_>>::next_time(&self.inner)
    }

    fn take(&mut self, imu: &mut SimulatedImu<'_>) -> Box<dyn Measurement<STATES>> {
        let t = Source::<STATES, SimulatedImu<'_>>::next_time(&self.inner).expect("due");
        let k = self.inner.given;
        self.inner.given += 1;
        let (scenario, pva) = (imu.scenario, *imu.truth());
        let mut reading = fix(scenario, &imu.drive, &mut imu.imu, t, &pva);
        reading.position_sigma_m = scenario.filter_gnss.position_sigma_m;
        reading.velocity_sigma_m_s = scenario.filter_gnss.velocity_sigma_m_s;
        if k % self.every == self.offset {
            let north = self.sigmas * scenario.truth_gnss.position_sigma_m.x;
            reading.position = offset(&reading.position, &Vector3::new(north, 0.0, 0.0));
        }
        Box::new(FixUpdate::whole(reading))
    }
}

/// What a run saw: each tested fix (its index, whether accepted, its components), and the
/// position error and P before the first update after `watch_s`.
#[derive(Default)]
struct Seen {
    fixes: Vec<(usize, bool, Vec<&'static str>)>,
    withheld: usize,
    watch_s: f64,
    at_watch: Option<(SVector<f64, STATES>, Square<STATES>)>,
    sigma_north_before_s: Option<(f64, f64)>,
}

impl Observer<STATES, SimulatedImu<'_>> for Seen {
    type Error = std::convert::Infallible;

    fn before(&mut self, ekf: &mut Ekf, sim: &SimulatedImu, due: &Due) -> Result<(), Self::Error> {
        if due.t_s > self.watch_s && self.at_watch.is_none() {
            self.at_watch = Some((error(ekf, sim.truth(), &sim.imu), ekf.covariance));
        }
        Ok(())
    }

    fn after(
        &mut self,
        ekf: &Ekf,
        _: &SimulatedImu,
        due: &Due,
        update: Update,
    ) -> Result<(), Self::Error> {
        match update {
            Update::Tested(nu) => {
                let names = nu.components.iter().map(|c| c.key).collect();
                self.fixes.push((due.index, nu.accepted, names));
                if due.t_s <= self.watch_s {
                    let s = ekf.covariance[(POSITION, POSITION)].sqrt();
                    self.sigma_north_before_s = Some((s, due.t_s));
                }
            }
            Update::Withheld => self.withheld += 1,
        }
        Ok(())
    }
}

/// Realization `index` of `scenario` through the driver with `gate`, `outages` and the receiver
/// `gnss` (`None`: the simulated one); the filter at the end and what the observer saw.
fn run(
    scenario: &Scenario,
    track: &Track,
    index: u64,
    gate: Option<Gate>,
    outages: Vec<Outage>,
    moved: Option<(usize, usize, f64)>,
    watch_s: f64,
) -> (Ekf, Seen) {
    let (imu, mut ekf) = start::<STATES>(scenario, track, index);
    let mut sim = SimulatedImu::new(scenario, track, imu);
    let inner = SimulatedGnss::of(scenario, track);
    let mut seen = Seen {
        watch_s,
        ..Seen::default()
    };
    let mut plain = SimulatedGnss::of(scenario, track);
    let mut shifted;
    let source: &mut dyn Source<STATES, SimulatedImu> = match moved {
        Some((every, offset, sigmas)) => {
            shifted = Moved {
                inner,
                every,
                offset,
                sigmas,
            };
            &mut shifted
        }
        None => &mut plain,
    };
    Driver::new(vec![source])
        .with_gate(gate)
        .with_outages(outages)
        .run(&mut ekf, &mut sim, &mut seen)
        .expect("the filter runs");
    (ekf, seen)
}

/// The six bias estimates and their σ's.
fn biases(ekf: &Ekf) -> [(f64, f64); 6] {
    std::array::from_fn(|k| {
        let i = if k < 3 {
            GYRO_BIAS + k
        } else {
            ACCEL_BIAS + k - 3
        };
        let b = if k < 3 {
            ekf.gyro_bias_rad_s[k]
        } else {
            ekf.accel_bias_m_s2[k - 3]
        };
        (b, ekf.covariance[(i, i)].sqrt())
    })
}

#[test]
fn the_gate_rejects_every_moved_fix_and_the_biases_stay() {
    let s = study(600.0, |_| {});
    let track = Track::of(&s);
    let gate = Some(Gate::new(ALPHA));
    // One fix in 100 moved north by 30 σ: fixes 37, 137, …, 537.
    let moved = Some((100, 37, 30.0));
    let (clean, _) = run(&s, &track, 0, gate, vec![], None, f64::INFINITY);
    let (gated, seen) = run(&s, &track, 0, gate, vec![], moved, f64::INFINITY);
    let (ungated, _) = run(&s, &track, 0, None, vec![], moved, f64::INFINITY);
    let rejected: Vec<usize> = seen.fixes.iter().filter(|f| !f.1).map(|f| f.0).collect();
    eprintln!("rejected fixes: {rejected:?} of {}", seen.fixes.len());
    for k in (37..seen.fixes.len()).step_by(100) {
        assert!(rejected.contains(&k), "moved fix {k} accepted");
        let names = &seen.fixes[k].2;
        assert!(names.contains(&"position_n"), "fix {k} names {names:?}");
    }
    let shift = |a: &Ekf| -> f64 {
        biases(a)
            .iter()
            .zip(biases(&clean))
            .map(|(x, c)| ((x.0 - c.0) / c.1).abs())
            .fold(0.0, f64::max)
    };
    let (with_gate, without) = (shift(&gated), shift(&ungated));
    eprintln!(
        "largest bias shift from the clean run: gated {with_gate:.3} σ, ungated {without:.3} σ"
    );
    // Within a quarter of their σ (one σ is the promise); ungated, the six moved fixes drag a
    // bias further than that.
    assert!(with_gate < 0.25, "gated: a bias moved {with_gate} σ");
    assert!(
        without > 0.25,
        "ungated: the moved fixes should drag a bias: {without} σ"
    );
}

/// The fixes tested and rejected over `drives` drives of `s`, gated at [`ALPHA`].
fn rejections(s: &Scenario, drives: u64) -> (u64, u64) {
    let track = Track::of(s);
    let gate = Some(Gate::new(ALPHA));
    (0..drives)
        .into_par_iter()
        .map(|l| {
            let (_, seen) = run(s, &track, l, gate, vec![], None, f64::INFINITY);
            let tested = seen.fixes.len() as u64;
            let rejected = seen.fixes.iter().filter(|f| !f.1).count() as u64;
            (tested, rejected)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

#[test]
fn the_gate_rejects_consistent_fixes_at_its_rate() {
    let drives = 200;
    let s = study(120.0, |_| {});
    let (tested, rejected) = rejections(&s, drives);
    let (lo, hi) = band(tested, ALPHA, ALPHA);
    eprintln!("{rejected} of {tested} fixes rejected, band [{lo}, {hi}]");
    assert!(
        (lo..=hi).contains(&rejected),
        "{rejected} outside [{lo}, {hi}]"
    );
    // Controls: a filter that takes the receiver's σ's as half, or twice, the truth's.
    for (factor, above) in [(0.5, true), (2.0, false)] {
        let c = study(120.0, |c| {
            let g = &c.gnss;
            c.filter.gnss_position_sigma_m = Some(g.gnss_position_sigma_m.map(|x| x * factor));
            c.filter.gnss_velocity_sigma_m_s = Some(g.gnss_velocity_sigma_m_s * factor);
        });
        let (t, r) = rejections(&c, drives);
        eprintln!("σ × {factor}: {r} of {t} rejected");
        assert!(
            if above { r > hi } else { r < lo },
            "σ × {factor}: {r} in [{lo}, {hi}]"
        );
    }
}

/// The position NEES at the first fix after a 60 s outage summed over `n` realizations, and
/// the median growth of the north σ over the outage.
fn outage_nees(s: &Scenario, n: u64) -> (f64, f64) {
    let track = Track::of(s);
    let outage = Outage {
        source: 0,
        from_s: 200.0,
        to_s: 260.0,
    };
    let runs: Vec<(f64, f64)> = (0..n)
        .into_par_iter()
        .map(|l| {
            let (_, seen) = run(s, &track, l, None, vec![outage], None, 200.0);
            assert_eq!(seen.withheld, 60);
            let (e, p) = seen.at_watch.expect("a fix after the outage");
            let er = e.fixed_rows::<3>(POSITION).into_owned();
            let prr = p.fixed_view::<3, 3>(POSITION, POSITION).into_owned();
            let nees = er.dot(&prr.cholesky().expect("P positive definite").solve(&er));
            let (before, _) = seen.sigma_north_before_s.expect("a fix before");
            (nees, p[(POSITION, POSITION)].sqrt() / before)
        })
        .collect();
    let mut growth: Vec<f64> = runs.iter().map(|r| r.1).collect();
    growth.sort_by(f64::total_cmp);
    (runs.iter().map(|r| r.0).sum(), growth[growth.len() / 2])
}

#[test]
fn through_an_outage_the_position_nees_stays_in_its_band() {
    let n = 200;
    let dof = 3.0 * n as f64;
    let chi2 = ChiSquared::new(dof).expect("dof");
    let (lo, hi) = (
        chi2.inverse_cdf(ALPHA / 2.0),
        chi2.inverse_cdf(1.0 - ALPHA / 2.0),
    );
    let (nees, growth) = outage_nees(&study(300.0, |_| {}), n);
    eprintln!("NEES sum {nees:.1}, band [{lo:.1}, {hi:.1}]; north σ grows × {growth:.2}");
    assert!(
        growth > 2.0,
        "the position σ should grow through the outage: × {growth}"
    );
    assert!(
        (lo..=hi).contains(&nees),
        "NEES {nees} outside [{lo}, {hi}]"
    );
    // Control: accelerometers ten times noisier than the filter assumes.
    let noisy = study(300.0, |c| {
        c.filter.accel_vrw_m_s_per_sqrt_s = Some(c.imu.accel_vrw_m_s_per_sqrt_s);
        c.imu.accel_vrw_m_s_per_sqrt_s *= 10.0;
    });
    let (bad, _) = outage_nees(&noisy, n);
    eprintln!("control: NEES sum {bad:.1}");
    assert!(bad > hi, "the control's NEES {bad} within the band");
}
