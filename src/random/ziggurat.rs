//! The standard normal numbers' ziggurat (Marsaglia and Tsang, 2000) with 1024 layers: its
//! tables, solved for at first use, and its two paths.

use std::sync::LazyLock;

use super::Core;

/// Layers of the ziggurat: 1024, so that only about 0.3 % of the draws leave the fast path.
const LAYERS: usize = 1024;

/// The ziggurat tables: layer edges x_i (x_0 = V/f(R) the base's equivalent width, x_1 = R, …,
/// x_LAYERS = 0) and f(x_i) = exp(−x_i²/2); R is the base layer's right edge.
pub(super) struct Ziggurat {
    x: [f64; LAYERS + 1],
    f: [f64; LAYERS + 1],
    r: f64,
}

fn pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

/// The edges of a ziggurat of `layers` layers whose base layer ends at `r`: every layer has the
/// base's area V = r·f(r) + ∫_r^∞ f; returns the edges and how far the top layer's upper edge
/// f(x_{layers−1}) + V/x_{layers−1} overshoots f(0) = 1 (positive: r is too small).
fn edges(layers: usize, r: f64) -> (Vec<f64>, f64) {
    let tail = (std::f64::consts::PI / 2.0).sqrt() * statrs::function::erf::erfc(r / 2f64.sqrt());
    let v = r * pdf(r) + tail;
    let mut x = vec![0.0; layers + 1];
    x[0] = v / pdf(r);
    x[1] = r;
    for i in 2..layers {
        // x_{i−1}·(f(x_i) − f(x_{i−1})) = V, solved for the next edge.
        let top = v / x[i - 1] + pdf(x[i - 1]);
        if top >= 1.0 {
            return (x, top - 1.0 + (layers - i) as f64);
        }
        x[i] = (-2.0 * top.ln()).sqrt();
    }
    let last = v / x[layers - 1] + pdf(x[layers - 1]) - 1.0;
    (x, last)
}

/// The base edge R of a ziggurat of `layers` layers, by bisection.
fn base_edge(layers: usize) -> f64 {
    let (mut lo, mut hi) = (1.0, 6.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if edges(layers, mid).1 > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

static ZIGGURAT: LazyLock<Ziggurat> = LazyLock::new(|| {
    let r = base_edge(LAYERS);
    let (edges, _) = edges(LAYERS, r);
    let x: [f64; LAYERS + 1] = std::array::from_fn(|i| if i == LAYERS { 0.0 } else { edges[i] });
    let f = std::array::from_fn(|i| pdf(x[i]));
    Ziggurat { x, f, r }
});

#[inline]
pub(super) fn ziggurat() -> &'static Ziggurat {
    &ZIGGURAT
}

impl Ziggurat {
    /// The fast path: layer i from the low 10 bits, u ∈ [−1, 1) from the top 52; accepted when
    /// |u·x_i| < x_{i+1} (the point lies inside the layer's inner rectangle).
    #[inline(always)]
    pub(super) fn fast(&self, bits: u64) -> (f64, bool) {
        let i = (bits as usize) & (LAYERS - 1);
        let u = f64::from_bits((bits >> 12) | 0x4000_0000_0000_0000) - 3.0;
        let x = u * self.x[i];
        (x, x.abs() < self.x[i + 1])
    }

    /// The rest of a draw whose first bits `bits` (giving `x`) fell outside the fast path: the
    /// tail beyond R for the base layer, else the wedge test; a rejected point starts over.
    #[cold]
    #[inline(never)]
    pub(super) fn slow(&self, mut bits: u64, mut x: f64, rng: &mut Core) -> f64 {
        loop {
            let i = (bits as usize) & (LAYERS - 1);
            if i == 0 {
                // Marsaglia's tail: x = −ln(U₁)/R until −2·ln(U₂) ≥ x².
                let negative = x < 0.0;
                loop {
                    let t = -rng.open_closed01().ln() / self.r;
                    let y = -rng.open_closed01().ln();
                    if 2.0 * y >= t * t {
                        let v = self.r + t;
                        return if negative { -v } else { v };
                    }
                }
            }
            let f_hi = self.f[i + 1];
            if f_hi + (self.f[i] - f_hi) * rng.closed_open01() < pdf(x) {
                return x;
            }
            bits = rng.next_u64();
            let (next, ok) = self.fast(bits);
            if ok {
                return next;
            }
            x = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ziggurat_tables_close_at_the_top() {
        // The solver reproduces Marsaglia and Tsang's published 256-layer table: R and x_255.
        let r = base_edge(256);
        assert!((r - 3.654_152_885_361_009).abs() < 1e-10, "R = {r}");
        assert!((edges(256, r).0[255] - 0.215_241_895_984_875).abs() < 1e-9);
        let z = ziggurat();
        assert!(z.x.windows(2).skip(1).all(|w| w[0] > w[1]));
        // The top layer closes at f(0) = 1.
        assert!(edges(LAYERS, z.r).1.abs() < 1e-9);
    }
}
