//! The passes of the noise identification over a series read piece by piece: a series (its
//! block means, [`Series`]), the line removed ([`Line`]), the lag-1 autocorrelation of the
//! series differenced d times ([`lag1_of`]), each in four lanes that are whole vector
//! operations.

/// A series the identification reads piece by piece: `fill(start, out)` writes u_start …
/// u_{start+out.len()−1}.
pub(super) trait Series {
    fn fill(&self, start: usize, out: &mut [f64]);
}

/// The series itself.
pub(super) struct Held<'a>(pub &'a [f64]);

impl Series for Held<'_> {
    #[inline(always)]
    fn fill(&self, start: usize, out: &mut [f64]) {
        out.copy_from_slice(&self.0[start..start + out.len()]);
    }
}

/// Block means (p_{k+1} − p_k)·scale from consecutive phase points p.
pub(super) struct Consecutive<'a> {
    pub points: &'a [f64],
    pub scale: f64,
}

impl Series for Consecutive<'_> {
    #[inline(always)]
    fn fill(&self, start: usize, out: &mut [f64]) {
        for (o, w) in out.iter_mut().zip(self.points[start..].windows(2)) {
            *o = (w[1] - w[0]) * self.scale;
        }
    }
}

/// Block means (x_{(k+1)m} − x_{km})·scale from the phase x.
pub(super) struct Strided<'a> {
    pub x: &'a [f64],
    pub m: usize,
    pub scale: f64,
}

impl Series for Strided<'_> {
    #[inline(always)]
    fn fill(&self, start: usize, out: &mut [f64]) {
        let mut points = self.x[start * self.m..].iter().step_by(self.m);
        let mut before = *points.next().expect("the block means are within the phase");
        for (o, &after) in out.iter_mut().zip(points) {
            *o = (after - before) * self.scale;
            before = after;
        }
    }
}

/// Terms of a series taken at once (a multiple of 4): the passes run piece by piece over
/// buffers of this length, so that their four lanes are whole vector operations.
pub(super) const PIECE: usize = 256;

/// 0, 1, …, PIECE + 1 as floats: the index within a piece (exact).
pub(super) const IOTA: [f64; PIECE + 2] = {
    let mut a = [0.0; PIECE + 2];
    let mut i = 0;
    while i < PIECE + 2 {
        a[i] = i as f64;
        i += 1;
    }
    a
};

/// The line-removed series z_i = u_i − ū − slope·(i − ī) of the series u given by `fill`.
pub(super) struct Line<F> {
    pub fill: F,
    pub u_mean: f64,
    pub slope: f64,
    pub t_mean: f64,
}

impl<F: Series> Line<F> {
    /// z_start … z_{start+n−1} into `out` (n = its length ≤ PIECE + 2), through `u`.
    #[inline(always)]
    fn z(&self, start: usize, u: &mut [f64; PIECE + 2], out: &mut [f64]) {
        let n = out.len();
        self.fill.fill(start, &mut u[..n]);
        let t0 = start as f64;
        for ((o, &u), &j) in out.iter_mut().zip(&u[..n]).zip(&IOTA[..n]) {
            *o = u - self.u_mean - self.slope * ((t0 + j) - self.t_mean);
        }
    }

    /// The series differenced `d` times (d ≤ 2), w_start … w_{start+n−1} into `w[1..=n]`.
    #[inline(always)]
    fn w(&self, d: usize, start: usize, n: usize, bufs: &mut Buffers) {
        let Buffers { u, z, w } = bufs;
        if d == 0 {
            return self.z(start, u, &mut w[1..=n]);
        }
        self.z(start, u, &mut z[..n + d]);
        let w = &mut w[1..=n];
        match d {
            1 => {
                for (o, p) in w.iter_mut().zip(z[..n + 1].windows(2)) {
                    *o = p[1] - p[0];
                }
            }
            _ => {
                for (o, p) in w.iter_mut().zip(z[..n + 2].windows(3)) {
                    *o = p[2] - 2.0 * p[1] + p[0];
                }
            }
        }
    }
}

/// The buffers of one pass: the series u, the line removed z, the differences w (after the
/// term before them).
struct Buffers {
    u: [f64; PIECE + 2],
    z: [f64; PIECE + 2],
    w: [f64; PIECE + 1],
}

/// r₁ of the series w_0 … w_{L−1}, the line-removed series differenced `d` times, L =
/// `len` ≥ 2, in one pass.
///
/// # Formula
/// Riley & Greenhall (2004), eq. (2), with the sums Σw, Σw², Σ w_i w_{i+1} of one pass:
/// Σ_{i<L−1} (w_i − w̄)(w_{i+1} − w̄) = Σ w_i w_{i+1} − w̄ (2Σw − w_0 − w_{L−1}) + (L − 1) w̄²
/// and Σ (w_i − w̄)² = Σw² − w̄ Σw. Every series identified has a mean near zero (a line
/// removed, or differences of one), so the expansion loses nothing to cancellation.
#[inline(always)]
pub(super) fn lag1_of<F: Series>(len: usize, d: usize, line: &Line<F>) -> f64 {
    let mut bufs = Buffers {
        u: [0.0; PIECE + 2],
        z: [0.0; PIECE + 2],
        w: [0.0; PIECE + 1],
    };
    line.w(d, 0, 1, &mut bufs);
    let first = bufs.w[1];
    // Four running sums of each kind (the additions of one do not wait on the other three):
    // w_i in lane (i − 1) mod 4 for the whole groups of four after w_0, the rest in lane 0.
    let (mut sum, mut squares, mut lagged) = (
        [first, 0.0, 0.0, 0.0],
        [first * first, 0.0, 0.0, 0.0],
        [0.0; 4],
    );
    let mut previous = first;
    let grouped = 1 + (len - 1) / 4 * 4;
    let mut start = 1;
    while start < len {
        let in_groups = start < grouped;
        let n = if in_groups {
            PIECE.min(grouped - start)
        } else {
            len - start
        };
        line.w(d, start, n, &mut bufs);
        bufs.w[0] = previous;
        let w = &bufs.w[..=n];
        if in_groups {
            for q in 0..n / 4 {
                let b: &[f64; 5] = w[4 * q..4 * q + 5].try_into().expect("five terms");
                for j in 0..4 {
                    sum[j] += b[j + 1];
                    squares[j] += b[j + 1] * b[j + 1];
                    lagged[j] += b[j] * b[j + 1];
                }
            }
        } else {
            for &v in &w[1..] {
                sum[0] += v;
                squares[0] += v * v;
                lagged[0] += previous * v;
                previous = v;
            }
        }
        previous = w[n];
        start += n;
    }
    let total = |a: [f64; 4]| (a[0] + a[1]) + (a[2] + a[3]);
    let (sum, squares, lagged) = (total(sum), total(squares), total(lagged));
    let l = len as f64;
    let mean = sum / l;
    let num = lagged - mean * (2.0 * sum - first - previous) + (l - 1.0) * mean * mean;
    num / (squares - mean * sum)
}
