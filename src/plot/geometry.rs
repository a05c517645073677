//! Data handling that keeps non-finite and off-scale values away from plotters: clipping lines at
//! the axes, thinning long runs to what the pixels can show, and fitting data ranges.

use std::ops::Range;

/// A data point (x, y).
pub(crate) type Point = (f64, f64);

/// Splits `points` at non-finite values and clips every segment to the rectangle `xr` × `yr`
/// (Liang–Barsky), returning the visible runs.
pub(super) fn clip_polyline(points: &[Point], xr: &Range<f64>, yr: &Range<f64>) -> Vec<Vec<Point>> {
    let finite = |p: &Point| p.0.is_finite() && p.1.is_finite();
    let mut runs: Vec<Vec<Point>> = Vec::new();
    let mut open = false;
    for w in points.windows(2) {
        let (p, q) = (w[0], w[1]);
        if !(finite(&p) && finite(&q)) {
            open = false;
            continue;
        }
        match clip_segment(p, q, xr, yr) {
            Some((a, b, t0, t1)) => {
                if open && t0 == 0.0 {
                    runs.last_mut().expect("an open run").push(b);
                } else {
                    runs.push(vec![a, b]);
                }
                open = t1 == 1.0;
            }
            None => open = false,
        }
    }
    if runs.is_empty() && points.len() == 1 && finite(&points[0]) {
        let p = points[0];
        if p.0 >= xr.start && p.0 <= xr.end && p.1 >= yr.start && p.1 <= yr.end {
            runs.push(vec![p, p]);
        }
    }
    runs
}

/// The part of segment p→q inside the rectangle, with its parameters t0 ≤ t1 along p→q.
fn clip_segment(
    p: Point,
    q: Point,
    xr: &Range<f64>,
    yr: &Range<f64>,
) -> Option<(Point, Point, f64, f64)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    for (den, num) in [
        (-dx, p.0 - xr.start),
        (dx, xr.end - p.0),
        (-dy, p.1 - yr.start),
        (dy, yr.end - p.1),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| (p.0 + t * dx, p.1 + t * dy);
    Some((
        if t0 == 0.0 { p } else { at(t0) },
        if t1 == 1.0 { q } else { at(t1) },
        t0,
        t1,
    ))
}

/// Thins a run ordered in x, drawn `columns` pixels wide, to what the pixels can show: one point
/// per pixel column (`column(x)`) where the run is monotone across it, and its extremes where it
/// turns inside it (noise, or a sawtooth's drop). Coordinates are whole pixels in the SVG, so the
/// dropped points would only have drawn a staircase of vertical steps.
pub(super) fn thin(run: &[Point], columns: usize, column: impl Fn(f64) -> i64) -> Vec<Point> {
    if run.len() <= columns {
        return run.to_vec();
    }
    let mut out = Vec::with_capacity(4 * columns + 4);
    let mut start = 0;
    while start < run.len() {
        let c = column(run[start].0);
        let mut end = start + 1;
        while end < run.len() && column(run[end].0) == c {
            end += 1;
        }
        let bucket = &run[start..end];
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in bucket.iter().enumerate() {
            if p.1 < bucket[lo].1 {
                lo = i;
            }
            if p.1 > bucket[hi].1 {
                hi = i;
            }
        }
        let last = bucket.len() - 1;
        let monotone = (lo == 0 && hi == last) || (hi == 0 && lo == last);
        if monotone {
            out.push(bucket[0]);
        } else {
            let mut keep = [0, lo, hi, last];
            keep.sort_unstable();
            let mut previous = usize::MAX;
            for k in keep {
                if k != previous {
                    out.push(bucket[k]);
                    previous = k;
                }
            }
        }
        start = end;
    }
    if out.last() != run.last() {
        out.extend(run.last());
    }
    out
}

/// The smallest and largest finite values, if any.
pub(crate) fn extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// The largest finite |value|, or 0.
pub(crate) fn max_abs(values: impl IntoIterator<Item = f64>) -> f64 {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(0.0, |m, v| m.max(v.abs()))
}

/// `[lo, hi]` widened by `frac` of its span on both sides.
pub(crate) fn padded((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    let pad = (hi - lo) * frac;
    (lo - pad, hi + pad)
}

/// Where a run of `[t0, t1]` has left the prior behind: after its first second, or its first
/// quarter if shorter. Axes fitted to the data from here on are not set by the prior's σ
/// (10 m, 1 m/s, 0.1 m/s²), which the first GPS fixes collapse.
pub(crate) fn settled_from(t0: f64, t1: f64) -> f64 {
    t0 + (1.0f64).min(0.25 * (t1 - t0))
}

/// Where a series stops running off its axis: the abscissa of the first point back inside after
/// the last point outside (`inside` false for a finite ordinate), or of that last point when none
/// follows. None when no finite point is outside. Points are in x order.
pub(crate) fn clipped_until(
    points: impl IntoIterator<Item = Point>,
    inside: impl Fn(f64) -> bool,
) -> Option<f64> {
    let mut until = None;
    let mut open = false;
    for (x, y) in points {
        if !(x.is_finite() && y.is_finite()) {
            continue;
        }
        if !inside(y) {
            until = Some(x);
            open = true;
        } else if open {
            until = Some(x);
            open = false;
        }
    }
    until
}

/// "before 1.6 s": the time `t` rounded up to a tenth of a second, for a title saying what is
/// clipped.
pub(crate) fn before(t: f64) -> String {
    format!(
        "before {} s",
        crate::format::fixed((t * 10.0).ceil() / 10.0, 1)
    )
}

/// The first and last finite abscissa of `values`, or `[0, 1]`.
pub(crate) fn time_span(times: impl IntoIterator<Item = f64>) -> (f64, f64) {
    extent(times).unwrap_or((0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_breaks_lines_at_gaps_and_edges() {
        let pts = [
            (0.0, 0.0),
            (1.0, 2.0),
            (2.0, 0.0),
            (3.0, f64::NAN),
            (4.0, 0.5),
            (5.0, 0.5),
        ];
        let runs = clip_polyline(&pts, &(0.0..5.0), &(-1.0..1.0));
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[0], vec![(0.0, 0.0), (0.5, 1.0)]);
        assert_eq!(runs[1], vec![(1.5, 1.0), (2.0, 0.0)]);
        assert_eq!(runs[2], vec![(4.0, 0.5), (5.0, 0.5)]);
    }

    #[test]
    fn clipping_ends_where_the_series_comes_back() {
        let inside = |y: f64| y.abs() <= 1.0;
        let pts = [
            (0.0, 5.0),
            (0.1, -3.0),
            (0.2, 0.5),
            (0.3, 2.0),
            (0.4, 0.0),
            (0.5, 0.1),
        ];
        assert_eq!(clipped_until(pts, inside), Some(0.4));
        assert_eq!(clipped_until([(0.0, 0.0), (1.0, f64::NAN)], inside), None);
        assert_eq!(clipped_until([(0.0, 0.0), (1.0, 9.0)], inside), Some(1.0));
        assert_eq!(before(1.51), "before 1.6 s");
    }

    #[test]
    fn thinning_keeps_the_extremes_of_each_column() {
        let run: Vec<Point> = (0..1000)
            .map(|i| (i as f64 / 1000.0, if i == 501 { 9.0 } else { 0.0 }))
            .collect();
        let thin = thin(&run, 10, |x| (x * 10.0).floor() as i64);
        assert!(thin.len() <= 40);
        assert!(thin.contains(&(0.501, 9.0)));
        assert!(thin.windows(2).all(|w| w[0].0 <= w[1].0));
    }
}
