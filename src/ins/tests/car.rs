//! A car: the IMU mounted upside down and a few degrees off in a vehicle that neither slides nor
//! lifts off. The 18-state filter with the non-holonomic constraint passes the check catalogue and
//! finds the mounting's pitch and yaw (not its roll, which the constraint does not see); filters
//! that trust the constraint ten times too much, or leave a 5° mounting yaw out, fail.

use crate::checks::{Budget, Verdicts, evaluate};
use crate::config::ins::{InsConfig, VehicleConfig};
use crate::ins::ensemble::{Calibration, Track, run};
use crate::ins::error_state::start_of;
use crate::ins::setup::Scenario;
use crate::ins::state::{Block, Layout};

const CAR: usize = Layout::CAR.dim();

fn car(edit: impl FnOnce(&mut InsConfig)) -> Scenario {
    let mut c = InsConfig {
        model: Some("car".into()),
        ..InsConfig::default()
    };
    edit(&mut c);
    Scenario::from_config(&c).unwrap()
}

fn outcome<const N: usize>(s: &Scenario, n: u64) -> (Verdicts, Calibration<N>) {
    let o = run::<N>(s, &Track::of(s), n).unwrap();
    let v = evaluate(&o.stats, &Budget::study(s.false_alarm_rate));
    for c in &v.checks {
        eprintln!(
            "{:<20} {:<10} outside {:>5} worst {:.3} band [{:.3}, {:.3}]",
            c.definition.title,
            c.verdict.name(),
            c.failures,
            c.worst_value(),
            c.lower,
            c.upper
        );
    }
    (v, o.calibration)
}

#[test]
fn the_car_s_filter_passes_and_finds_the_mounting_s_pitch_and_yaw() {
    let s = car(|_| {});
    assert_eq!(s.layout(), Layout::CAR);
    let (v, cal) = outcome::<CAR>(&s, 64);
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(failed.is_empty(), "the car's filter failed {failed:?}");
    let prior = VehicleConfig::default().mounting_sigma_deg.to_radians();
    let at = start_of::<CAR>(Block::Mounting);
    let sigma = |k: usize| cal.filter_sigma[at + k] / prior;
    // Measured: roll 1 (the constraint has no roll column), pitch 0.003, yaw 0.009.
    assert!(
        sigma(0) > 0.999,
        "the roll's σ fell to {:.4} of its prior",
        sigma(0)
    );
    assert!(
        sigma(1) < 0.05 && sigma(2) < 0.05,
        "pitch {:.3}, yaw {:.3}",
        sigma(1),
        sigma(2)
    );
}

#[test]
fn an_overconfident_constraint_and_a_mounting_left_out_fail() {
    let s = car(|c| c.filter.nhc_sigma_m_s = Some(0.005));
    let (v, _) = outcome::<CAR>(&s, 64);
    assert!(
        v.failed().count() > 0,
        "a slip σ ten times too small went unseen"
    );
    let s = car(|c| {
        c.vehicle = Some(VehicleConfig {
            mounting_rpy_deg: [180.0, 0.0, 5.0],
            mounting_sigma_deg: 0.0,
            ..VehicleConfig::default()
        });
        c.filter.mounting_rpy_deg = Some([180.0, 0.0, 0.0]);
        c.filter.error_states = Some(15);
    });
    let (v, _) = outcome::<{ Layout::CORE.dim() }>(&s, 64);
    let failed: Vec<_> = v.failed().map(|c| c.definition.title).collect();
    assert!(
        failed.contains(&"NEES"),
        "a 5° mounting yaw went unseen: {failed:?}"
    );
}

#[test]
fn a_vehicle_needs_the_car_model_and_18_states_a_vehicle() {
    let c = InsConfig {
        model: Some("ins".into()),
        vehicle: Some(VehicleConfig::default()),
        ..InsConfig::default()
    };
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(e.contains("model"), "{e}");
    let mut c = InsConfig::default();
    c.filter.nhc_sigma_m_s = Some(0.1);
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(e.contains("filter.nhc_sigma_m_s"), "{e}");
    let c = InsConfig {
        model: Some("car".into()),
        vehicle: Some(VehicleConfig {
            mounting_rpy_deg: [0.0, 200.0, 0.0],
            ..VehicleConfig::default()
        }),
        ..InsConfig::default()
    };
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(
        e.contains("vehicle.mounting_rpy_deg") && e.contains("[−180, 180]"),
        "{e}"
    );
    // A mounting known exactly cannot be estimated: 15 states, or a σ above 0.
    let mut c = InsConfig {
        model: Some("car".into()),
        vehicle: Some(VehicleConfig {
            mounting_sigma_deg: 0.0,
            ..VehicleConfig::default()
        }),
        ..InsConfig::default()
    };
    let e = Scenario::from_config(&c).unwrap_err().to_string();
    assert!(e.contains("vehicle.mounting_sigma_deg"), "{e}");
    c.filter.error_states = Some(15);
    assert_eq!(Scenario::from_config(&c).unwrap().layout(), Layout::CORE);
}
