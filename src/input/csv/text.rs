//! The text of a CSV log's rows: every number in the shortest form that parses back to the same
//! double (Rust's `{}` and `{:e}`, both shortest round-trip representations), so that a log
//! written with it reads back bit for bit through [`super::read`] (the logs' CSV rules are
//! `docs/guide/logs.md`'s).

use std::fmt::Write as _;

/// Appends `x` to `out` in the shortest form that parses back to the same double: plain decimals
/// (Rust's `{}`) between 10⁻⁵ and 10¹⁶, exponent form (`{:e}`) outside, where plain decimals
/// would run to hundreds of digits. Both are shortest round-trip representations.
///
/// # Examples
/// ```
/// let mut s = String::new();
/// for x in [0.1 + 0.2, -3.0, 1e-300, 0.005 * 3.0] {
///     accelcal::input::csv::text::push_number(&mut s, x);
///     s.push(' ');
/// }
/// assert_eq!(s, "0.30000000000000004 -3 1e-300 0.015 ");
/// ```
pub fn push_number(out: &mut String, x: f64) {
    let a = x.abs();
    // Writing into a String cannot fail.
    let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}

/// Appends one CSV row of `values` and a line end.
pub fn push_row(out: &mut String, values: &[f64]) {
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_number(out, x);
    }
    out.push('\n');
}

/// The header line of a log with `columns`.
pub fn header(columns: &[&str]) -> String {
    format!("{}\n", columns.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_bit_for_bit() {
        let mut s = String::new();
        let values = [
            0.0,
            -0.0,
            1.0 / 3.0,
            -2.5e-7,
            123456.789e10,
            f64::MIN_POSITIVE,
            f64::MAX,
            1e16 - 2.0,
            1e16,
        ];
        for x in values {
            s.clear();
            push_number(&mut s, x);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x} written as {s}");
            assert!(s.len() <= 24, "{s}");
        }
    }
}
