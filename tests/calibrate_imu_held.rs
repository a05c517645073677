//! The three-axis logs held as columns (`read::held_steps`, `gnss::held_gnss`, what the Python
//! package hands the library): the same steps, span and rows as the readers give for the shipped
//! comma2k19 minute, with a negative control; a NaN, an infinity and a short column refused
//! with the column and the line of the equivalent CSV (index + 2).

use std::path::PathBuf;

use accelcal::config::ins::Axes;
use accelcal::input::csv::read::LogFile;
use accelcal::input::gnss_csv::{GNSS_COLUMNS, GNSS_OPTIONAL, held_gnss, read_gnss};
use accelcal::input::imu_csv::{ImuLayout, held_steps, read_steps};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("examples/comma2k19_3d")
        .join(name)
}

/// A CSV's columns by name, "nan" read as NaN.
fn columns(name: &str) -> Vec<(String, Vec<f64>)> {
    let text = std::fs::read_to_string(example(name)).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut out: Vec<(String, Vec<f64>)> = names.into_iter().map(|n| (n, Vec::new())).collect();
    for line in lines {
        for (k, field) in line.split(',').enumerate() {
            out[k].1.push(field.parse().unwrap());
        }
    }
    out
}

fn column<'a>(table: &'a [(String, Vec<f64>)], name: &str) -> &'a [f64] {
    &table.iter().find(|(n, _)| n == name).unwrap().1
}

#[test]
fn held_columns_give_the_readers_steps_and_rows() {
    let imu = columns("imu.csv");
    let mut six = [&[][..]; 6];
    for (k, c) in six.iter_mut().enumerate() {
        *c = &imu[k + 1].1;
    }
    let held = held_steps("imu", &imu[0].1, six, ImuLayout::Rates, Axes::Frd).unwrap();
    let read = read_steps(&LogFile::new(&example("imu.csv")), Axes::Frd).unwrap();
    assert_eq!(held, read);
    assert_eq!(held.0.len(), imu[0].1.len() - 1);

    let gnss = columns("gnss.csv");
    let required = GNSS_COLUMNS.map(|c| column(&gnss, c));
    let optional = GNSS_OPTIONAL.map(|c| gnss.iter().find(|(n, _)| n == c).map(|(_, v)| &v[..]));
    let rows = held_gnss("gnss", required, optional).unwrap();
    assert_eq!(
        rows,
        read_gnss(&LogFile::new(&example("gnss.csv"))).unwrap()
    );
    assert!(
        rows.iter()
            .filter(|r| r.velocity_ned_m_s[2].is_none())
            .count()
            > 500
    );

    // Negative control: one gyro sample moved by 1e-9 rad/s is another step.
    let mut moved = imu[6].1.clone();
    moved[100] += 1e-9;
    six[5] = &moved;
    let other = held_steps("imu", &imu[0].1, six, ImuLayout::Rates, Axes::Frd).unwrap();
    assert_ne!(other.0, read.0);
}

#[test]
fn bad_columns_name_the_column_and_the_line() {
    let imu = columns("imu.csv");
    let mut ay = imu[2].1.clone();
    ay[5] = f64::NAN;
    let mut six = [&[][..]; 6];
    for (k, c) in six.iter_mut().enumerate() {
        *c = &imu[k + 1].1;
    }
    six[1] = &ay;
    let e = held_steps("imu", &imu[0].1, six, ImuLayout::Rates, Axes::Frd).unwrap_err();
    assert_eq!(
        e.to_string(),
        "imu, line 7: `ay_m_s2` = `NaN` is not a finite number"
    );
    six[1] = &imu[2].1[..10];
    let e = held_steps("imu", &imu[0].1, six, ImuLayout::Rates, Axes::Frd).unwrap_err();
    assert!(
        e.to_string().contains("ay_m_s2 has 10 values and t_s has"),
        "{e}"
    );

    let gnss = columns("gnss.csv");
    let required = GNSS_COLUMNS.map(|c| column(&gnss, c));
    let mut vn = column(&gnss, "vn_m_s").to_vec();
    vn[3] = f64::INFINITY;
    let mut optional = [None; 9];
    optional[0] = Some(&vn[..]);
    let e = held_gnss("gnss", required, optional).unwrap_err();
    assert_eq!(
        e.to_string(),
        "gnss, line 5: `vn_m_s` = `inf` is not a finite number"
    );
    let mut t = required[0].to_vec();
    t.swap(8, 9);
    let e = held_gnss(
        "gnss",
        [&t, required[1], required[2], required[3]],
        [None; 9],
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("gnss, line 11: "), "{e}");
}
