//! The five figures of a three-axis calibration's page: the track, the six biases, the attitude,
//! the innovations within ±√S and the NIS of every fix.

use super::RenderError;
use super::figures::figure;
use super::view::FigureView;
use crate::calibrate::imu::run::{Calibrated, bias_sigmas, euler_sigmas};
use crate::calibrate::imu::smoother::Smoothed;
use crate::calibrate::imu::summary::Summary;
use crate::format::{count, percent, sig};
use crate::ins::earth::radii_m;
use crate::ins::euler_of;
use crate::plot::calibration_imu::{
    EstimateSeries, InnovationSeries, imu_estimates, imu_innovations, imu_nis,
};
use crate::stats::chi_squared_band;

/// The axes' names.
const AXIS: [&str; 3] = ["x", "y", "z"];
/// The innovation components in words, with their unit, in the records' order.
const COMPONENTS: [(&str, &str); 6] = [
    ("north position", "m"),
    ("east position", "m"),
    ("down position", "m"),
    ("north velocity", "m/s"),
    ("east velocity", "m/s"),
    ("down velocity", "m/s"),
];

/// `yaw` (°) without its jumps of 360°: each value within 180° of the one before.
///
/// # Formula
/// ψ'_k = ψ_k − 360°·round((ψ_k − ψ'_{k−1}) / 360°).
pub fn unwrapped_deg(yaw: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(yaw.len());
    for &y in yaw {
        let v = match out.last() {
            Some(prev) => y - 360.0 * ((y - prev) / 360.0).round(),
            None => y,
        };
        out.push(v);
    }
    out
}

/// The five figures of the page of `c`, `s`, `smoothed`.
///
/// # Errors
/// [`RenderError::Figure`] when a figure cannot be drawn.
pub fn figures<const N: usize>(
    c: &Calibrated<N>,
    s: &Summary,
    smoothed: &[Smoothed<N>],
) -> Result<Vec<FigureView>, RenderError> {
    let r = &c.records;
    let t: Vec<f64> = r.iter().map(|f| f.t_s).collect();
    Ok(vec![
        track(c, &t)?,
        biases(c, smoothed, &t, ("fig-imu-biases", 2))?,
        attitude(c, smoothed, &t)?,
        innovations(c, &t)?,
        nis(c, s, &t, ("fig-imu-nis", 5))?,
    ])
}

/// Figure 1: north and east from the first fix (the local radii of curvature at its latitude,
/// Groves (2013) eqs. 2.105–2.106: Δn = (R_N + h)·ΔL, Δe = (R_E + h)·cos L·Δλ) and the height.
fn track<const N: usize>(c: &Calibrated<N>, t: &[f64]) -> Result<FigureView, RenderError> {
    let first = c.records.first().map(|f| f.pva.position);
    let (mut north, mut east, mut height) = (Vec::new(), Vec::new(), Vec::new());
    if let Some(p0) = first {
        let (rn, re) = radii_m(p0.lat_rad);
        for f in &c.records {
            let p = f.pva.position;
            north.push((p.lat_rad - p0.lat_rad) * (rn + p0.height_m));
            let d_lon = crate::ins::earth::longitude_difference(p.lon_rad, p0.lon_rad);
            east.push(d_lon * (re + p0.height_m) * p0.lat_rad.cos());
            height.push(p.height_m);
        }
    }
    let svg = if north.is_empty() {
        crate::plot::ins_track(&[0.0], &[0.0], &[0.0], &[0.0])
    } else {
        crate::plot::ins_track(t, &north, &east, &height)
    };
    figure(
        "fig-imu-track",
        1,
        "The track",
        &format!(
            "The filtered solution at each of the {} fixes the filter used, seen from above (north against east, metres from the first, the dot) and its ellipsoidal height.",
            count(c.records.len() as u64)
        ),
        svg,
    )
}

