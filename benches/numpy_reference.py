#!/usr/bin/env python3
"""A numpy reference of accelcal's per-sample ensemble, vectorized over realizations.

Same model as the default configuration (200 Hz for 30 s, GPS at 5 Hz, analytic truth, point
samples): draw p(0), v(0), b; draw w at every accelerometer sample for every realization and
integrate eq. (3) (an interval's samples at once, as one matrix product); at every fix draw the GPS noise, run the filter with the precomputed gains,
and add the statistics the checks use (per fix: Σe, Σe·eᵀ, Σe·x̂ᵀ, Σx̂, Σx̂², NEES a priori and a
posteriori, NIS; and Σρ·ρᵀ over the stacked residuals of every pair of fixes).

Prints the median rate (realizations/s) over repeated runs, with min and max; the rate counts
the whole ensemble (schedule excluded, computed once).

    python3 benches/numpy_reference.py [--realizations N] [--batch B] [--repeats R]
"""

import argparse
import time

import numpy as np

A, OMEGA, DURATION = 10.0, 0.6283185307179586, 30.0
RATE_HZ, W, BIAS_VAR = 200.0, 4e-4, 0.01
GPS_HZ, SIG_P, SIG_V = 5.0, 1.0, 0.04
P0_MEAN, P0_SIG, V0_MEAN, V0_SIG = 0.0, 10.0, 100.0, 1.0

DT = 1.0 / RATE_HZ
STEPS = int(round(DURATION * RATE_HZ))
SPF = int(round(RATE_HZ / GPS_HZ))
FIX_STEPS = np.arange(SPF, STEPS + 1, SPF)
ACCEL = A * np.sin(OMEGA * np.arange(STEPS + 1) * DT)


def schedule():
    """Gains and inverse covariances at every fix (eq. 5 propagated per sample)."""
    phi = np.array([[1.0, DT, -0.5 * DT * DT], [0.0, 1.0, -DT], [0.0, 0.0, 1.0]])
    g = np.array([-0.5 * DT * DT, -DT, 0.0])
    q = np.outer(g, g) * W
    h = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    r = np.diag([SIG_P**2, SIG_V**2])
    p = np.diag([P0_SIG**2, V0_SIG**2, BIAS_VAR])
    out = []
    j = 0
    for jf in FIX_STEPS:
        for _ in range(jf - j):
            p = phi @ p @ phi.T + q
        j = jf
        tau = SPF * DT
        phi_fix = np.array([[1.0, tau, -0.5 * tau * tau], [0.0, 1.0, -tau], [0.0, 0.0, 1.0]])
        s = h @ p @ h.T + r
        k = p @ h.T @ np.linalg.inv(s)
        ikh = np.eye(3) - k @ h
        post = ikh @ p @ ikh.T + k @ r @ k.T
        out.append((phi_fix, k, np.linalg.inv(p), np.linalg.inv(post), np.linalg.inv(s)))
        p = post
    return out


def analytic(t, p0, v0):
    x = OMEGA * t
    return (p0 + v0 * t + (A / OMEGA) * t - (A / OMEGA**2) * np.sin(x),
            v0 + (A / OMEGA) * (1.0 - np.cos(x)))


def ensemble(n, sched, rng):
    fixes = len(FIX_STEPS)
    p0 = P0_MEAN + P0_SIG * rng.standard_normal(n)
    v0 = V0_MEAN + V0_SIG * rng.standard_normal(n)
    b = np.sqrt(BIAS_VAR) * rng.standard_normal(n)
    sw = np.sqrt(W)
    half = 0.5 * DT * DT
    pc = np.full(n, P0_MEAN)
    vc = np.full(n, V0_MEAN)
    est = np.zeros((3, n))
    resid = np.empty((n, 2 * fixes))
    sums = []
    j = 0
    for i, jf in enumerate(FIX_STEPS):
        # Every sample's output a_c = a + b + w, integrated by eq. (3) over the interval at once:
        # p_c gains v_c·τ + Σ_k a_c,k·(Δt²/2 + (n − 1 − k)·Δt²), v_c gains Σ_k a_c,k·Δt.
        steps = jf - j
        ac = rng.standard_normal((steps, n))
        ac *= sw
        ac += b
        ac += ACCEL[j:jf, None]
        coef_p = half + (steps - 1 - np.arange(steps)) * DT * DT
        pc += vc * (steps * DT) + coef_p @ ac
        vc += DT * ac.sum(0)
        j = jf
        tp, tv = analytic(jf * DT, p0, v0)
        dx = np.stack([tp - pc, tv - vc, b])
        z = np.stack([tp + SIG_P * rng.standard_normal(n), tv + SIG_V * rng.standard_normal(n)])
        dz = z - np.stack([pc, vc])
        phi, gain, p_prior_inv, p_post_inv, s_inv = sched[i]
        prior = phi @ est
        r = dz - prior[:2]
        post = prior + gain @ r
        est = post
        fix = []
        for x, pinv in ((prior, p_prior_inv), (post, p_post_inv)):
            e = dx - x
            fix.append((e.sum(1), e @ e.T, e @ x.T, x.sum(1), (x * x).sum(1),
                        ((pinv @ e) * e).sum()))
        fix.append(((s_inv @ r) * r).sum())
        sums.append(fix)
        resid[:, 2 * i] = r[0]
        resid[:, 2 * i + 1] = r[1]
    products = resid.T @ resid
    return sums, products


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--realizations", type=int, default=20000)
    ap.add_argument("--batch", type=int, default=10000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    sched = schedule()
    rng = np.random.default_rng(2017)
    rates = []
    for _ in range(args.repeats):
        t = time.perf_counter()
        done = 0
        while done < args.realizations:
            n = min(args.batch, args.realizations - done)
            ensemble(n, sched, rng)
            done += n
        rates.append(args.realizations / (time.perf_counter() - t))
    rates.sort()
    med = rates[len(rates) // 2] if len(rates) % 2 else 0.5 * (rates[len(rates) // 2 - 1] + rates[len(rates) // 2])
    print(f"numpy {np.__version__}, vectorized over realizations (batches of {args.batch})")
    print(f"numpy reference ensemble           median {med:9.0f} realizations/s "
          f"(min {rates[0]:.0f}, max {rates[-1]:.0f}; {args.repeats} runs of {args.realizations})")


if __name__ == "__main__":
    main()
