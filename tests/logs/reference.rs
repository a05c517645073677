//! An independent processing of the logs, written here with plain arrays and the textbook
//! formulas: per-step Δt_j from the time stamps, Euler integration (eq. 3), Φ(Δt_j) and
//! Q(Δt_j) = W·g·gᵀ (with the bias's own φ(Δt_j) and q_b(Δt_j) when it drifts), the short-form
//! update P⁺ = P⁻ − K·S·Kᵀ with an explicit 2×2 inverse, and a
//! Rauch–Tung–Striebel smoother over every sample with explicit 3×3 inverses. It shares no code
//! with the library's filter.
// Matrix formulas read best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub use super::common::plain::M3;
use super::common::plain::{mul, transpose};
/// An accelerometer log: (t, a_c).
pub type AccelLog = Vec<(f64, f64)>;
/// A GPS log: (t, z_p, z_v).
pub type GpsLog = Vec<(f64, f64, f64)>;

/// How the filter's bias moves between samples.
#[derive(Clone, Copy, Debug)]
pub enum Drift {
    /// A constant bias: φ = 1, q_b = 0.
    None,
    /// A random walk with K (m/s² per √s): φ = 1, q_b = K²·Δt.
    RandomWalk(f64),
    /// Gauss–Markov with τ_b (s), stationary at the prior variance σ_b²: φ = e^(−Δt/τ_b),
    /// q_b = σ_b²·(1 − φ²).
    GaussMarkov(f64),
}

/// The filter's assumptions.
#[derive(Clone, Copy, Debug)]
pub struct Prior {
    pub p0_m: f64,
    pub v0_m_s: f64,
    pub sigma_p0_m: f64,
    pub sigma_v0_m_s: f64,
    pub bias_var: f64,
    pub accel_noise_var: f64,
    pub gps_p_sigma_m: f64,
    pub gps_v_sigma_m_s: f64,
    pub drift: Drift,
}

impl Prior {
    /// The default configuration's.
    pub fn default_config() -> Self {
        Prior {
            p0_m: 0.0,
            v0_m_s: 100.0,
            sigma_p0_m: 10.0,
            sigma_v0_m_s: 1.0,
            bias_var: 0.01,
            accel_noise_var: 0.0004,
            gps_p_sigma_m: 1.0,
            gps_v_sigma_m_s: 0.04,
            drift: Drift::None,
        }
    }
}

/// Filtered and smoothed estimates at every sample.
pub struct Processed {
    pub t: Vec<f64>,
    pub pc: Vec<f64>,
    pub x: Vec<[f64; 3]>,
    pub p: Vec<M3>,
    pub xs: Vec<[f64; 3]>,
    pub ps: Vec<M3>,
}

fn mul_v(a: &M3, v: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn add(a: &M3, b: &M3, sign: f64) -> M3 {
    let mut c = *a;
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] += sign * b[i][j];
        }
    }
    c
}

/// Inverse by cofactors.
fn inverse(a: &M3) -> M3 {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
    };
    let det = a[0][0] * c(0, 0) + a[0][1] * c(0, 1) + a[0][2] * c(0, 2);
    let mut inv = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            inv[j][i] = c(i, j) / det;
        }
    }
    inv
}

/// One time the filter stops at: a sample, or a fix between two samples.
struct Node {
    t: f64,
    /// The output integrated from here to the next node: this sample's, or the sample's before
    /// the fix.
    a: f64,
    fix: Option<(f64, f64)>,
    sample: bool,
    /// The step of the sample that starts or holds it, s (0 at the last sample).
    step: f64,
}

