//! One simulated realization of the three-axis scenario written as sensor logs, in the formats of a
//! real recording (`imu.csv`, `gnss.csv`) and its truth (`truth.csv`).
//!
//! - `imu.csv`: `t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s`, body axes
//!   forward-right-down; each row is the IMU's output over the step ending at `t_s` as a mean
//!   rate (Δv/Δt, Δθ/Δt), so that rate × Δt gives back the increments.
//! - `gnss.csv`: `t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s`, the antenna's fix.
//! - `truth.csv`: `t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s,roll_deg,pitch_deg,yaw_deg`
//!   of the IMU, and the six biases `bgx_rad_s,bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2`
//!   over the step ending at `t_s`, at every IMU time; when the IMU has scale factors, the six
//!   of them besides, `sgx_ppm,sgy_ppm,sgz_ppm,sax_ppm,say_ppm,saz_ppm` (constants); in a car,
//!   the IMU's true mounting `mount_roll_deg,mount_pitch_deg,mount_yaw_deg` (ZYX, from the IMU's
//!   axes to the vehicle's; constants).
//!
//! Numbers are written as the shortest decimals that read back to the same `f64` (a negative
//! zero as 0).

use std::io::{self, Write};

use nalgebra::Vector3;

use super::drive::Drive;
use super::earth::offset;
use super::gnss::{self, Fix};
use super::mech::Pva;
use super::sensors::Imu;
use super::setup::Scenario;
use super::truth::{self, Truth};

/// The IMU log's header.
pub const IMU_HEADER: &str = "t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s";
/// The GNSS log's header.
pub const GNSS_HEADER: &str = "t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s";
/// The truth's header.
pub const TRUTH_HEADER: &str = "t_s,lat_deg,lon_deg,height_m,vn_m_s,ve_m_s,vd_m_s,roll_deg,pitch_deg,\
                                yaw_deg,bgx_rad_s,bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2";
/// The truth's columns of the scale factors, when the IMU has them.
pub const TRUTH_SCALE_COLUMNS: &str = ",sgx_ppm,sgy_ppm,sgz_ppm,sax_ppm,say_ppm,saz_ppm";
/// The truth's columns of the mounting, in a car.
pub const TRUTH_MOUNTING_COLUMNS: &str = ",mount_roll_deg,mount_pitch_deg,mount_yaw_deg";

/// What a written realization holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Written {
    /// IMU rows.
    pub samples: usize,
    /// GNSS fixes.
    pub fixes: usize,
    /// The gyro biases at the start, rad/s.
    pub gyro_bias_rad_s: Vector3<f64>,
    /// The accelerometer biases at the start, m/s².
    pub accel_bias_m_s2: Vector3<f64>,
    /// The IMU's true mounting in a car: roll, pitch, yaw (ZYX), degrees.
    pub mounting_rpy_deg: Option<[f64; 3]>,
}

/// The fix the receiver reports at `t_s` for the true state `vehicle` (the drive's): the
/// antenna through the lever arm (IMU axes), with the receiver's white noise from the
/// realization's stream.
pub fn fix(scenario: &Scenario, drive: &Drive, imu: &mut Imu, t_s: f64, vehicle: &Pva) -> Fix {
    let g = &scenario.truth_gnss;
    let (omega, _) = truth::imu_rates(&vehicle.position, &drive.motion(t_s));
    let pva = imu.pva_of(vehicle);
    let (p, v) = gnss::antenna(&pva, &g.lever_arm_b_m, &imu.to_body(&omega));
    Fix {
        t_s,
        position: offset(&p, &imu.normals(&g.position_sigma_m)),
        velocity_ned_m_s: Some(v + imu.normals(&g.velocity_sigma_m_s)),
        position_sigma_m: g.position_sigma_m,
        velocity_sigma_m_s: g.velocity_sigma_m_s,
    }
}

