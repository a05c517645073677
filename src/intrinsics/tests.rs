//! The calibration against sessions drawn from its model.

use super::simulate::{Session, draw_intrinsics, random_poses, simulate};
use super::{Settings, calibrate};
use crate::random::Stream;

#[test]
fn a_session_of_twelve_poses_recovers_the_intrinsics() {
    let mut rng = Stream::new(0x01a7, 0);
    let truth = draw_intrinsics(&mut rng);
    let session = Session::consumer(random_poses(12, &mut rng));
    let log = simulate(&truth, &session, &mut rng);
    let mut settings = Settings::new(session.gravity_m_s2);
    settings.latitude_rad = Some(session.latitude_rad);
    let x = calibrate(&log, &settings).expect("a good session");
    assert_eq!(
        x.detection.intervals.len(),
        12,
        "{:?}",
        x.detection.intervals
    );
    let a = &x.accel;
    assert!(a.determined.iter().all(|d| *d));
    for i in 0..3 {
        let z = (a.params[i] - truth.accel_bias[i]) / a.covariance[(i, i)].sqrt();
        assert!(z.abs() < 5.0, "bias {i}: z {z}");
        let zg = (x.gyro.bias[i].value - truth.gyro_bias[i]) / x.gyro.bias[i].sigma;
        assert!(zg.abs() < 5.0, "gyro bias {i}: z {zg}");
    }
    let m = a.matrix();
    for (k, &(r, c)) in super::accel::MATRIX_ENTRIES.iter().enumerate() {
        let z = (m[(r, c)] - truth.accel_matrix[(r, c)]) / a.covariance[(3 + k, 3 + k)].sqrt();
        assert!(z.abs() < 5.0, "m[{r},{c}]: z {z}");
    }
    eprintln!("{}", super::export::intrinsics_json(&x, "sim"));
}
