//! The error state's and the GNSS measurement's components in words, for the checks' members,
//! the JSON and the report (the same order as [`super::error_state`]'s indices).

use crate::state::Variable;

const fn v(
    key: &'static str,
    name: &'static str,
    symbol: &'static str,
    unit: &'static str,
) -> Variable {
    Variable {
        key,
        name,
        symbol,
        unit,
    }
}

/// The error states: δr, δv (NED), δψ, δb_g, δb_a (body axes), then in the 21-state form δs_g,
/// δs_a (the first 15 are the 15-state form's), and a car's δμ (vehicle axes): three per
/// [`super::state::Block`], in its order.
pub const VARIABLES: [Variable; 24] = [
    v("position_n", "north position error", "δr_N", "m"),
    v("position_e", "east position error", "δr_E", "m"),
    v("position_d", "down position error", "δr_D", "m"),
    v("velocity_n", "north velocity error", "δv_N", "m/s"),
    v("velocity_e", "east velocity error", "δv_E", "m/s"),
    v("velocity_d", "down velocity error", "δv_D", "m/s"),
    v("attitude_n", "attitude error about north", "δψ_N", "rad"),
    v("attitude_e", "attitude error about east", "δψ_E", "rad"),
    v("attitude_d", "attitude error about down", "δψ_D", "rad"),
    v("gyro_bias_x", "gyro bias error, x", "δb_gx", "rad/s"),
    v("gyro_bias_y", "gyro bias error, y", "δb_gy", "rad/s"),
    v("gyro_bias_z", "gyro bias error, z", "δb_gz", "rad/s"),
    v(
        "accel_bias_x",
        "accelerometer bias error, x",
        "δb_ax",
        "m/s²",
    ),
    v(
        "accel_bias_y",
        "accelerometer bias error, y",
        "δb_ay",
        "m/s²",
    ),
    v(
        "accel_bias_z",
        "accelerometer bias error, z",
        "δb_az",
        "m/s²",
    ),
    v("gyro_scale_x", "gyro scale factor error, x", "δs_gx", "1"),
    v("gyro_scale_y", "gyro scale factor error, y", "δs_gy", "1"),
    v("gyro_scale_z", "gyro scale factor error, z", "δs_gz", "1"),
    v(
        "accel_scale_x",
        "accelerometer scale factor error, x",
        "δs_ax",
        "1",
    ),
    v(
        "accel_scale_y",
        "accelerometer scale factor error, y",
        "δs_ay",
        "1",
    ),
    v(
        "accel_scale_z",
        "accelerometer scale factor error, z",
        "δs_az",
        "1",
    ),
    v("mounting_x", "mounting angle error about x", "δμ_x", "rad"),
    v("mounting_y", "mounting angle error about y", "δμ_y", "rad"),
    v("mounting_z", "mounting angle error about z", "δμ_z", "rad"),
];

/// The GNSS measurement's rows: position and velocity, NED.
pub const MEASURED: usize = 6;

/// The 6 innovation components: the antenna's position and velocity, NED.
pub const MEASUREMENTS: [Variable; MEASURED] = [
    v("position_n", "north position", "r_N", "m"),
    v("position_e", "east position", "r_E", "m"),
    v("position_d", "down position", "r_D", "m"),
    v("velocity_n", "north velocity", "v_N", "m/s"),
    v("velocity_e", "east velocity", "v_E", "m/s"),
    v("velocity_d", "down velocity", "v_D", "m/s"),
];
