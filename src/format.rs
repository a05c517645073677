//! Numbers as people read them: significant digits, the true minus sign, thin-space thousands,
//! superscript powers of ten. The only way the figures, the report and the command line turn
//! numbers into text.

const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];

/// `n` in superscript digits: −3 → "⁻³".
pub fn superscript(n: i32) -> String {
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for d in n.unsigned_abs().to_string().bytes() {
        s.push(SUPERSCRIPTS[(d - b'0') as usize]);
    }
    s
}

/// 10^k with a superscript exponent: "1", "10", "10⁻³".
///
/// # Examples
/// ```
/// use accelcal::format::power_of_ten;
/// assert_eq!(power_of_ten(-12), "10⁻¹²");
/// assert_eq!(power_of_ten(0), "1");
/// ```
pub fn power_of_ten(k: i32) -> String {
    match k {
        0 => "1".to_string(),
        1 => "10".to_string(),
        _ => format!("10{}", superscript(k)),
    }
}

/// `x` with `sig` significant digits: plain between 10⁻³ and 10⁶, otherwise `m × 10ⁿ`.
/// Uses the true minus sign.
///
/// # Examples
/// ```
/// use accelcal::format::sig;
/// assert_eq!(sig(0.012345, 3), "0.0123");
/// assert_eq!(sig(-1234.6, 3), "−1235");
/// assert_eq!(sig(2.5e-5, 2), "2.5 × 10⁻⁵");
/// ```
pub fn sig(x: f64, sig: usize) -> String {
    if !x.is_finite() {
        return "—".to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let a = x.abs();
    let exp = a.log10().floor() as i32;
    let s = if (-3..6).contains(&exp) {
        let decimals = (sig as i32 - 1 - exp).max(0) as usize;
        format!("{a:.decimals$}")
    } else {
        let mant = a / 10f64.powi(exp);
        // Rounding can carry the mantissa to 10.
        let (mant, exp) = if format!("{mant:.*}", sig - 1).starts_with("10") {
            (mant / 10.0, exp + 1)
        } else {
            (mant, exp)
        };
        format!("{mant:.*} × 10{}", sig - 1, superscript(exp))
    };
    if x < 0.0 { format!("−{s}") } else { s }
}

/// `x` with a fixed number of decimals and the true minus sign; never "−0".
///
/// # Examples
/// ```
/// use accelcal::format::fixed;
/// assert_eq!(fixed(-0.0001, 2), "0.00");
/// assert_eq!(fixed(-1.5, 1), "−1.5");
/// ```
pub fn fixed(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return "—".to_string();
    }
    let s = format!("{:.decimals$}", x.abs());
    if x < 0.0 && s.bytes().any(|b| (b'1'..=b'9').contains(&b)) {
        format!("−{s}")
    } else {
        s
    }
}

/// `x` with up to 4 significant digits and no trailing zeros: 5 → "5", 0.6283185 → "0.6283".
pub fn short(x: f64) -> String {
    let s = sig(x, 4);
    if s.contains('×') || !s.contains('.') {
        return s;
    }
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// An estimate and its interval's ends, each with the significant digits that show the
/// interval's width: the fewest digits d ≥ `min_sig` (at most 17) at which the printed ends
/// differ from each other and each from the printed estimate, wherever they differ as numbers.
/// All three take the same d; rounding to d significant digits is monotone, so the printed ends
/// keep their order.
///
/// # Examples
/// ```
/// use accelcal::format::interval;
/// // 0.061389 ± 1.06 × 10⁻⁵ at 3 digits would read [0.0614, 0.0614].
/// let (v, lo, hi) = interval(0.0613890, 0.0613682, 0.0614098, 3);
/// assert_eq!((v.as_str(), lo.as_str(), hi.as_str()), ("0.06139", "0.06137", "0.06141"));
/// assert_eq!(interval(1.5, 1.0, 2.0, 3).1, "1.00");
/// ```
pub fn interval(value: f64, lower: f64, upper: f64, min_sig: usize) -> (String, String, String) {
    let d = interval_digits(value, lower, upper, min_sig);
    (sig(value, d), sig(lower, d), sig(upper, d))
}

/// The significant digits [`interval`] gives an estimate and its interval's ends: the fewest
/// d ≥ `min_sig` (within 1…17) at which pairs that differ as numbers differ as printed.
pub fn interval_digits(value: f64, lower: f64, upper: f64, min_sig: usize) -> usize {
    let min_sig = min_sig.clamp(1, 17);
    // Compared as numbers read back: a carry prints −0.97 at one digit as "−1.0", −1.2 as "−1".
    let apart = |d: usize| {
        let [v, l, u] = [value, lower, upper].map(|x| reading(&sig(x, d)));
        (lower == upper || l != u) && (lower == value || l != v) && (upper == value || u != v)
    };
    (min_sig..=17).find(|&d| apart(d)).unwrap_or(17)
}

/// The number [`sig`] printed, read back: the true minus sign, "m × 10ⁿ"; NaN for "—".
fn reading(text: &str) -> f64 {
    let text = text.replace('−', "-");
    let Some((mantissa, power)) = text.split_once(" × 10") else {
        return text.parse().unwrap_or(f64::NAN);
    };
    let exponent: String = power
        .chars()
        .map(|c| match SUPERSCRIPTS.iter().position(|&d| d == c) {
            Some(k) => char::from(b'0' + k as u8),
            None => '-',
        })
        .collect();
    format!("{mantissa}e{exponent}").parse().unwrap_or(f64::NAN)
}

/// A whole number with thin-space thousands separators: 10 000.
pub fn count(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push('\u{202F}');
        }
        out.push(c);
    }
    out
}