/// The samples of `accel` and the fixes of `gps` in time order: a fix at a sample's time stamp
/// (or before the first sample, or after the last) is applied at that sample, any other between
/// its two samples at its own time.
fn nodes(accel: &[(f64, f64)], gps: &[(f64, f64, f64)]) -> Vec<Node> {
    let n = accel.len();
    let mut out = Vec::with_capacity(n + gps.len());
    let mut fixes = gps.iter().peekable();
    for k in 0..n {
        let (t, a) = accel[k];
        let end = accel.get(k + 1).map_or(f64::INFINITY, |s| s.0);
        let step = accel.get(k + 1).map_or(0.0, |s| s.0 - t);
        let mut sample = Node {
            t,
            a,
            fix: None,
            sample: true,
            step,
        };
        let mut within = Vec::new();
        while let Some(&&(tf, zp, zv)) = fixes.peek() {
            if tf >= end {
                break;
            }
            if tf <= t || k + 1 == n {
                sample.fix = Some((zp, zv));
            } else {
                within.push(Node {
                    t: tf,
                    a,
                    fix: Some((zp, zv)),
                    sample: false,
                    step,
                });
            }
            fixes.next();
        }
        out.push(sample);
        out.extend(within);
    }
    out
}

/// Processes an accelerometer log `(t, a_c)` and a GPS log `(t, z_p, z_v)`; each fix is applied
/// at its own time (at the sample whose time stamp it has, or between two samples, the step cut
/// there), the smoother running over samples and fixes alike.
pub fn process(accel: &[(f64, f64)], gps: &[(f64, f64, f64)], prior: &Prior) -> Processed {
    let nodes = nodes(accel, gps);
    let n = nodes.len();
    let (rp, rv) = (prior.gps_p_sigma_m.powi(2), prior.gps_v_sigma_m_s.powi(2));
    let mut x = [0.0; 3];
    let mut p = [
        [prior.sigma_p0_m.powi(2), 0.0, 0.0],
        [0.0, prior.sigma_v0_m_s.powi(2), 0.0],
        [0.0, 0.0, prior.bias_var],
    ];
    let (mut pc, mut vc) = (prior.p0_m, prior.v0_m_s);
    let mut all = Processed {
        t: Vec::with_capacity(n),
        pc: Vec::with_capacity(n),
        x: Vec::with_capacity(n),
        p: Vec::with_capacity(n),
        xs: vec![],
        ps: vec![],
    };
    // Per step: the a priori estimate at the next node and the transition, for the smoother.
    let mut x_prior_next = Vec::with_capacity(n);
    let mut p_prior_next = Vec::with_capacity(n);
    let mut f_step = Vec::with_capacity(n);
    for k in 0..n {
        if let Some((zp, zv)) = nodes[k].fix {
            update(&mut x, &mut p, [zp - pc, zv - vc], [rp, rv]);
        }
        all.t.push(nodes[k].t);
        all.pc.push(pc);
        all.x.push(x);
        all.p.push(p);
        if k + 1 < n {
            let dt = nodes[k + 1].t - nodes[k].t;
            let a = nodes[k].a;
            pc += vc * dt + a * dt * dt / 2.0;
            vc += a * dt;
            let (phi, q_b) = match prior.drift {
                Drift::None => (1.0, 0.0),
                Drift::RandomWalk(k) => (1.0, k * k * dt),
                Drift::GaussMarkov(tau_b) => {
                    let phi = (-dt / tau_b).exp();
                    (phi, prior.bias_var * (1.0 - phi * phi))
                }
            };
            let f = [[1.0, dt, -dt * dt / 2.0], [0.0, 1.0, -dt], [0.0, 0.0, phi]];
            x = mul_v(&f, &x);
            p = mul(&mul(&f, &p), &transpose(&f));
            let q = white_noise(&nodes[k], &nodes[k + 1], dt);
            for i in 0..2 {
                for j in 0..2 {
                    p[i][j] += prior.accel_noise_var * q[i][j];
                }
            }
            p[2][2] += q_b;
            x_prior_next.push(x);
            p_prior_next.push(p);
            f_step.push(f);
        }
    }
    smooth(&mut all, &f_step, &x_prior_next, &p_prior_next);
    samples_only(all, &nodes)
}

/// The rows of the samples of `all`, whose rows are `nodes`.
fn samples_only(all: Processed, nodes: &[Node]) -> Processed {
    let keep = |v: Vec<[f64; 3]>| -> Vec<[f64; 3]> {
        v.into_iter()
            .zip(nodes)
            .filter(|(_, node)| node.sample)
            .map(|(x, _)| x)
            .collect()
    };
    Processed {
        t: keep_f(&all.t, nodes),
        pc: keep_f(&all.pc, nodes),
        x: keep(all.x),
        p: keep_m(all.p, nodes),
        xs: keep(all.xs),
        ps: keep_m(all.ps, nodes),
    }
}

