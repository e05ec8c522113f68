//! The discrete energy E_d = −∂L_d/∂τ of a step ([`DiscreteEnergy`]): exact on the ball and by
//! hand for Verlet, E_d − H of the order the method's discrete Lagrangian has, and the values
//! of the independent Python implementation (python/varmech/impacts.py).

use varmech::integrators::{DiscreteEnergy, Dynamics, General, Increment, Integrator, Method, Splitting, StepStart};
use varmech::scenes::{BouncingBall, DoublePendulum, HarmonicOscillator, Pendulum, SphericalPendulum};

/// Every method with a kick–drift splitting.
fn kick_drift_methods() -> impl Iterator<Item = Method> {
    Method::ALL.into_iter().filter(|m| Splitting::of(*m).is_some())
}

/// The end (q₁, p₁) of one step of size τ of `method` from (q₀, p₀).
fn step<S: Dynamics + ?Sized>(sys: &S, method: Method, tau: f64, q0: &[f64], p0: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = q0.len();
    let (mut dq, mut dp) = (vec![0.0; n], vec![0.0; n]);
    let mut integrator = Integrator::new(method, n);
    let start = StepStart {
        t: 0.0,
        h: tau,
        q: q0,
        p: p0,
    };
    let mut increment = Increment {
        dq: &mut dq,
        dp: &mut dp,
    };
    sys.increment(&mut integrator, &start, &mut increment).unwrap();
    let add = |x: &[f64], d: &[f64]| x.iter().zip(d).map(|(a, b)| a + b).collect::<Vec<_>>();
    (add(q0, &dq), add(p0, &dp))
}

/// E_d of `method`'s step of size τ from (q₀, p₀), to where the method takes it.
fn discrete_energy<S: Dynamics + ?Sized>(sys: &S, method: Method, tau: f64, q0: &[f64], p0: &[f64]) -> f64 {
    let (q1, p1) = step(sys, method, tau, q0, p0);
    let mut energy = DiscreteEnergy::new(method, q0.len()).expect("a method with E_d");
    energy.energy(sys, 0.0, tau, (q0, p0), (&q1, &p1)).unwrap()
}

/// H(q, p) = E, the energy function.
fn hamiltonian<S: Dynamics + ?Sized>(sys: &S, q: &[f64], p: &[f64]) -> f64 {
    sys.as_lagrangian().energy_terms(q, p, 0.0).unwrap().energy
}

/// The measured orders log₂(|E_d − H|(τ)/|E_d − H|(τ/2)) over the halvings of τ.
fn orders<S: Dynamics + ?Sized>(sys: &S, method: Method, taus: &[f64], q0: &[f64], p0: &[f64]) -> Vec<f64> {
    let h = hamiltonian(sys, q0, p0);
    let errors: Vec<f64> = taus
        .iter()
        .map(|&tau| (discrete_energy(sys, method, tau, q0, p0) - h).abs())
        .collect();
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
}

#[test]
fn the_methods_with_a_discrete_energy_are_the_kick_drift_methods_the_two_point_and_galerkin_rules() {
    for method in Method::every() {
        let expected = Splitting::of(method).is_some()
            || matches!(
                method,
                Method::Midpoint | Method::Trapezoid | Method::Galerkin4 | Method::Galerkin6
            );
        assert_eq!(DiscreteEnergy::new(method, 2).is_some(), expected, "{method:?}");
    }
}

#[test]
fn the_balls_midpoint_energy_is_h_less_g_squared_tau_squared_over_8() {
    // The midpoint step is exact on the parabola: q̄ = q₀ + τp̄/2, p̄ = p₀ − gτ/2, so
    // H(q̄, p̄) = p̄²/2 + g q̄ = H(q₀, p₀) − g²τ²/8.
    let g = 9.81;
    let ball = BouncingBall::new(g).unwrap();
    for (q0, p0) in [(1.0, 0.0), (0.3, -2.5), (2.0, 4.0)] {
        for tau in [0.1, 0.01, 0.5] {
            let h = 0.5 * p0 * p0 + g * q0;
            let energy = discrete_energy(&ball, Method::Midpoint, tau, &[q0], &[p0]);
            let exact = h - g * g * tau * tau / 8.0;
            assert!(
                (energy - exact).abs() <= 1e-14 * exact.abs().max(1.0),
                "(q0, p0) = ({q0}, {p0}), τ = {tau}: E_d = {energy}, H − g²τ²/8 = {exact}"
            );
        }
    }
}

#[test]
fn verlets_energy_is_the_half_step_kinetic_and_the_mean_potential() {
    // Störmer–Verlet by hand: p½ = p₀ − (τ/2)V′(q₀), q₁ = q₀ + τp½,
    // E_d = T(p½) + ½(V(q₀) + V(q₁)); the trapezoid is the same step (its v is p½) with
    // E_d = ½[E(q₀, v) + E(q₁, v)], the same value.
    let g = 9.81;
    let ball = BouncingBall::new(g).unwrap();
    agrees_with_verlet_by_hand(&ball, |q| g * q, |_| g);
    agrees_with_verlet_by_hand(&Pendulum::new(), |q| -q.cos(), f64::sin);
}