/// A probability as a percentage: 0.01 → "1 %".
pub fn percent(p: f64) -> String {
    let s = sig(100.0 * p, 3);
    // Only a fraction's trailing zeros go: 100 stays "100", not "1".
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    format!("{s}\u{202F}%")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(1.0, 3), "1.00");
        assert_eq!(sig(0.5, 2), "0.50");
        assert_eq!(sig(123.456, 4), "123.5");
        assert_eq!(sig(9.999e-7, 2), "1.0 × 10⁻⁶");
        assert_eq!(sig(-3.0e7, 2), "−3.0 × 10⁷");
        assert_eq!(sig(f64::NAN, 2), "—");
        assert_eq!(sig(0.0, 2), "0");
    }

    #[test]
    fn fixed_decimals_and_minus() {
        assert_eq!(fixed(-0.25, 1), "−0.2");
        assert_eq!(fixed(-0.0001, 2), "0.00");
        assert_eq!(fixed(1.23456, 2), "1.23");
    }

    #[test]
    fn short_drops_trailing_zeros() {
        assert_eq!(short(5.0), "5");
        assert_eq!(short(200.0), "200");
        assert_eq!(short(0.005), "0.005");
        assert_eq!(short(0.6283185307179586), "0.6283");
        assert_eq!(short(30.0), "30");
    }

    #[test]
    fn interval_ends_differ_from_each_other_and_from_the_estimate() {
        // The hour-long simulated log's bias: 0.0613890 ± 1.96 × 1.06 × 10⁻⁵.
        let (b, h) = (0.0613890, 1.96 * 1.06e-5);
        let (v, lo, hi) = interval(b, b - h, b + h, 3);
        assert_eq!(
            (v.as_str(), lo.as_str(), hi.as_str()),
            ("0.06139", "0.06137", "0.06141")
        );
        // Wide enough at 3 digits: nothing added.
        assert_eq!(
            interval(-0.56, -0.567, -0.554, 3),
            ("−0.560".into(), "−0.567".into(), "−0.554".into())
        );
        // An end equal to the estimate stays equal; the other still differs.
        assert_eq!(interval(1.0, 1.0, 1.0 + 1e-9, 3).2, "1.000000001");
        assert_eq!(
            interval(2.0, 2.0, 2.0, 3),
            ("2.00".into(), "2.00".into(), "2.00".into())
        );
        assert_eq!(interval(2.5e-5, 2.4e-5, 2.6e-5, 2).1, "2.4 × 10⁻⁵");
        // A carry at one digit prints −0.97 as "−1.0" and −1.2 as "−1": one number.
        assert_eq!(interval(-0.966, -1.215, 0.0, 1).1, "−1.2");
        assert_eq!(reading("−2.5 × 10⁻⁵"), -2.5e-5);
    }

    #[test]
    fn counts_and_percentages() {
        assert_eq!(count(10_000), "10\u{202F}000");
        assert_eq!(count(999), "999");
        assert_eq!(count(1_234_567), "1\u{202F}234\u{202F}567");
        assert_eq!(percent(0.01), "1\u{202F}%");
        assert_eq!(percent(0.05), "5\u{202F}%");
        assert_eq!(percent(1.0), "100\u{202F}%");
        assert_eq!(percent(0.1), "10\u{202F}%");
    }
}