/// Figure 2: the six biases, filtered and smoothed, ±σ; `(id, number)` its element id and
/// number.
pub(super) fn biases<const N: usize>(
    c: &Calibrated<N>,
    sm: &[Smoothed<N>],
    t: &[f64],
    (id, number): (&str, usize),
) -> Result<FigureView, RenderError> {
    let r = &c.records;
    let mut series = Vec::new();
    for i in 0..6 {
        let gyro = i < 3;
        let k = i % 3;
        let pick = |g: &nalgebra::Vector3<f64>, a: &nalgebra::Vector3<f64>| {
            if gyro { g[k] } else { a[k] }
        };
        let sigma = |p: &crate::ins::error_state::Square<N>| {
            let (sg, sa) = bias_sigmas(p);
            if gyro { sg[k] } else { sa[k] }
        };
        series.push(EstimateSeries {
            title: format!(
                "{} bias, {}",
                if gyro { "Gyro" } else { "Accelerometer" },
                AXIS[k]
            ),
            name: "bias",
            unit: if gyro { "rad/s" } else { "m/s²" },
            t_s: t,
            filtered: r
                .iter()
                .map(|f| pick(&f.gyro_bias_rad_s, &f.accel_bias_m_s2))
                .collect(),
            filtered_sigma: r.iter().map(|f| sigma(&f.covariance)).collect(),
            smoothed: sm
                .iter()
                .map(|f| pick(&f.gyro_bias_rad_s, &f.accel_bias_m_s2))
                .collect(),
            smoothed_sigma: sm.iter().map(|f| sigma(&f.covariance)).collect(),
        });
    }
    figure(
        id,
        number,
        "The six biases",
        "The gyro biases (rad/s, top) and the accelerometer biases (m/s², bottom) in body axes at each fix: the filtered estimate after the fix's update and the smoothed one (Rauch–Tung–Striebel over every fix), each with ±1σ. The axes are fitted after the first second, where the prior's σ has collapsed; a band that stays wide is a bias the drive does not determine.",
        imu_estimates(&series),
    )
}

/// Figure 3: roll, pitch and yaw, filtered and smoothed, ±σ.
fn attitude<const N: usize>(
    c: &Calibrated<N>,
    sm: &[Smoothed<N>],
    t: &[f64],
) -> Result<FigureView, RenderError> {
    let deg = |(r, p, y): (f64, f64, f64)| [r, p, y].map(f64::to_degrees);
    let filtered: Vec<[f64; 3]> = c
        .records
        .iter()
        .map(|f| deg(euler_of(&f.pva.attitude)))
        .collect();
    let smoothed: Vec<[f64; 3]> = sm.iter().map(|f| deg(euler_of(&f.pva.attitude))).collect();
    let fs: Vec<[f64; 3]> = c
        .records
        .iter()
        .map(|f| euler_sigmas(&f.pva, &f.covariance).map(f64::to_degrees))
        .collect();
    let ss: Vec<[f64; 3]> = sm
        .iter()
        .map(|f| euler_sigmas(&f.pva, &f.covariance).map(f64::to_degrees))
        .collect();
    let names = ["Roll", "Pitch", "Yaw"];
    let series: Vec<EstimateSeries> = (0..3)
        .map(|k| {
            let col = |v: &[[f64; 3]]| v.iter().map(|a| a[k]).collect::<Vec<_>>();
            let (mut f, mut s) = (col(&filtered), col(&smoothed));
            if k == 2 {
                // The smoothed yaw is unwrapped next to the filtered one, not on its own.
                f = unwrapped_deg(&f);
                s = s
                    .iter()
                    .zip(&f)
                    .map(|(y, r)| y - 360.0 * ((y - r) / 360.0).round())
                    .collect();
            }
            EstimateSeries {
                title: names[k].to_string(),
                name: ["roll", "pitch", "yaw"][k],
                unit: "°",
                t_s: t,
                filtered: f,
                filtered_sigma: col(&fs),
                smoothed: s,
                smoothed_sigma: col(&ss),
            }
        })
        .collect();
    figure(
        "fig-imu-attitude",
        3,
        "The attitude",
        "Roll, pitch and yaw of the IMU's body axes (z-y-x Euler angles of q_{b}^{n}, °) at each fix, filtered and smoothed with ±1σ; the yaw is drawn without its jumps of 360°.",
        imu_estimates(&series),
    )
}