/// E_d of Verlet and the trapezoid on a system of one coordinate with potential V and slope V′
/// against T(p½) + ½(V(q₀) + V(q₁)).
fn agrees_with_verlet_by_hand<S: Dynamics>(sys: &S, potential: impl Fn(f64) -> f64, slope: impl Fn(f64) -> f64) {
    for (q0, p0, tau) in [(1.0, 0.0, 0.1), (0.3, -0.7, 0.25), (-1.2, 1.5, 0.03)] {
        let half = p0 - 0.5 * tau * slope(q0);
        let q1 = q0 + tau * half;
        let by_hand = 0.5 * half * half + 0.5 * (potential(q0) + potential(q1));
        for method in [Method::Verlet, Method::Trapezoid] {
            let energy = discrete_energy(sys, method, tau, &[q0], &[p0]);
            assert!(
                (energy - by_hand).abs() <= 1e-14 * by_hand.abs().max(1.0),
                "{method:?}, (q0, p0, τ) = ({q0}, {p0}, {tau}): E_d = {energy}, by hand {by_hand}"
            );
        }
    }
}

#[test]
fn a_kick_drift_methods_energy_is_h_to_its_order() {
    // E_d − H(q₀, p₀) = O(τʳ), r the method's order, since L_d is the exact discrete Lagrangian
    // to O(τʳ⁺¹) and E_d its −∂/∂τ at fixed ends. Measured on τ = 0.05 → 0.025 (r ≤ 2), 0.1 → 0.05
    // (r = 4), 0.2 → 0.1 (r = 6) and 0.4 → 0.2 (r = 8, whose errors then are 1e-11 already):
    // symplectic Euler 0.99 and 0.96, Verlet 1.96 and 2.03, the order-4 methods 3.88–4.07 except
    // McLachlan's on the pendulum, 4.46 (from above as τ halves: 4.58, 4.56, 4.46, 4.33, 4.20,
    // its τ⁴ term small there), the order-6 ones 5.83–5.94, the order-8 ones 7.42–8.30.
    let oscillator = HarmonicOscillator::new(1.0).unwrap();
    let pendulum = Pendulum::new();
    for method in kick_drift_methods() {
        let r = method.info().order;
        let (taus, tolerance) = match r {
            1 | 2 => ([0.05, 0.025], 0.2),
            4 => ([0.1, 0.05], 0.5),
            6 => ([0.2, 0.1], 0.2),
            _ => ([0.4, 0.2], 0.6),
        };
        let measured = [
            ("oscillator", orders(&oscillator, method, &taus, &[0.6], &[0.8])[0]),
            ("pendulum", orders(&pendulum, method, &taus, &[0.9], &[0.4])[0]),
        ];
        for (system, order) in measured {
            assert!(
                (order - r as f64).abs() <= tolerance,
                "{method:?} on the {system}: |E_d − H| of order {order:.3}, not {r}"
            );
        }
    }
}

#[test]
fn a_two_point_rules_energy_on_a_natural_system_is_h_to_order_2() {
    // M(q) depends on the configuration: the trapezoid's velocity is iterated, the midpoint's
    // energy is H at the mean state. Measured on τ = 0.025 → 0.0125: midpoint 2.00 on both,
    // trapezoid 2.00 and 2.09 (the spherical pendulum's from above: 2.62, 2.47, 2.30, 2.17, 2.09
    // as τ halves from 0.4).
    let double = DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let spherical = SphericalPendulum::new(1.0, 1.0, 1.0).unwrap();
    let taus = [0.025, 0.0125];
    for method in [Method::Midpoint, Method::Trapezoid] {
        let measured = [
            (
                "double pendulum",
                orders(&General(&double), method, &taus, &[0.7, -0.4], &[1.3, 0.8])[0],
            ),
            (
                "spherical pendulum",
                orders(&General(&spherical), method, &taus, &[1.0, 0.3], &[0.2, 0.85])[0],
            ),
        ];
        for (system, order) in measured {
            assert!(
                (order - 2.0).abs() <= 0.2,
                "{method:?} on the {system}: |E_d − H| of order {order:.3}, not 2"
            );
        }
    }
}