/// The white noise's (δp, δv) covariance per unit of W over `dt` from node `a` to node `b`: a
/// whole step holds the sample's noise; a piece of a step cut by a fix takes it as white within
/// the step, of density W·Δt_j.
fn white_noise(a: &Node, b: &Node, dt: f64) -> [[f64; 2]; 2] {
    if a.sample && b.sample {
        let g = [-dt * dt / 2.0, -dt];
        [[g[0] * g[0], g[0] * g[1]], [g[1] * g[0], g[1] * g[1]]]
    } else {
        let h = a.step;
        [
            [h * dt.powi(3) / 3.0, h * dt * dt / 2.0],
            [h * dt * dt / 2.0, h * dt],
        ]
    }
}

fn keep_f(v: &[f64], nodes: &[Node]) -> Vec<f64> {
    v.iter()
        .zip(nodes)
        .filter(|(_, n)| n.sample)
        .map(|(x, _)| *x)
        .collect()
}

fn keep_m(v: Vec<M3>, nodes: &[Node]) -> Vec<M3> {
    v.into_iter()
        .zip(nodes)
        .filter(|(_, n)| n.sample)
        .map(|(x, _)| x)
        .collect()
}

/// The update of the estimate `x` and its covariance `p` by the fix whose difference from the
/// integration is `dz` = (z_p − p_c, z_v − v_c), with the GPS variances `r`.
fn update(x: &mut [f64; 3], p: &mut M3, dz: [f64; 2], [rp, rv]: [f64; 2]) {
    // S = H P Hᵀ + R, H = [I₂ 0].
    let s = [[p[0][0] + rp, p[0][1]], [p[1][0], p[1][1] + rv]];
    let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let si = [
        [s[1][1] / det, -s[0][1] / det],
        [-s[1][0] / det, s[0][0] / det],
    ];
    // K = P Hᵀ S⁻¹ (3×2).
    let k_gain: [[f64; 2]; 3] = [0, 1, 2].map(|i| {
        [
            p[i][0] * si[0][0] + p[i][1] * si[1][0],
            p[i][0] * si[0][1] + p[i][1] * si[1][1],
        ]
    });
    let r = [dz[0] - x[0], dz[1] - x[1]];
    for i in 0..3 {
        x[i] += k_gain[i][0] * r[0] + k_gain[i][1] * r[1];
    }
    // P⁺ = P⁻ − K S Kᵀ.
    let mut p_new = *p;
    for i in 0..3 {
        for j in 0..3 {
            let mut ksk = 0.0;
            for a in 0..2 {
                for b in 0..2 {
                    ksk += k_gain[i][a] * s[a][b] * k_gain[j][b];
                }
            }
            p_new[i][j] -= ksk;
        }
    }
    *p = p_new;
}

/// Rauch–Tung–Striebel over every sample: fills `out.xs` and `out.ps` from the filtered
/// estimates, the transitions `f_step` and the a priori estimates at the next sample.
fn smooth(out: &mut Processed, f_step: &[M3], x_prior_next: &[[f64; 3]], p_prior_next: &[M3]) {
    let n = out.x.len();
    out.xs = out.x.clone();
    out.ps = out.p.clone();
    for k in (0..n.saturating_sub(1)).rev() {
        let c = mul(
            &mul(&out.p[k], &transpose(&f_step[k])),
            &inverse(&p_prior_next[k]),
        );
        let dx = [0, 1, 2].map(|i| out.xs[k + 1][i] - x_prior_next[k][i]);
        let corr = mul_v(&c, &dx);
        out.xs[k] = [0, 1, 2].map(|i| out.x[k][i] + corr[i]);
        let dp = add(&out.ps[k + 1], &p_prior_next[k], -1.0);
        out.ps[k] = add(&out.p[k], &mul(&mul(&c, &dp), &transpose(&c)), 1.0);
    }
}
