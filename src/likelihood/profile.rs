//! Profile-likelihood intervals: for one variable, the values at which the likelihood maximised
//! over the others falls by half the χ²₁ quantile from its maximum.

use super::search::{Maximum, Objective};

/// Accept an interval end when the deviance is this close to the quantile.
const DEVIANCE_TOLERANCE: f64 = 2e-3;
/// Profile evaluations per interval end at most.
const MAX_POINTS: usize = 40;

/// One point of a profile: the variable's value and the deviance −2·(ℓ_p − ℓ̂) there.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ProfilePoint {
    /// The variable (its logarithm).
    pub u: f64,
    /// −2·(ℓ_p(u) − ℓ̂), ≥ 0.
    pub deviance: f64,
}

/// One end of a profile-likelihood interval.
#[derive(Clone, Debug)]
pub struct End {
    /// Where the deviance reaches the quantile; `None` when it stays below it up to the search's
    /// bound (the data bound the variable on this side no more than the search does).
    pub at: Option<f64>,
    /// The profile's points evaluated on the way, in the order evaluated.
    pub points: Vec<ProfilePoint>,
    /// The evaluations of the likelihood it took.
    pub evaluations: u64,
}

/// The profile of variable `j` at `u_j` = `t`: the maximum over the other variables of
/// `free`, started on the ridge (du_o/du_j = `ridge`) through `warm`.
fn profile_at(
    objective: &Objective<'_>,
    (free, j, ridge): (&[usize], usize, &[f64]),
    t: f64,
    warm: &[f64],
) -> Maximum {
    let u: Vec<f64> = warm
        .iter()
        .zip(ridge)
        .map(|(w, r)| w + (t - warm[j]) * r)
        .collect();
    let others: Vec<usize> = free.iter().copied().filter(|&i| i != j).collect();
    if others.is_empty() {
        let value = objective.value(&u);
        return Maximum {
            u,
            value,
            hessian: Vec::new(),
        };
    }
    objective.climb(&u, &others)
}

/// The end of variable `j`'s interval on the side `side` (−1 below the maximum, +1 above) at
/// deviance `q`, from the maximum `best` over the variables `free`.
///
/// The first step is the Wald interval's from `best`'s curvature; then the deviance's square
/// root, linear in the variable for a quadratic profile, is interpolated between the last point
/// below the quantile and the first above it (bisection when that stalls), or extrapolated
/// (at most ×4) until the quantile is passed or the bound reached.
pub fn interval_end(
    f: &(dyn Fn(&[f64]) -> f64 + Sync),
    (lo, hi): (&[f64], &[f64]),
    best: &Maximum,
    free: &[usize],
    (j, side, q): (usize, f64, f64),
) -> End {
    let objective = Objective::new(f, lo.to_vec(), hi.to_vec());
    let u0 = best.u[j];
    let room = if side < 0.0 { u0 - lo[j] } else { hi[j] - u0 };
    let mut end = End {
        at: None,
        points: Vec::new(),
        evaluations: 0,
    };
    if room <= 0.0 {
        return end;
    }
    let mut delta = wald_half_width(best, free, j, q).min(room);
    let mut below = (0.0, 0.0_f64);
    let mut above: Option<(f64, f64)> = None;
    let ridge = ridge(best, free, j);
    let mut warm = best.u.clone();
    for _ in 0..MAX_POINTS {
        let t = u0 + side * delta;
        // The others start on the ridge of the quadratic model through the last point below.
        let m = profile_at(&objective, (free, j, &ridge), t, &warm);
        let deviance = (2.0 * (best.value - m.value)).max(0.0);
        end.points.push(ProfilePoint { u: t, deviance });
        if (deviance - q).abs() <= DEVIANCE_TOLERANCE {
            end.at = Some(t);
            break;
        }
        if deviance < q {
            below = (delta, deviance);
            warm = m.u;
            if delta >= room {
                break;
            }
        } else {
            above = Some((delta, deviance));
        }
        delta = next_delta(below, above, q, room);
    }
    if end.at.is_none() && above.is_some() {
        // Out of points: the closest bracketing point stands for the end.
        end.at = above.map(|(d, _)| u0 + side * d);
    }
    // A few more points for the profile's figure: inside the interval and just beyond its end
    // (towards the bound when the end is open), where the search left gaps.
    let span = end.at.map_or(room, |t| (t - u0).abs());
    for fraction in [0.4, 0.75, 1.3] {
        let d = fraction * span;
        let near = |p: &ProfilePoint| ((p.u - u0).abs() - d).abs() < 0.1 * span;
        if d > room || end.points.iter().any(near) {
            continue;
        }
        let t = u0 + side * d;
        let m = profile_at(&objective, (free, j, &ridge), t, &best.u);
        let deviance = (2.0 * (best.value - m.value)).max(0.0);
        end.points.push(ProfilePoint { u: t, deviance });
    }
    end.evaluations = objective.evaluations();
    end
}