#[test]
fn a_galerkin_rules_energy_is_h_to_its_order_and_exact_on_the_ball() {
    // L_d of degree s with s Gauss nodes is the exact discrete Lagrangian to O(τ^{2s+1}), so
    // E_d − H = O(τ^{2s}). Measured on the double pendulum, τ = 0.4 → 0.025: galerkin4 4.11,
    // 4.05, 4.01, 4.00; galerkin6 12.2, 4.58, 5.77, 5.99 (asymptotic from τ = 0.05). On the ball the parabola is a polynomial of degree 2 and L along it one
    // of degree 2, which both rules reproduce: E_d = H to round-off at any τ.
    let double = DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let ball = BouncingBall::new(9.81).unwrap();
    for (method, order, taus) in [
        (Method::Galerkin4, 4.0, &[0.1, 0.05]),
        (Method::Galerkin6, 6.0, &[0.05, 0.025]),
    ] {
        let measured = orders(&General(&double), method, taus, &[0.7, -0.4], &[1.3, 0.8])[0];
        assert!(
            (measured - order).abs() <= 0.2,
            "{method:?}: |E_d − H| of order {measured:.3}, not {order}"
        );
        for (q0, p0, tau) in [(1.0, 0.0, 0.3), (0.3, -2.5, 0.05)] {
            let h = hamiltonian(&General(&ball), &[q0], &[p0]);
            let energy = discrete_energy(&General(&ball), method, tau, &[q0], &[p0]);
            assert!((energy - h).abs() <= 1e-13 * h.abs(), "{method:?}: E_d {energy}, H {h}");
        }
    }
}

#[test]
fn the_discrete_energy_is_the_python_implementations() {
    // E_d of python/varmech/impacts.py's `Splitting(...).forward` (pendulum, (q₀, p₀) = (0.3,
    // 0.7), τ = 0.1) and `TwoPoint(...).energy` (double pendulum, from (0.7, −0.4), (1.3, 0.8) to
    // the core's step), printed by this script on main at 88600cf:
    //     import numpy as np, varmech
    //     from varmech import _core
    //     from varmech.impacts import Splitting, TwoPoint
    //     from varmech.methods import method_info
    //     pend = varmech.scenes.pendulum().model
    //     for m in ["verlet", "symplectic_euler", "yoshida4", "blanes_moan4", "aba864", "mclachlan8_dkd"]:
    //         print(m, repr(Splitting(pend, *method_info(m).splitting, 0.0).forward(
    //             np.array([0.3]), np.array([0.7]), 0.1)[2]))
    //     model = varmech.scenes.double_pendulum().model
    //     q0, p0 = np.array([0.7, -0.4]), np.array([1.3, 0.8])
    //     for m in ["midpoint", "trapezoid"]:
    //         for tau in [0.05, 0.2]:
    //             s = _core.Stepper(model._core, q0, p0, dt=tau, method=m)
    //             cp = s.checkpoint(); s.step(); q1, p1 = np.asarray(s.q), np.asarray(s.p)
    //             print(m, tau, q1.tolist(), p1.tolist(), repr(TwoPoint(model, cp, 0.0).energy(q0, p0, q1, p1, tau)))
    let pendulum = Pendulum::new();
    let splittings = [
        (Method::Verlet, -0.7093326120404325),
        (Method::SymplecticEuler, -0.7305862426291739),
        (Method::Yoshida4, -0.7103484419845927),
        (Method::BlanesMoan4, -0.710336491055819),
        (Method::Aba864, -0.7103364908032652),
        (Method::McLachlan8Dkd, -0.7103364891255602),
    ];
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    for (method, python) in splittings {
        let mut energy = DiscreteEnergy::new(method, 1).unwrap();
        // A kick–drift method's E_d replays the step from its start; the end is not read.
        let core = energy
            .energy(&pendulum, 0.0, 0.1, (&[0.3], &[0.7]), (&[f64::NAN], &[f64::NAN]))
            .unwrap();
        assert!(close(core, python), "{method:?}: core {core}, python {python}");
    }
    let double = DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let (q0, p0) = ([0.7, -0.4], [1.3, 0.8]);
    let two_point = [
        (
            Method::Midpoint,
            0.05,
            [0.6996936433356383, -0.39610124394949714],
            [-0.594685318385118, 1.9401271039806145],
            -99.19640910810634,
        ),
        (
            Method::Midpoint,
            0.2,
            [0.6353973939602908, -0.3464988584854118],
            [-5.807560331358619, 4.912168312419043],
            -100.24656222510141,
        ),
        (
            Method::Trapezoid,
            0.05,
            [0.6996889223874165, -0.396092476473525],
            [-0.5946754694720806, 1.940108524983929],
            -99.19628733023154,
        ),
        (
            Method::Trapezoid,
            0.2,
            [0.6316364451341184, -0.34367731229219084],
            [-5.766292039354, 4.875377703742773],
            -100.21359803407981,
        ),
    ];
    for (method, tau, q1, p1, python) in two_point {
        let mut energy = DiscreteEnergy::new(method, 2).unwrap();
        let core = energy
            .energy(&General(&double), 0.0, tau, (&q0, &p0), (&q1, &p1))
            .unwrap();
        assert!(
            close(core, python),
            "{method:?}, τ = {tau}: core {core}, python {python}"
        );
    }
}
