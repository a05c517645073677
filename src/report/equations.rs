//! Every equation and symbol of the report, as LaTeX, converted once to MathML.
//! Templates refer to them by name: `{{ eq.error_dynamics|safe }}`.

use super::math::Math;

macro_rules! equations {
    ($($name:ident: $mode:ident => $tex:expr,)*) => {
        /// The report's equations as MathML, one field per equation or inline symbol.
        pub struct Equations {
            $(
                #[allow(missing_docs)]
                pub $name: String,
            )*
        }

        impl Equations {
            /// Converts every equation with `math`.
            pub fn render(math: &Math) -> Self {
                Self { $($name: math.$mode($tex),)* }
            }

            /// The LaTeX source of every equation, by name (for tests).
            pub fn sources() -> Vec<(&'static str, &'static str)> {
                vec![$((stringify!($name), $tex),)*]
            }
        }
    };
}

equations! {
    // Inline symbols.
    dx: inline => r"\dx",
    dxhat: inline => r"\dxhat",
    dp: inline => r"\delta p",
    dv: inline => r"\delta v",
    b: inline => r"b",
    dt: inline => r"\Delta t",
    ti: inline => r"t_i",
    tj: inline => r"t_j",
    tm_lt_ti: inline => r"t_m < t_i",
    omega: inline => r"\omega",
    w: inline => r"w",
    big_w: inline => r"W",
    eta: inline => r"\eta",
    q_b_step: inline => r"q_b = K^2 \cdot \Delta t",
    p_c: inline => r"p_c",
    v_c: inline => r"v_c",
    p_prior: inline => r"P(t_i^-)",
    p_post: inline => r"P(t_i^+)",
    n_real: inline => r"N",
    alpha: inline => r"\alpha",
    alpha_m: inline => r"\alpha_c / M",
    alpha_c: inline => r"\alpha_c = \alpha / 7",
    e_err: inline => r"e = \dx - \dxhat",
    sigma_over_sqrt_n: inline => r"\sigma/\sqrt{N}",
    residual: inline => r"r(t_i)",
    z_score: inline => r"z",
    chi2_3n: inline => r"\chi^2(3N)",
    chi2_2n: inline => r"\chi^2(2N)",
    chi2_n1: inline => r"\chi^2(N-1)",
    ac_minus_a: inline => r"a_c - \bar{a} = b + w",
    euler_errors: inline => r"\delta p_E = p_E - p_c,\ \delta v_E = v_E - v_c",
    actual_errors: inline => r"\delta p = p - p_c,\ \delta v = v - v_c",
    q_def: inline => r"Q = \Gamma W \Gamma\T",
    one_over_sqrt_n: inline => r"1/\sqrt{N}",

    // The truth and the sensors.
    profile: block => r"a(t) = A \sin(\omega t)",
    analytic_truth: block => r"v(t) = v(0) + \frac{A}{\omega}\left(1 - \cos \omega t\right), \qquad p(t) = p(0) + \left(v(0) + \frac{A}{\omega}\right) t - \frac{A}{\omega^2} \sin \omega t",
    accelerometer: block => r"a_c(t_j) = a(t_j) + b + w(t_j), \qquad w(t_j) \sim \mathcal{N}(0, W), \qquad b \sim \mathcal{N}(0, M_b)",
    interval_mean: block => r"a_c(t_j) = \frac{1}{\Delta t} \int_{t_j}^{t_j + \Delta t} a(t)\,dt + b + w(t_j) = A\,\frac{\sin(\omega \Delta t / 2)}{\omega \Delta t / 2}\,\sin\!\left(\omega \left(t_j + \frac{\Delta t}{2}\right)\right) + b + w(t_j)",
    accel_integration: block => r"v_c(t_{j+1}) = v_c(t_j) + a_c(t_j)\,\Delta t, \qquad p_c(t_{j+1}) = p_c(t_j) + v_c(t_j)\,\Delta t + a_c(t_j)\,\frac{\Delta t^2}{2}",
    euler_truth: block => r"v_E(t_{j+1}) = v_E(t_j) + \bar{a}(t_j)\,\Delta t, \qquad p_E(t_{j+1}) = p_E(t_j) + v_E(t_j)\,\Delta t + \bar{a}(t_j)\,\frac{\Delta t^2}{2}",
    lag: block => r"v(t_{j+1}) - v(t_j) - a(t_j)\,\Delta t = \int_{t_j}^{t_{j+1}} \left(a(t) - a(t_j)\right) dt \approx \frac{\Delta t^2}{2}\,\dot{a}(t_j), \qquad \delta v(t) - \delta v_E(t) \approx \frac{\Delta t}{2}\left(a(t) - a(0)\right)",
    prediction: block => r"m(t_i^{\pm}) = \mathrm{E}\left[e(t_i^{\pm})\right] = e(t_i^{\pm}) \text{ with } w = 0,\ \eta = 0,\ \dx(0) = 0, \qquad \mathrm{E}\left[\bar{\epsilon}(t_i^{+})\right] = 3 + m\T P(t_i^{+})^{-1} m",
    gps: block => r"z^p(t_i) = p(t_i) + \eta^p(t_i), \qquad z^v(t_i) = v(t_i) + \eta^v(t_i), \qquad \eta(t_i) \sim \mathcal{N}(0, R)",

    // The error-state system.
    subtract: block => r"\delta v_E(t_{j+1}) = \delta v_E(t_j) - \left(b + w(t_j)\right)\Delta t, \qquad \delta p_E(t_{j+1}) = \delta p_E(t_j) + \delta v_E(t_j)\,\Delta t - \left(b + w(t_j)\right)\frac{\Delta t^2}{2}",
    error_dynamics: block => r"\underbrace{\begin{bmatrix} \delta p \\ \delta v \\ b \end{bmatrix}_{j+1}}_{\dx(t_{j+1})} = \underbrace{\begin{bmatrix} 1 & \Delta t & -\frac{\Delta t^2}{2} \\ 0 & 1 & -\Delta t \\ 0 & 0 & 1 \end{bmatrix}}_{\Phi} \begin{bmatrix} \delta p \\ \delta v \\ b \end{bmatrix}_j + \underbrace{\begin{bmatrix} -\frac{\Delta t^2}{2} \\ -\Delta t \\ 0 \end{bmatrix}}_{\Gamma} w(t_j)",
    measurement: block => r"\delta z(t_i) = \begin{bmatrix} z^p(t_i) - p_c(t_i) \\ z^v(t_i) - v_c(t_i) \end{bmatrix} = \underbrace{\begin{bmatrix} 1 & 0 & 0 \\ 0 & 1 & 0 \end{bmatrix}}_{H} \dx(t_i) + \eta(t_i), \qquad R = \begin{bmatrix} \sigma_p^2 & 0 \\ 0 & \sigma_v^2 \end{bmatrix}",
    initial: block => r"\dxhat(0) = 0, \qquad P(0) = \operatorname{diag}\left(M_p, M_v, M_b\right)",
    transition_closed: block => r"\Phi^n = \begin{bmatrix} 1 & n\Delta t & -\frac{(n\Delta t)^2}{2} \\ 0 & 1 & -n\Delta t \\ 0 & 0 & 1 \end{bmatrix}",

    // The filter.
    propagate: block => r"\dxbar(t_{j+1}) = \Phi\, \dxhat(t_j), \qquad P(t_{j+1}) = \Phi\, P(t_j)\, \Phi\T + \Gamma W \Gamma\T",
    gain: block => r"S(t_i) = H P(t_i^-) H\T + R, \qquad K(t_i) = P(t_i^-) H\T S(t_i)^{-1}",
    update: block => r"r(t_i) = \delta z(t_i) - H \dxbar(t_i), \qquad \dxhat(t_i^+) = \dxbar(t_i) + K(t_i)\, r(t_i)",
    joseph: block => r"P(t_i^+) = \left(I - K H\right) P(t_i^-) \left(I - K H\right)\T + K R K\T",

    // The Monte Carlo checks.
    bonferroni: block => r"|z| \le F_{\mathcal{N}}^{-1}\!\left(1 - \frac{\alpha_c}{2M}\right), \qquad F_{\chi^2}^{-1}\!\left(\frac{\alpha_c}{2M}\right) \le \chi^2 \le F_{\chi^2}^{-1}\!\left(1 - \frac{\alpha_c}{2M}\right)",
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_equation_converts_without_unknown_commands() {
        let math = Math::new();
        for (name, tex) in Equations::sources() {
            let out = math.inline(tex);
            assert!(out.starts_with("<math"), "{name}: {out}");
            assert!(
                !out.contains("merror") && !out.contains("color:red"),
                "{name}: {out}"
            );
        }
    }
}
