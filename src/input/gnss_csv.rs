//! The GNSS log of `calibrate --imu --gnss`: geodetic fixes, held whole (one [`GnssRow`] per
//! fix), read from CSV or from columns held in memory (the Python package's arrays).
//!
//! # Format
//! The CSV text of [`super::csv`] with the columns of `docs/guide/calibrate_imu.md` (§ The
//! recordings): `t_s,lat_deg,lon_deg,height_m` (WGS-84, ellipsoidal height), optionally
//!   `vn_m_s,ve_m_s,vd_m_s` and the σ's `sigma_n_m,sigma_e_m,sigma_d_m`,
//!   `sigma_vn_m_s,sigma_ve_m_s,sigma_vd_m_s`; in those optional columns an empty cell or `nan`
//!   means "not measured".

use std::io::{BufRead, Read};

use super::csv::read::LogSource;
use super::records::{Geodetic, GnssRow};
use super::{LogError, LogProblem, echo};

/// The GNSS log's required columns.
pub const GNSS_COLUMNS: [&str; 4] = ["t_s", "lat_deg", "lon_deg", "height_m"];
/// Its optional columns: velocity NED, then the position's and the velocity's σ's.
pub const GNSS_OPTIONAL: [&str; 9] = [
    "vn_m_s",
    "ve_m_s",
    "vd_m_s",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
    "sigma_vn_m_s",
    "sigma_ve_m_s",
    "sigma_vd_m_s",
];

/// A field's number: `None` for an empty cell or `nan` where `optional`, else a finite number.
fn field(text: &str, column: &'static str, optional: bool) -> Result<Option<f64>, LogProblem> {
    let t = text.trim();
    if optional && (t.is_empty() || t.eq_ignore_ascii_case("nan")) {
        return Ok(None);
    }
    match t.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(Some(x)),
        Ok(_) => Err(LogProblem::NotFinite {
            column,
            text: echo(t),
        }),
        Err(_) => Err(LogProblem::NotANumber {
            column,
            text: echo(t),
        }),
    }
}

/// `value` of `column` within `[lo, hi]`, or the problem.
fn within(
    column: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    words: &str,
) -> Result<(), LogProblem> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(LogProblem::OutOfRange {
            column,
            value,
            range: words.to_string(),
        })
    }
}

/// The lowest and highest ellipsoidal heights accepted, m: the normal-gravity model and the
/// radii hold from the deepest land to low orbit.
pub const HEIGHT_RANGE_M: (f64, f64) = (-12_000.0, 100_000.0);

/// Every fix of the GNSS log `source`, in time order.
///
/// # Errors
/// [`LogError`] naming the line of a malformed row, a missing required column, a NaN where one is
/// not allowed, a latitude beyond ±90°, a longitude beyond ±180°, a height outside
/// [`HEIGHT_RANGE_M`], a σ not positive, or a time stamp not after the previous; the file when
/// it holds no fix.
pub fn read_gnss(source: &dyn LogSource) -> Result<Vec<GnssRow>, LogError> {
    let name = source.name();
    let mut reader = source.open()?;
    let expected = format!(
        "{} and optionally {}",
        GNSS_COLUMNS.join(","),
        GNSS_OPTIONAL.join(",")
    );
    let mut buf = Vec::new();
    let (header, mut line) = header_line(&mut reader, &mut buf, name, &expected)?;
    let (required, optional) = gnss_columns(name, &header, line, &expected)?;
    let width = header.split(',').count();
    let at = |line: u64, problem| LogError::at(name, line, problem);
    let mut rows: Vec<GnssRow> = Vec::new();
    loop {
        if !next_line(&mut reader, &mut buf, name)? {
            break;
        }
        line += 1;
        if buf.len() > crate::input::csv::block::MAX_LINE_BYTES {
            let limit_bytes = crate::input::csv::block::MAX_LINE_BYTES;
            return Err(at(line, LogProblem::LineTooLong { limit_bytes }));
        }
        let text = std::str::from_utf8(&buf).map_err(|_| at(line, LogProblem::NotText))?;
        let text = text.trim_end_matches(['\n', '\r']);
        if text.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != width {
            let problem = LogProblem::FieldCount {
                expected: width,
                found: fields.len(),
                header: echo(&header),
            };
            return Err(at(line, problem));
        }
        let row = parse_row(&fields, &required, &optional, line).map_err(|p| at(line, p))?;
        push_increasing(&mut rows, row).map_err(|p| at(line, p))?;
    }
    some_rows(rows, name)
}