/// Realization `index` of `scenario` written into `imu`, `gnss` and `truth`.
///
/// # Errors
/// The writers' errors.
pub fn write_realization(
    scenario: &Scenario,
    index: u64,
    imu_out: &mut impl Write,
    gnss_out: &mut impl Write,
    truth_out: &mut impl Write,
) -> io::Result<Written> {
    writeln!(imu_out, "{IMU_HEADER}")?;
    writeln!(gnss_out, "{GNSS_HEADER}")?;
    let m = &scenario.truth_imu;
    let scaled = m.gyro_scale_sigma > 0.0 || m.accel_scale_sigma > 0.0;
    let scale_columns = if scaled { TRUTH_SCALE_COLUMNS } else { "" };
    let mut imu = scenario.imu(index);
    let mounting_rpy_deg = imu.mounting.map(|q| {
        let (r, p, y) = super::euler_of(&q);
        [r, p, y].map(f64::to_degrees)
    });
    let mounting_columns = match mounting_rpy_deg {
        Some(_) => TRUTH_MOUNTING_COLUMNS,
        None => "",
    };
    writeln!(truth_out, "{TRUTH_HEADER}{scale_columns}{mounting_columns}")?;
    let drive = scenario.drive();
    let dt = 1.0 / scenario.imu_rate_hz;
    let truth = Truth::new(&drive, scenario.start, dt).until(scenario.duration_s);
    let start = (imu.gyro_bias_rad_s, imu.accel_bias_m_s2);
    let (mut samples, mut fixes) = (0, 0);
    for (k, (inc, pva)) in truth.enumerate() {
        let t = (k + 1) as f64 * dt;
        let (bg, ba) = (imu.gyro_bias_rad_s, imu.accel_bias_m_s2);
        let raw = imu.read(&inc);
        let (a, w) = (raw.dvel_m_s / dt, raw.dtheta_rad / dt);
        row(imu_out, t, &[a.x, a.y, a.z, w.x, w.y, w.z])?;
        let (roll, pitch, yaw) = super::euler_of(&imu.pva_of(&pva).attitude);
        let (p, v) = (&pva.position, pva.velocity_ned_m_s);
        let mut values = vec![
            p.lat_rad.to_degrees(),
            p.lon_rad.to_degrees(),
            p.height_m,
            v.x,
            v.y,
            v.z,
            roll.to_degrees(),
            pitch.to_degrees(),
            yaw.to_degrees(),
            bg.x,
            bg.y,
            bg.z,
            ba.x,
            ba.y,
            ba.z,
        ];
        if scaled {
            values.extend(
                imu.gyro_scale
                    .iter()
                    .chain(&imu.accel_scale)
                    .map(|x| x * 1e6),
            );
        }
        values.extend(mounting_rpy_deg.iter().flatten());
        row(truth_out, t, &values)?;
        samples += 1;
        if (k + 1) % scenario.imu_steps_per_fix == 0 {
            let f = fix(scenario, &drive, &mut imu, t, &pva);
            let (p, v) = (
                &f.position,
                f.velocity_ned_m_s.unwrap_or_else(Vector3::zeros),
            );
            let (lat, lon) = (p.lat_rad.to_degrees(), p.lon_rad.to_degrees());
            row(gnss_out, t, &[lat, lon, p.height_m, v.x, v.y, v.z])?;
            fixes += 1;
        }
    }
    Ok(Written {
        samples,
        fixes,
        gyro_bias_rad_s: start.0,
        accel_bias_m_s2: start.1,
        mounting_rpy_deg,
    })
}

/// One CSV row: `t` and `values`, each the shortest decimal that reads back to it, a negative
/// zero written as 0 (what a reader of the CSV expects).
fn row(out: &mut impl Write, t: f64, values: &[f64]) -> io::Result<()> {
    write!(out, "{t}")?;
    for x in values {
        write!(out, ",{}", x + 0.0)?;
    }
    writeln!(out)
}
