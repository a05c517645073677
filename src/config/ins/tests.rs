//! The three-axis configuration: the default file, the fallback to the truth, bad values.
use super::*;

#[test]
fn the_default_file_parses_to_the_default_and_validates() {
    let c = InsConfig::from_toml_str(DEFAULT_INS_TOML).unwrap();
    assert_eq!(
        c,
        InsConfig {
            model: Some("ins".into()),
            ..InsConfig::default()
        }
    );
    c.validate().unwrap();
    // The datasheet figures behind the defaults.
    let i = ImuConfig::default();
    assert_eq!(i.gyro_arw_rad_per_sqrt_s, 0.1_f64.to_radians() / 60.0);
    assert_eq!(i.accel_vrw_m_s_per_sqrt_s, 0.1 / 60.0);
    assert_eq!(i.gyro_bias_sigma_rad_s, (50.0_f64 / 3600.0).to_radians());
    assert_eq!(i.accel_bias_sigma_m_s2, 0.25e-3 * 9.80665);
}

#[test]
fn missing_filter_keys_take_the_truth_s() {
    let c = InsConfig::from_toml_str(
        "[imu]\ngyro_arw_rad_per_sqrt_s = 1e-4\n[filter]\ngnss_lever_arm_m = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let a = c.assumed();
    assert_eq!(a.imu.gyro_arw_rad_per_sqrt_s, 1e-4);
    assert_eq!(a.gnss.gnss_lever_arm_m, [0.0; 3]);
    assert_eq!(a.gnss.gnss_position_sigma_m, c.gnss.gnss_position_sigma_m);
}

#[test]
fn bad_values_name_their_field_and_range() {
    let error = |text: &str| {
        InsConfig::from_toml_str(text)
            .and_then(|c| c.validate())
            .unwrap_err()
            .to_string()
    };
    let e = error("[gnss]\ngnss_rate_hz = 400.0\n");
    assert!(e.contains("gnss.gnss_rate_hz") && e.contains("IMU"), "{e}");
    let e = error("[gnss]\ngnss_rate_hz = 3.0\n");
    assert!(e.contains("divides"), "{e}");
    let e = error("[filter]\ngyro_arw_rad_per_sqrt_s = -1.0\n");
    assert!(e.contains("filter.gyro_arw_rad_per_sqrt_s"), "{e}");
    let e = error("[drive]\nstart_lat_deg = 89.5\n");
    assert!(e.contains("drive.start_lat_deg") && e.contains("80"), "{e}");
    let e = error("[imu]\ngyro_arw = 1.0\n");
    assert!(e.contains("gyro_arw"), "{e}");
    let e = error("model = \"1d\"\n");
    assert!(e.contains("model"), "{e}");
    let e = error("[gnss]\ngnss_lever_arm_m = [0.0, 1e9, 0.0]\n");
    assert!(e.contains("gnss.gnss_lever_arm_m"), "{e}");
}