/// The next line of `reader` into `buf` (at most one byte beyond the longest line accepted);
/// false at the end.
fn next_line(reader: &mut dyn BufRead, buf: &mut Vec<u8>, name: &str) -> Result<bool, LogError> {
    buf.clear();
    let limit = crate::input::csv::block::MAX_LINE_BYTES as u64 + 1;
    let n = reader.take(limit).read_until(b'\n', buf).map_err(|e| {
        let message = e.to_string();
        LogError::of_file(name, LogProblem::Unreadable { message })
    })?;
    Ok(n > 0)
}

/// The header: the first line that is not blank, and its line.
fn header_line(
    reader: &mut dyn BufRead,
    buf: &mut Vec<u8>,
    name: &str,
    expected: &str,
) -> Result<(String, u64), LogError> {
    let mut line = 0;
    loop {
        if !next_line(reader, buf, name)? {
            let header = expected.to_string();
            return Err(LogError::of_file(name, LogProblem::Empty { header }));
        }
        line += 1;
        let text =
            std::str::from_utf8(buf).map_err(|_| LogError::at(name, line, LogProblem::NotText))?;
        if !text.trim().is_empty() {
            return Ok((text.trim_start_matches('\u{feff}').trim().to_string(), line));
        }
    }
}

/// Where the GNSS log's required and optional columns lie in `header` (at `line`).
#[allow(clippy::type_complexity)]
fn gnss_columns(
    name: &str,
    header: &str,
    line: u64,
    expected: &str,
) -> Result<([usize; 4], [Option<usize>; 9]), LogError> {
    let found: Vec<&str> = header.split(',').map(str::trim).collect();
    let at = |line: u64, problem| LogError::at(name, line, problem);
    for (k, c) in found.iter().enumerate() {
        if found[..k].contains(c) {
            return Err(at(line, LogProblem::DuplicateColumn { column: echo(c) }));
        }
    }
    let position = |c: &str| found.iter().position(|f| *f == c);
    let mut required = [0usize; 4];
    for (k, c) in GNSS_COLUMNS.iter().enumerate() {
        required[k] = position(c).ok_or_else(|| {
            at(
                line,
                LogProblem::MissingColumn {
                    column: c,
                    found: echo(header),
                    header: expected.to_string(),
                },
            )
        })?;
    }
    let optional = GNSS_OPTIONAL.map(position);
    Ok((required, optional))
}

/// One data row of the GNSS log.
fn parse_row(
    fields: &[&str],
    required: &[usize; 4],
    optional: &[Option<usize>; 9],
    line: u64,
) -> Result<GnssRow, LogProblem> {
    let mut r = [0.0; 4];
    for (k, &p) in required.iter().enumerate() {
        r[k] = field(fields[p], GNSS_COLUMNS[k], false)?.unwrap_or(f64::NAN);
    }
    check_required(&r)?;
    let mut o = [None; 9];
    for (k, p) in optional.iter().enumerate() {
        if let Some(p) = p {
            o[k] = field(fields[*p], GNSS_OPTIONAL[k], true)?;
            check_optional(k, o[k])?;
        }
    }
    Ok(row_of(line, r, o))
}

/// The ranges of the required values `r` ([`GNSS_COLUMNS`]).
fn check_required(r: &[f64; 4]) -> Result<(), LogProblem> {
    within("lat_deg", r[1], -90.0, 90.0, "latitude in [−90, 90]°")?;
    within("lon_deg", r[2], -180.0, 360.0, "longitude in [−180, 360]°")?;
    let (lo, hi) = HEIGHT_RANGE_M;
    within("height_m", r[3], lo, hi, "height in [−12 000, 100 000] m")
}

/// The range of the optional column `k` ([`GNSS_OPTIONAL`]) where it holds a value.
fn check_optional(k: usize, value: Option<f64>) -> Result<(), LogProblem> {
    let Some(x) = value else { return Ok(()) };
    if k >= 3 {
        within(
            GNSS_OPTIONAL[k],
            x,
            f64::MIN_POSITIVE,
            1e6,
            "a σ in (0, 10⁶]",
        )
    } else {
        within(
            GNSS_OPTIONAL[k],
            x,
            -1e4,
            1e4,
            "a speed in [−10 000, 10 000] m/s",
        )
    }
}

