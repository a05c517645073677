//! The recipe for a new measurement, proven by doing (`--features throwaway-measurement`, as
//! `.ci/run` builds it): the throwaway down-velocity measurement of `ins/throwaway.rs` joins
//! `ins::extra::sources` and runs, beside the GNSS fixes, through the driver of the ensemble's
//! simulated drive and through `calibrate --imu` on the shipped recording.
#![cfg(feature = "throwaway-measurement")]

use std::path::Path;

use accelcal::calibrate::imu::CONSUMER;
use accelcal::calibrate::imu::run::calibrate;
use accelcal::config::ins::InsConfig;
use accelcal::input::csv::read::LogFile;
use accelcal::ins::driver::{Driver, Due, Observer, Source, Update};
use accelcal::ins::ensemble::{SimulatedGnss, SimulatedImu, Track, start};
use accelcal::ins::error_state::STATES;
use accelcal::ins::extra::{GNSS, sources};
use accelcal::ins::filter::Ekf;
use accelcal::ins::setup::Scenario;

/// Each source's updates: how many, and the components of the other sources'.
#[derive(Default)]
struct Count {
    gnss: usize,
    other: Vec<(f64, Vec<&'static str>, f64)>,
}

impl<C: ?Sized> Observer<STATES, C> for Count {
    type Error = std::convert::Infallible;

    fn after(&mut self, _: &Ekf, _: &C, due: &Due, update: Update) -> Result<(), Self::Error> {
        let Update::Tested(nu) = update else {
            return Ok(());
        };
        if due.source == GNSS {
            self.gnss += 1;
        } else {
            let names = nu.components.iter().map(|v| v.key).collect();
            self.other.push((due.t_s, names, nu.nis));
        }
        Ok(())
    }
}

#[test]
fn the_throwaway_measurement_runs_beside_gnss_in_a_simulated_drive() {
    let mut c = InsConfig::default();
    c.drive.duration_s = 60.0;
    let scenario = Scenario::from_config(&c).expect("a valid scenario");
    let track = Track::of(&scenario);
    let (imu, mut ekf) = start::<STATES>(&scenario, &track, 0);
    let mut sim = SimulatedImu::new(&scenario, &track, imu);
    let mut gnss = SimulatedGnss::of(&scenario, &track);
    let mut extra = sources::<STATES, SimulatedImu>(0.0, scenario.duration_s, &scenario.aids());
    assert_eq!(extra.len(), 1, "the throwaway is in the list");
    let mut list = vec![&mut gnss as &mut dyn Source<STATES, SimulatedImu>];
    list.extend(
        extra
            .iter_mut()
            .map(|s| &mut **s as &mut dyn Source<STATES, SimulatedImu>),
    );
    let mut count = Count::default();
    Driver::new(list)
        .run(&mut ekf, &mut sim, &mut count)
        .expect("the drive runs");
    // One a second at k + 0.5 s, 60 of them in (0, 60], between the fixes.
    assert_eq!(count.other.len(), 60);
    assert!(count.gnss >= 59, "{} fixes", count.gnss);
    for (t, names, nis) in &count.other {
        assert_eq!((t - 0.5).fract(), 0.0, "at {t} s");
        assert_eq!(names, &["velocity_d"]);
        // The truth's own down velocity with σ = 1 m/s: νᵀS⁻¹ν far inside χ²₁'s 0.999 quantile.
        assert!(nis.is_finite() && *nis < 10.83, "NIS {nis} at {t} s");
    }
}

#[test]
fn the_throwaway_measurement_runs_in_calibrate_imu() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/comma2k19_3d");
    let (imu, gnss) = (
        LogFile::new(&dir.join("imu.csv")),
        LogFile::new(&dir.join("gnss.csv")),
    );
    let c = calibrate(&imu, &gnss, &CONSUMER).expect("the recording calibrates");
    // The records are the GNSS fixes': the throwaway's updates are judged through them.
    assert!(
        c.records
            .iter()
            .all(|r| r.rows == 6 || r.rows == 5 || r.rows == 3)
    );
    assert!(c.records.len() > 500, "{} records", c.records.len());
    let g = c.records.last().expect("records").gyro_bias_rad_s;
    assert!(g.iter().all(|x| x.is_finite()));
}
