//! Property tests of `format::interval`: the ends of an interval, as printed, parse back in
//! order and differ from each other and from the estimate whenever they differ as numbers.

use accelcal::format::{interval, sig};
use proptest::prelude::*;

/// A number as `format::sig` prints it, read back: the true minus sign and "m × 10ⁿ".
fn parse(s: &str) -> f64 {
    let s = s.replace('−', "-");
    let Some((mantissa, power)) = s.split_once(" × 10") else {
        return s.parse().expect("a plain number");
    };
    let digits: String = power
        .chars()
        .map(|c| match c {
            '⁻' => '-',
            c => {
                let k = "⁰¹²³⁴⁵⁶⁷⁸⁹"
                    .chars()
                    .position(|d| d == c)
                    .expect("a superscript");
                char::from(b'0' + k as u8)
            }
        })
        .collect();
    format!("{mantissa}e{digits}").parse().expect("m × 10ⁿ")
}

/// (value, lower, upper) with lower < value < upper: any sign and magnitude, relative
/// half-widths from 10⁻¹⁴ to 10, each side its own.
fn triple() -> impl Strategy<Value = (f64, f64, f64)> {
    (-1.0f64..1.0, -12i32..12, -14.0f64..1.0, -14.0f64..1.0).prop_map(|(m, e, a, b)| {
        let v = m * 10f64.powi(e);
        let scale = v.abs().max(1e-300);
        (v, v - scale * 10f64.powf(a), v + scale * 10f64.powf(b))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn printed_ends_parse_back_in_order_and_differ((v, lo, hi) in triple(), min_sig in 1usize..6) {
        prop_assume!(lo < v && v < hi);
        let (vs, ls, hs) = interval(v, lo, hi, min_sig);
        let (vp, lp, hp) = (parse(&vs), parse(&ls), parse(&hs));
        prop_assert!(lp < vp && vp < hp, "{v} [{lo}, {hi}] printed {vs} [{ls}, {hs}]");
    }
}

/// The negative control: at three significant digits the simulated hour-long log's interval
/// prints one number for both ends, so the property above fails for `sig` alone.
#[test]
fn three_digits_alone_print_a_narrow_interval_as_one_number() {
    let (v, h) = (0.0613890, 1.96 * 1.06e-5);
    assert_eq!(sig(v - h, 3), sig(v + h, 3));
    let (_, lo, hi) = interval(v, v - h, v + h, 3);
    assert!(parse(&lo) < parse(&hi), "[{lo}, {hi}]");
}