/// The row on `line` of the required values `r` ([`GNSS_COLUMNS`]) and the optional ones `o`
/// ([`GNSS_OPTIONAL`], `None` where not measured), their ranges checked.
fn row_of(line: u64, r: [f64; 4], o: [Option<f64>; 9]) -> GnssRow {
    GnssRow {
        line,
        t_s: r[0],
        position: Geodetic {
            lat_rad: r[1].to_radians(),
            lon_rad: super::records::wrap_longitude(r[2].to_radians()),
            height_m: r[3],
        },
        velocity_ned_m_s: [o[0], o[1], o[2]],
        position_sigma_m: [o[3], o[4], o[5]],
        velocity_sigma_m_s: [o[6], o[7], o[8]],
    }
}

/// The columns of a GNSS log held in memory (the Python package's arrays): the required ones
/// `required` in the order of [`GNSS_COLUMNS`] and those of [`GNSS_OPTIONAL`] that are given,
/// NaN where not measured (as an empty cell or `nan` in the file). Row `i` is the row on line
/// `i + 2` of the log written as CSV: the checks and the rows are [`read_gnss`]'s, so they
/// equal those of the log written as text with each number in its shortest round-trip form.
///
/// # Errors
/// As [`read_gnss`]: [`LogProblem::NotFinite`] for a NaN or infinity in a required column or an
/// infinity in an optional one, the ranges, time stamps that do not increase, no fix; and
/// [`LogProblem::Unreadable`] when a column's length differs from `t_s`'s.
pub fn held_gnss(
    name: &str,
    required: [&[f64]; 4],
    optional: [Option<&[f64]>; 9],
) -> Result<Vec<GnssRow>, LogError> {
    let n = required[0].len();
    let lengths = required.iter().zip(GNSS_COLUMNS).chain(
        optional
            .iter()
            .zip(GNSS_OPTIONAL)
            .filter_map(|(c, k)| Some((c.as_ref()?, k))),
    );
    for (c, column) in lengths {
        if c.len() != n {
            let message = format!(
                "{column} has {} values and t_s has {n}: expected one value per time stamp",
                c.len()
            );
            return Err(LogError::of_file(name, LogProblem::Unreadable { message }));
        }
    }
    let not_finite = |column: &'static str, x: f64| LogProblem::NotFinite {
        column,
        text: x.to_string(),
    };
    let mut rows: Vec<GnssRow> = Vec::with_capacity(n);
    for i in 0..n {
        let line = i as u64 + 2;
        let at = |problem| LogError::at(name, line, problem);
        let r = required.map(|c| c[i]);
        if let Some(k) = r.iter().position(|x| !x.is_finite()) {
            return Err(at(not_finite(GNSS_COLUMNS[k], r[k])));
        }
        check_required(&r).map_err(at)?;
        let mut o = [None; 9];
        for (k, c) in optional.iter().enumerate() {
            let Some(x) = c.map(|c| c[i]) else { continue };
            if x.is_infinite() {
                return Err(at(not_finite(GNSS_OPTIONAL[k], x)));
            }
            o[k] = (!x.is_nan()).then_some(x);
            check_optional(k, o[k]).map_err(at)?;
        }
        let row = row_of(line, r, o);
        push_increasing(&mut rows, row).map_err(at)?;
    }
    some_rows(rows, name)
}

/// `row` after the rows read so far, or the problem of a time stamp that does not increase.
fn push_increasing(rows: &mut Vec<GnssRow>, row: GnssRow) -> Result<(), LogProblem> {
    if let Some(p) = rows.last()
        && row.t_s <= p.t_s
    {
        return Err(LogProblem::NotIncreasing {
            t_s: row.t_s,
            previous_s: p.t_s,
        });
    }
    rows.push(row);
    Ok(())
}

/// The rows of the log `name`, or its error when it has none.
fn some_rows(rows: Vec<GnssRow>, name: &str) -> Result<Vec<GnssRow>, LogError> {
    if rows.is_empty() {
        let problem = LogProblem::TooFewRows {
            found: 0,
            needed: 1,
        };
        return Err(LogError::of_file(name, problem));
    }
    Ok(rows)
}
