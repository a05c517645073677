//! imu.yaml's keys against values worked out by hand.

use super::*;
use crate::allan::analyse;
use crate::allan::imu::ChannelAnalysis;
use crate::allan::simulate::StaticLog;

/// An analysis whose reported N, B and K are set to the given values (the fit's reading).
fn with_terms(n: f64, b: f64, k: f64) -> Analysis {
    let log = StaticLog {
        sample_period_s: 0.01,
        velocity_random_walk_m_s_per_sqrt_s: 2e-3,
        acceleration_random_walk_m_s2_per_sqrt_s: 0.0,
        offset_m_s2: 0.0,
    };
    let mut a = analyse(&log.samples(20_000, 1), 0.01, 0.683).unwrap();
    a.reading = Reading::Fit;
    for t in &mut a.terms {
        let v = match t.term {
            Term::VelocityRandomWalk => n,
            Term::BiasInstability => b,
            Term::AccelerationRandomWalk => k,
            _ => continue,
        };
        (t.value, t.lower, t.upper) = (Some(v), Some(0.9 * v), 1.1 * v);
    }
    a
}

/// Each key of imu.yaml against a value worked out by hand from the terms set: the largest
/// of the axes in the key's unit, and KF-GINS's units.
#[test]
fn imu_yaml_keys_hold_hand_computed_values() {
    // Gyro y: N = 0.1 °/√h = 0.1·(π/180)/60 rad/√s, B = 0.6643·(50 °/h in rad/s), K = 1e-6.
    // Accelerometer z: N = 1/60 m/s/√s (1 m/s/√h), B = 0.6643·10⁻³ m/s² (σ_b 100 mGal).
    let terms = [
        (Channel::Ax, (1e-3, 1e-4, 1e-5)),
        (Channel::Ay, (2e-3, 2e-4, 2e-5)),
        (Channel::Az, (1.0 / 60.0, 0.6643e-3, 3e-5)),
        (Channel::Gx, (1e-5, 1e-5, 1e-7)),
        (
            Channel::Gy,
            (
                2.908_882_086_657_216e-5,
                0.6643 * 2.424_068_405_547_679_8e-4,
                1e-6,
            ),
        ),
        (Channel::Gz, (2e-5, 1e-5, 2e-7)),
    ];
    let imu = ImuAnalysis {
        samples: 20_000,
        sample_period_s: 0.01,
        confidence: 0.683,
        channels: terms
            .iter()
            .map(|&(channel, (n, b, k))| ChannelAnalysis {
                channel,
                analysis: with_terms(n, b, k),
            })
            .collect(),
    };
    let text = imu_yaml(&imu, "hand.csv");
    let y = &yaml_rust2::YamlLoader::load_from_str(&text).unwrap()[0];
    let real = |key: &str| y[key].as_f64().unwrap_or_else(|| panic!("{key}\n{text}"));
    assert_eq!(
        real("accelerometer_noise_density"),
        0.016_666_666_666_666_666
    );
    assert_eq!(real("accelerometer_random_walk"), 3e-5);
    assert_eq!(real("gyroscope_noise_density"), 2.908_882_086_657_216e-5);
    assert_eq!(real("gyroscope_random_walk"), 1e-6);
    assert_eq!(real("update_rate"), 100.0);
    // Discrete at 100 Hz: (1/60)·√100 = 0.1667 m/s²; 1e-6/√100 = 1e-7 rad/s.
    assert!(
        text.contains("discrete at the log's rate: 0.1667 m/s²"),
        "{text}"
    );
    assert!(
        text.contains("on gy_rad_s; discrete at the log's rate: 1.000 × 10⁻⁷ rad/s"),
        "{text}"
    );
    let kf = &y["imunoise"];
    let close = |v: &yaml_rust2::Yaml, want: f64| {
        let got = v.as_f64().unwrap();
        assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}\n{text}");
    };
    close(&kf["arw"][1], 0.1);
    close(&kf["vrw"][2], 1.0);
    close(&kf["gbstd"][1], 50.0);
    close(&kf["abstd"][2], 100.0);
    assert!(kf["corrtime"].as_f64().unwrap() > 0.0);
}