/// How the other variables move with variable `j` along the ridge of the quadratic model at
/// `best`: du_o/du_j = −H_oo⁻¹·H_oj (1 for j itself, 0 where the Hessian says nothing).
fn ridge(best: &Maximum, free: &[usize], j: usize) -> Vec<f64> {
    let mut r = vec![0.0; best.u.len()];
    r[j] = 1.0;
    let others: Vec<usize> = free.iter().copied().filter(|&i| i != j).collect();
    if best.hessian.is_empty() || others.is_empty() {
        return r;
    }
    let m = others.len();
    let h = &best.hessian;
    let a = nalgebra::DMatrix::from_fn(m, m, |x, y| -h[others[x]][others[y]]);
    let b = nalgebra::DVector::from_fn(m, |x, _| h[others[x]][j]);
    if let Some(c) = a.cholesky() {
        let d = c.solve(&b);
        for (x, &i) in others.iter().enumerate() {
            if d[x].is_finite() {
                r[i] = d[x];
            }
        }
    }
    r
}

/// The Wald half-width √(q·(−H⁻¹)ⱼⱼ) over the variables `free`; 1 when the Hessian is not
/// negative definite there.
fn wald_half_width(best: &Maximum, free: &[usize], j: usize, q: f64) -> f64 {
    let m = free.len();
    let Some(r) = free.iter().position(|&i| i == j) else {
        return 1.0;
    };
    if best.hessian.is_empty() {
        return 1.0;
    }
    let a = nalgebra::DMatrix::from_fn(m, m, |a, b| -best.hessian[free[a]][free[b]]);
    match a.cholesky() {
        Some(c) => {
            let var = c.inverse()[(r, r)];
            if var.is_finite() && var > 0.0 {
                (q * var).sqrt()
            } else {
                1.0
            }
        }
        None => 1.0,
    }
}

/// The next distance from the maximum to try: √deviance interpolated to √q between the last
/// point below and the first above (kept inside the bracket's middle 80 %), or extrapolated
/// from the last point below (at most ×4, at least ×1.2, at most `room`).
fn next_delta(below: (f64, f64), above: Option<(f64, f64)>, q: f64, room: f64) -> f64 {
    let root = |(d, dev): (f64, f64)| (d, dev.max(0.0).sqrt());
    let (d0, s0) = root(below);
    let target = q.sqrt();
    match above {
        Some(a) => {
            let (d1, s1) = root(a);
            let t = if s1 > s0 {
                (target - s0) / (s1 - s0)
            } else {
                0.5
            };
            d0 + t.clamp(0.1, 0.9) * (d1 - d0)
        }
        None => {
            let factor = if s0 > 0.0 {
                (target / s0 * 1.02).clamp(1.2, 4.0)
            } else {
                4.0
            };
            (d0 * factor).min(room)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_profile_gives_the_wald_interval_and_an_open_end_at_a_bound() {
        // ℓ = −½ uᵀ A u with A = [[2, 1], [1, 1]]: the profile of u₀ is −½ u₀²/(A⁻¹)₀₀ =
        // −½ u₀² (A⁻¹ = [[1, −1], [−1, 2]]), so the 95 % ends are ±1.96 for u₀, ±1.96·√2 for u₁.
        let f = |u: &[f64]| -0.5 * (2.0 * u[0] * u[0] + 2.0 * u[0] * u[1] + u[1] * u[1]);
        let (lo, hi) = (vec![-10.0, -10.0], vec![10.0, 2.0]);
        let o = Objective::new(&f, lo.clone(), hi.clone());
        let best = o.maximize(&[1.0, 1.0], &[0, 1]);
        let q = 3.841_458_820_694_124;
        for (j, side, want) in [
            (0, -1.0, -1.96),
            (0, 1.0, 1.96),
            (1, -1.0, -1.96 * 2f64.sqrt()),
        ] {
            let e = interval_end(&f, (&lo, &hi), &best, &[0, 1], (j, side, q));
            let at = e.at.expect("a closed end");
            assert!((at - want).abs() < 2e-3, "{j} {side}: {at} against {want}");
            assert!(e.evaluations > 0 && !e.points.is_empty());
        }
        // u₁'s upper end 2.77 lies beyond the bound 2: open.
        let e = interval_end(&f, (&lo, &hi), &best, &[0, 1], (1, 1.0, q));
        assert_eq!(e.at, None);
        // A negative control: half the quantile's root (the wrong curvature) misses the end.
        let e = interval_end(&f, (&lo, &hi), &best, &[0, 1], (0, 1.0, q / 4.0));
        assert!((e.at.unwrap() - 1.96).abs() > 0.9);
    }
}