/// Figure 4: the innovation of each measured component within ±√S.
fn innovations<const N: usize>(c: &Calibrated<N>, t: &[f64]) -> Result<FigureView, RenderError> {
    let r = &c.records;
    let measured: Vec<usize> = (0..6)
        .filter(|&i| r.iter().any(|f| f.innovation[i].is_finite()))
        .collect();
    let series: Vec<InnovationSeries> = measured
        .iter()
        .map(|&i| InnovationSeries {
            title: format!("Innovation, {}", COMPONENTS[i].0),
            name: "ν",
            unit: COMPONENTS[i].1,
            t_s: t,
            innovation: r.iter().map(|f| f.innovation[i]).collect(),
            sqrt_s: r.iter().map(|f| f.innovation_sigma[i]).collect(),
        })
        .collect();
    let left_out: Vec<&str> = (0..6)
        .filter(|i| !measured.contains(i))
        .map(|i| COMPONENTS[i].0)
        .collect();
    let missing = if left_out.is_empty() {
        String::new()
    } else {
        format!(
            " The {} is not measured by any fix and has no panel.",
            left_out.join(" and ")
        )
    };
    figure(
        "fig-imu-innovations",
        4,
        "Innovations",
        &format!(
            "The innovation ν = z − ẑ⁻ of each measured component at each fix within the ±√S and ±2√S the filter predicts for it (the diagonal of S = HP^{{−}}H^{{T}} + R); for a consistent filter about 68 % and 95 % of the points fall inside and neighbours are unrelated.{missing}"
        ),
        imu_innovations(&series),
    )
}

/// Figure 5: the NIS of every fix against the χ²(mᵢ) band of its own mᵢ; `(id, number)` its
/// element id and number.
pub(super) fn nis<const N: usize>(
    c: &Calibrated<N>,
    s: &Summary,
    t: &[f64],
    (id, number): (&str, usize),
) -> Result<FigureView, RenderError> {
    let n = &s.nis;
    let alpha = n.false_alarm_rate;
    let bands: Vec<(f64, f64)> = c
        .records
        .iter()
        .map(|f| chi_squared_band(f.rows as f64, 1.0, alpha))
        .collect();
    let lower: Vec<f64> = bands.iter().map(|b| b.0).collect();
    let upper: Vec<f64> = bands.iter().map(|b| b.1).collect();
    let values: Vec<f64> = c.records.iter().map(|f| f.nis).collect();
    let title = format!(
        "NIS per fix; sum {} over {} fixes, band [{}, {}]: {}",
        sig(n.sum, 4),
        count(n.fixes as u64),
        sig(n.lower, 4),
        sig(n.upper, 4),
        n.verdict
    );
    figure(
        id,
        number,
        "Normalized innovations squared",
        &format!(
            "The NIS ν^{{T}}S^{{−1}}ν of each fix, χ²(m_{{i}}) for a consistent filter with m_{{i}} the components the fix measured, against the band that holds it with probability 1 − α = {} (α/2 in each tail); {} fixes are outside in vermillion, about {} would be by chance.",
            percent(1.0 - alpha),
            count(n.outside_per_fix as u64),
            sig(n.expected_outside_per_fix, 2)
        ),
        imu_nis(t, &values, [&lower, &upper], &title),
    )
}

#[cfg(test)]
mod tests {
    use super::unwrapped_deg;

    #[test]
    fn a_turn_through_south_is_drawn_without_its_jump() {
        // 170° → −170° is a turn of +20°, not of −340°; back again, and a second lap.
        let y = unwrapped_deg(&[170.0, -170.0, -150.0, 170.0, -10.0, 170.0, -170.0]);
        assert_eq!(y, vec![170.0, 190.0, 210.0, 170.0, 350.0, 530.0, 550.0]);
        // Negative control: values within 180° of each other are left alone.
        let z = [10.0, 100.0, -60.0, 30.0];
        assert_eq!(unwrapped_deg(&z), z.to_vec());
    }
}
