//! The tangent map of a kick–drift step and of the implicit rules' steps against differences of
//! two nearby steps, its symplecticity, and the Lyapunov spectra it gives: Hénon–Heiles chaotic
//! (a positive exponent and its mirror, a sum of 0 to round-off at every time) and regular (λ₁
//! falling as log T/T), the harmonic oscillator's all falling to 0, the double pendulum's pairs
//! under the midpoint rule, and the damped, driven pendulum's sum: the discrete map's exact
//! volume change, and −2β to the method's order.

use crate::common::Potential;
use varmech::diagnostics::{lyapunov, LyapunovOptions, Stretching};
use varmech::integrators::{Dynamics, Feature, General, Method, ModelKind, Options, Stepper, Tangent};
use varmech::scenes::{DampedDrivenPendulum, DoublePendulum, FermiPastaUlam, HarmonicOscillator, HenonHeiles};
use varmech::Error;

/// One step of `method` from (q, p): the end (q, p) as one vector.
fn step<S: Dynamics>(sys: &S, method: Method, h: f64, x: &[f64]) -> Vec<f64> {
    let n = sys.dim();
    let mut stepper = Stepper::new(sys, method, &x[..n], &x[n..], &Options::new(h, 1)).unwrap();
    stepper.step().unwrap();
    stepper.q().iter().chain(stepper.p()).copied().collect()
}

/// The tangent map applied to the 2n unit vectors: the step's Jacobian Ψ, column-major.
fn jacobian<S: Dynamics>(sys: &S, method: Method, h: f64, x: &[f64]) -> Vec<f64> {
    let (dim, n) = (x.len(), x.len() / 2);
    let mut psi = vec![0.0; dim * dim];
    (0..dim).for_each(|j| psi[j * dim + j] = 1.0);
    let mut tangent = Tangent::new(method, sys).unwrap();
    let mut stepper = Stepper::new(sys, method, &x[..n], &x[n..], &Options::new(h, 1)).unwrap();
    stepper.step_with_tangent(&mut tangent, &mut psi).unwrap();
    psi
}

/// max |Ψ − central differences of the step| over max |Ψ|, and ‖ΨᵀJΨ − J‖_max.
fn check<S: Dynamics>(sys: &S, method: Method, h: f64, x: &[f64]) -> (f64, f64) {
    let dim = x.len();
    let psi = jacobian(sys, method, h, x);
    let (mut error, mut size) = (0.0_f64, 0.0_f64);
    for j in 0..dim {
        let delta = 1e-5 * x[j].abs().max(1.0);
        let moved = |s: f64| {
            let mut y = x.to_vec();
            y[j] += s * delta;
            step(sys, method, h, &y)
        };
        let (plus, minus) = (moved(1.0), moved(-1.0));
        for i in 0..dim {
            let difference = (plus[i] - minus[i]) / (2.0 * delta);
            error = error.max((psi[j * dim + i] - difference).abs());
            size = size.max(psi[j * dim + i].abs());
        }
    }
    let n = dim / 2;
    // (ΨᵀJΨ)ᵢⱼ = Σ_k Ψ_{k,i}·(JΨ)_{k,j}, (JΨ)_{k,j} = Ψ_{k+n,j} for k < n, −Ψ_{k−n,j} after.
    let mut defect = 0.0_f64;
    for i in 0..dim {
        for j in 0..dim {
            let form: f64 = (0..n)
                .map(|k| psi[i * dim + k] * psi[j * dim + k + n] - psi[i * dim + k + n] * psi[j * dim + k])
                .sum();
            let exact = if j == i + n && i < n {
                1.0
            } else if i == j + n && j < n {
                -1.0
            } else {
                0.0
            };
            defect = defect.max((form - exact).abs());
        }
    }
    (error / size, defect)
}

#[test]
fn the_tangent_map_is_the_steps_jacobian_and_symplectic() {
    // Hénon–Heiles with its exact Hessian, and FPU's differenced one; BAB, ABA and first-order
    // splittings. Differences of 1e-5 of the step are right to about 1e-9.
    let hh = HenonHeiles::new();
    let fpu = FermiPastaUlam::new(3, 10.0).unwrap();
    let methods = [
        Method::Verlet,
        Method::Yoshida4,
        Method::Aba864,
        Method::SymplecticEuler,
    ];
    for method in methods {
        let (error, defect) = check(&hh, method, 0.1, &[0.1, -0.2, 0.3, 0.25]);
        assert!(error < 1e-8, "{method:?} on Hénon–Heiles: {error:e}");
        assert!(defect < 1e-14, "{method:?} on Hénon–Heiles: ΨᵀJΨ − J = {defect:e}");
        let x: Vec<f64> = (0..12).map(|i| 0.1 * ((i * 7 % 5) as f64 - 2.0)).collect();
        let (error, defect) = check(&fpu, method, 0.01, &x);
        assert!(error < 1e-7, "{method:?} on FPU: {error:e}");
        assert!(defect < 1e-11, "{method:?} on FPU: ΨᵀJΨ − J = {defect:e}");
    }
}

#[test]
fn vectors_carried_in_the_methods_loop_are_the_step_by_step_ones_to_the_bit() {
    // Hénon–Heiles (n = 2, the fixed-size loop, exact H) and FPU (n = 6, step by step,
    // differenced H); BAB, a composition with stage momenta, ABA and a first-order splitting.
    let hh = HenonHeiles::new();
    let fpu = FermiPastaUlam::new(3, 10.0).unwrap();
    let fpu_start: Vec<f64> = (0..12).map(|i| 0.1 * ((i * 7 % 5) as f64 - 2.0)).collect();
    let cases: [(&dyn Dynamics, Vec<f64>, f64); 2] =
        [(&hh, vec![0.0, -0.25, 0.42, 0.0], 0.05), (&fpu, fpu_start, 0.01)];
    for method in [
        Method::Verlet,
        Method::Yoshida4,
        Method::Aba864,
        Method::SymplecticEuler,
    ] {
        for (sys, x0, h) in &cases {
            let (n, steps) = (sys.dim(), 500);
            let start = |steps| Stepper::new(*sys, method, &x0[..n], &x0[n..], &Options::new(*h, steps)).unwrap();
            let vectors = || -> Vec<f64> { (0..4 * n * n).map(|i| ((i * 37 % 11) as f64 - 5.0) / 7.0).collect() };
            let (mut one, mut by_step) = (start(steps), vectors());
            let mut tangent = Tangent::new(method, *sys).unwrap();
            for _ in 0..steps {
                one.step_with_tangent(&mut tangent, &mut by_step).unwrap();
            }
            let (mut loop_, mut carried) = (start(steps), vectors());
            let mut tangent = Tangent::new(method, *sys).unwrap();
            loop_
                .advance_with_tangent(steps, &mut tangent, &mut carried, || Ok(()))
                .unwrap();
            let mut plain = start(steps);
            plain.advance(steps, || Ok(())).unwrap();
            let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&carried), bits(&by_step), "{method:?}, n = {n}");
            assert_eq!(bits(loop_.q()), bits(plain.q()), "{method:?}, n = {n}");
            assert_eq!(bits(loop_.p()), bits(plain.p()), "{method:?}, n = {n}");
            assert_eq!(loop_.steps(), steps);
            // Past a bound that the run reaches: the loop stops after the step that first takes
            // a component past it, the vectors as step by step there.
            let large = 0.5 * by_step.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let (mut bounded, mut x, mut tangent) = (start(steps), vectors(), Tangent::new(method, *sys).unwrap());
            let stopped = bounded
                .advance_with_tangent_below(steps, (&mut tangent, &mut x), large, || Ok(()))
                .unwrap();
            let (mut again, mut bound_x, mut tangent) = (start(steps), vectors(), Tangent::new(method, *sys).unwrap());
            let first = (1..=steps).find(|_| {
                again.step_with_tangent(&mut tangent, &mut bound_x).unwrap();
                bound_x.iter().any(|v| v.abs() > large)
            });
            assert_eq!((stopped, Some(bounded.steps())), (true, first), "{method:?}, n = {n}");
            assert_eq!(bits(&x), bits(&bound_x), "{method:?}, n = {n}");
        }
    }
}

fn spectrum<S: Dynamics>(sys: &S, q0: &[f64], p0: &[f64], (dt, steps): (f64, usize)) -> Stretching {
    spectrum_of(sys, Method::Verlet, q0, p0, (dt, steps))
}

fn spectrum_of<S: Dynamics>(sys: &S, method: Method, q0: &[f64], p0: &[f64], (dt, steps): (f64, usize)) -> Stretching {
    let options = LyapunovOptions {
        t0: 0.0,
        dt,
        steps,
        k: 2 * q0.len(),
        every: 10,
        start: None,
    };
    lyapunov(sys, method, q0, p0, &options, || Ok(())).unwrap()
}

/// λⱼ at row r of the run.
fn exponents(s: &Stretching, r: usize) -> Vec<f64> {
    s.sums[r * s.k..(r + 1) * s.k].iter().map(|x| x / s.t[r]).collect()
}

#[test]
fn henon_heiles_chaotic_has_a_positive_exponent_its_mirror_and_a_sum_of_zero_at_every_time() {
    let sys = HenonHeiles::new();
    let s = spectrum(&sys, &[0.0, -0.25], &[0.42, 0.0], (0.05, 200_000));
    // The tangent map has determinant 1: Σ ln Rⱼⱼ is 0 to round-off at every
    // re-orthonormalization (20 000 of them here).
    let worst = s
        .sums
        .chunks_exact(4)
        .map(|r| r.iter().sum::<f64>().abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-11, "Σ ln R = {worst:e}");
    let last = exponents(&s, s.t.len() - 1);
    assert!(last[0] > 0.04, "λ₁ = {}", last[0]);
    assert!((last[0] + last[3]).abs() < 1e-3, "{last:?}");
    // The two along the flow and across the energy shell fall as 1/T.
    assert!(last[1].abs() < 2e-3 && last[2].abs() < 2e-3, "{last:?}");
    // The same run's states, bit for bit.
    let mut stepper = Stepper::new(
        &sys,
        Method::Verlet,
        &[0.0, -0.25],
        &[0.42, 0.0],
        &Options::new(0.05, 1),
    )
    .unwrap();
    stepper.advance(200_000, || Ok(())).unwrap();
    assert_eq!((stepper.q(), stepper.p()), (&s.q[..], &s.p[..]));
}

#[test]
fn a_regular_orbits_exponents_fall_as_log_t_over_t() {
    // Hénon–Heiles on a torus (H = 0.13, the SciML protocol's orbit), and the harmonic
    // oscillator (its Hessian differenced): λ₁(T) ≈ c·ln T/T, so from T = 10³ to 10⁴ it falls by
    // about 7.7 (at least 4 here), and Σλ stays 0.
    let hh = HenonHeiles::new();
    let ho = HarmonicOscillator::new(2.0).unwrap();
    let runs = [
        spectrum(&hh, &[0.1, 0.0], &[0.0, 0.5], (0.05, 200_000)),
        spectrum(&ho, &[1.0], &[0.0], (0.05, 200_000)),
    ];
    for s in runs {
        let at = |t: f64| exponents(&s, s.t.iter().position(|&x| x >= t).unwrap());
        let (early, late) = (at(1e3), at(1e4));
        assert!(
            late[0] > 0.0 && late[0] < early[0] / 4.0,
            "λ₁ {} → {}",
            early[0],
            late[0]
        );
        assert!(late[0] < 2e-3, "{late:?}");
        assert!(late.iter().sum::<f64>().abs() < 1e-14, "{late:?}");
    }
}

#[test]
fn bad_requests_are_refused_naming_the_argument() {
    let hh = HenonHeiles::new();
    let options = LyapunovOptions {
        t0: 0.0,
        dt: 0.05,
        steps: 100,
        k: 4,
        every: 10,
        start: None,
    };
    let refused = |sys: &dyn Dynamics, method, options: LyapunovOptions| match lyapunov(
        sys,
        method,
        &[0.1, 0.0],
        &[0.0, 0.5],
        &options,
        || Ok(()),
    ) {
        Err(Error::InvalidArgument { argument, .. }) => argument,
        other => panic!("not refused: {other:?}"),
    };
    assert_eq!(refused(&hh, Method::Verlet, LyapunovOptions { k: 5, ..options }), "k");
    assert_eq!(refused(&hh, Method::Verlet, LyapunovOptions { k: 0, ..options }), "k");
    assert_eq!(
        refused(&hh, Method::Verlet, LyapunovOptions { every: 0, ..options }),
        "every"
    );
    assert_eq!(refused(&hh, Method::Rk4, options), "method");
    let twice = [1.0, 0.0, 0.0, 0.0].repeat(4);
    let start = LyapunovOptions {
        start: Some(&twice),
        ..options
    };
    assert_eq!(refused(&hh, Method::Verlet, start), "tangent0");
    // A kick–drift method on a general Lagrangian; its implicit rules take it.
    let pendulum = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81).unwrap();
    assert_eq!(refused(&General(&pendulum), Method::Verlet, options), "model");
    assert!(lyapunov(
        &General(&pendulum),
        Method::Midpoint,
        &[0.1, 0.0],
        &[0.0, 0.5],
        &options,
        || Ok(())
    )
    .is_ok());
}

#[test]
fn a_tangent_map_is_made_exactly_for_the_methods_the_table_gives_one() {
    // Each method on a model it integrates: Hénon–Heiles, or the planar chain on constraints.
    // Those with `Feature::TangentMap` get one; the others are refused naming the method and
    // listing those that have one.
    let hh = HenonHeiles::new();
    let chain = varmech::scenes::planar_chain(2).unwrap();
    let listed = Method::names(|m| m.supports(Feature::TangentMap));
    for method in Method::every() {
        let made = if ModelKind::Separable.admits(method) {
            Tangent::new(method, &hh)
        } else if ModelKind::ConstrainedSeparable.admits(method) {
            Tangent::new(method, &chain.system)
        } else {
            assert!(
                !method.supports(Feature::TangentMap),
                "{method:?}: no model here to check it on"
            );
            continue;
        };
        match made {
            Ok(_) => assert!(method.supports(Feature::TangentMap), "{method:?}"),
            Err(Error::InvalidArgument { argument, reason }) => {
                assert!(!method.supports(Feature::TangentMap), "{method:?}: {reason}");
                assert_eq!(argument, "method");
                assert!(listed.iter().all(|name| reason.contains(name)), "{reason}");
            }
            Err(other) => panic!("{method:?}: {other}"),
        }
    }
}

#[test]
fn the_implicit_rules_tangent_maps_are_their_steps_jacobians() {
    // The double pendulum (M(q): a general Lagrangian) and Hénon–Heiles through its Lagrangian:
    // symplectic to the differencing error; the damped, driven pendulum (forced, its drive
    // depending on t): its Jacobian, whose determinant is the step's volume change. Measured:
    // 1e-11–7e-11 from the differences of the step (themselves right to about 1e-10), ΨᵀJΨ − J
    // 3e-12–1.4e-11.
    let double = DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.81).unwrap();
    let hh = HenonHeiles::new();
    let (damped, _) = taylor(1.077);
    for method in crate::common::IMPLICIT {
        let (error, defect) = check(&General(&double), method, 0.01, &[0.5, 1.0, 0.3, -0.2]);
        assert!(error < 1e-9, "{method:?} on the double pendulum: {error:e}");
        assert!(
            defect < 1e-10,
            "{method:?} on the double pendulum: ΨᵀJΨ − J = {defect:e}"
        );
        let (error, defect) = check(&hh, method, 0.1, &[0.1, -0.2, 0.3, 0.25]);
        assert!(error < 1e-9, "{method:?} on Hénon–Heiles: {error:e}");
        assert!(defect < 1e-10, "{method:?} on Hénon–Heiles: ΨᵀJΨ − J = {defect:e}");
        let (error, _) = check(&General(&damped), method, 0.005, &[0.4, 2.0]);
        assert!(error < 1e-9, "{method:?} on the damped pendulum: {error:e}");
    }
}

#[test]
fn the_double_pendulums_exponents_come_in_pairs_under_the_midpoint_rule() {
    // Chaotic (both arms swinging from 90°): λ₁ > 0, λ₁ + λ₄ and λ₂ + λ₃ near 0, and Σλ, the
    // tangent map's log-determinant per unit time, 0 to the differencing error.
    let double = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81).unwrap();
    let half = std::f64::consts::FRAC_PI_2;
    let s = spectrum_of(
        &General(&double),
        Method::Midpoint,
        &[half, half],
        &[0.0, 0.0],
        (0.01, 50_000),
    );
    let last = exponents(&s, s.t.len() - 1);
    assert!(last[0] > 0.5, "{last:?}");
    assert!((last[0] + last[3]).abs() < 0.05 * last[0], "{last:?}");
    assert!((last[1] + last[2]).abs() < 0.05 * last[0], "{last:?}");
    assert!(last.iter().sum::<f64>().abs() < 1e-8, "{last:?}");
}

/// The damped, driven pendulum in Taylor's form φ̈ + 2βφ̇ + ω₀² sin φ = γω₀² cos ωt (ω = 2π,
/// ω₀ = 1.5ω, β = ω₀/4): m = l = 1, g = ω₀², damping 2β, amplitude γω₀², drive ω.
fn taylor(gamma: f64) -> (DampedDrivenPendulum, f64) {
    let omega = 2.0 * std::f64::consts::PI;
    let (omega0, beta) = (1.5 * omega, 0.375 * omega);
    let sys = DampedDrivenPendulum::new(1.0, 1.0, omega0 * omega0, 2.0 * beta, gamma * omega0 * omega0, omega).unwrap();
    (sys, beta)
}

#[test]
fn the_driven_pendulums_exponents_sum_to_the_steps_exact_volume_change_and_to_minus_two_beta() {
    // The forced midpoint step's determinant, from its equations p₀ = (1 + hb/2)v + (h/2)K sin q̄ + …,
    // p₁ = (1 − hb/2)v − (h/2)K sin q̄ + … in (q₀, v): (1 − hb/2 + c)/(1 + hb/2 + c), c = (h²/4)K cos q̄,
    // q̄ the step's midpoint. Σ ln det over the run is Σλ·T to the differencing error, and
    // Σλ = −2β + O(h²).
    let (sys, beta) = taylor(1.077);
    let omega0_sq = (3.0 * std::f64::consts::PI).powi(2);
    let mut errors = Vec::new();
    for h in [1.0 / 100.0, 1.0 / 200.0] {
        let steps = (100.0 / h) as usize;
        let s = spectrum_of(&General(&sys), Method::Midpoint, &[0.0], &[0.0], (h, steps));
        let total: f64 = s.sums[s.sums.len() - 2..].iter().sum();
        let model = General(&sys);
        let mut stepper = Stepper::new(&model, Method::Midpoint, &[0.0], &[0.0], &Options::new(h, 1)).unwrap();
        let mut exact = 0.0;
        for _ in 0..steps {
            let q0 = stepper.q()[0];
            stepper.step().unwrap();
            let c = 0.25 * h * h * omega0_sq * (0.5 * (q0 + stepper.q()[0])).cos();
            exact += ((1.0 - h * beta + c) / (1.0 + h * beta + c)).ln();
        }
        assert!(
            (total - exact).abs() < 1e-10 * exact.abs(),
            "h = {h}: Σ ln R = {total}, Σ ln det = {exact}"
        );
        errors.push(total / 100.0 + 2.0 * beta);
    }
    // Second order: the error falls by 4 from h to h/2.
    let order = (errors[0] / errors[1]).log2();
    assert!((order - 2.0).abs() < 0.1, "Σλ + 2β = {errors:?}, order {order}");
}

#[test]
fn the_driven_pendulum_is_chaotic_past_taylors_cascade_and_periodic_before_it() {
    // γ = 1.06: the period-1 attractor, both exponents negative; γ = 1.105 (Taylor's chaotic
    // example, past γ ≈ 1.0829): λ₁ > 0.
    let lambda = |gamma: f64| {
        let (sys, _) = taylor(gamma);
        let s = spectrum_of(
            &General(&sys),
            Method::Midpoint,
            &[-std::f64::consts::FRAC_PI_2],
            &[0.0],
            (0.005, 60_000),
        );
        exponents(&s, s.t.len() - 1)
    };
    let periodic = lambda(1.06);
    assert!(periodic[0] < -0.1, "{periodic:?}");
    let chaotic = lambda(1.105);
    assert!(chaotic[0] > 0.1, "{chaotic:?}");
}

#[test]
fn rattles_tangent_map_is_its_steps_jacobian_on_the_constraint_manifold() {
    // The double pendulum in Cartesian coordinates (two unit masses on unit links, 4
    // coordinates, 2 constraints), moving: Ψ maps every vector into the tangent space at the
    // step's end (G(q₁)δq₁ = 0), and on the manifold it is the Jacobian of RATTLE's step,
    // against differences of steps from states projected onto it (1e-5 apart; right to about
    // 1e-10). Measured: 7.6e-12 and 2.9e-11.
    let chain = varmech::scenes::planar_chain(2).unwrap();
    let sys = &chain.system;
    let h = 0.01;
    let mut stepper = Stepper::new(
        sys,
        Method::Rattle,
        &chain.initial.q,
        &chain.initial.p,
        &Options::new(h, 1),
    )
    .unwrap();
    stepper.advance(50, || Ok(())).unwrap();
    let (q, p) = (stepper.q().to_vec(), stepper.p().to_vec());
    let x: Vec<f64> = q.iter().chain(&p).copied().collect();
    let psi = jacobian(sys, Method::Rattle, h, &x);
    let end = step(sys, Method::Rattle, h, &x);
    let mut g1 = nalgebra::DMatrix::zeros(2, 4);
    sys.holonomic().unwrap().jacobian(&end[..4], &mut g1).unwrap();
    let (mut worst_tangency, mut worst_error) = (0.0_f64, 0.0_f64);
    for j in 0..8 {
        let v: Vec<f64> = (0..8).map(|i| ((3 * i + 5 * j) % 7) as f64 / 7.0 - 0.4).collect();
        let image: Vec<f64> = (0..8).map(|i| (0..8).map(|c| psi[c * 8 + i] * v[c]).sum()).collect();
        let tangency = (0..2)
            .map(|r| (0..4).map(|c| g1[(r, c)] * image[c]).sum::<f64>().abs())
            .fold(0.0, f64::max);
        worst_tangency = worst_tangency.max(tangency);
        // A tangent vector w at (q, p) from states projected onto the manifold, and the steps
        // from them.
        let delta = 1e-5;
        let onto = |s: f64| {
            let moved: Vec<f64> = x.iter().zip(&v).map(|(x, v)| x + s * delta * v).collect();
            let (q, p) = Dynamics::project(sys, &moved[..4], &moved[4..]).unwrap().unwrap();
            q.into_iter().chain(p).collect::<Vec<f64>>()
        };
        let (plus, minus) = (onto(1.0), onto(-1.0));
        let w: Vec<f64> = plus.iter().zip(&minus).map(|(a, b)| (a - b) / (2.0 * delta)).collect();
        let (a, b) = (
            step(sys, Method::Rattle, h, &plus),
            step(sys, Method::Rattle, h, &minus),
        );
        for i in 0..8 {
            let difference = (a[i] - b[i]) / (2.0 * delta);
            let mapped: f64 = (0..8).map(|c| psi[c * 8 + i] * w[c]).sum();
            worst_error = worst_error.max((mapped - difference).abs());
        }
    }
    assert!(worst_tangency < 1e-10, "G(q₁)δq₁ = {worst_tangency:e}");
    assert!(worst_error < 1e-9, "{worst_error:e}");
}

/// V = −q²/2 at its top, q = p = 0: the state stays there while a tangent vector grows by about
/// h² a step, past any float at h = 10¹⁶⁰.
fn inverted() -> Potential {
    Potential::unit(1, |q| -0.5 * q[0] * q[0], |q, grad| grad[0] = -q[0])
}

/// Tangent vectors that one step takes past the largest float stop the spectrum, and a
/// stepper's tangent run, with a divergence saying what to change, never NaN exponents; at a
/// step they survive (stretched 10¹⁰⁰ a step), the exponent is the step map's own.
#[test]
fn tangent_vectors_that_overflow_in_a_step_are_a_divergence_not_nan() {
    let sys = inverted();
    let options = |dt: f64| LyapunovOptions {
        t0: 0.0,
        dt,
        steps: 4,
        k: 2,
        every: 1,
        start: None,
    };
    for method in [Method::Verlet, Method::Yoshida4] {
        match lyapunov(&sys, method, &[0.0], &[0.0], &options(1e160), || Ok(())) {
            Err(Error::Divergence { step: 1, reason, .. }) => {
                assert!(
                    reason.contains("tangent vectors overflowed") && reason.contains("smaller dt"),
                    "{reason}"
                )
            }
            other => panic!("{method:?}: {other:?}"),
        }
    }
    // Verlet's map at q = 0 is [[1 + h², h], [h, 1]] (δp first kicked by h/2·δq): its
    // eigenvalue 1 + h²/2 + h√(1 + h²/4) is e^(λh) for the largest exponent.
    let h = 1e50;
    let largest = LyapunovOptions {
        steps: 100,
        k: 1,
        ..options(h)
    };
    let found = lyapunov(&sys, Method::Verlet, &[0.0], &[0.0], &largest, || Ok(())).unwrap();
    // After the first step (whose start leans on the contracting direction: the map is far
    // from normal) the vector grows by the eigenvalue each step.
    let (sums, t) = (&found.sums, &found.t);
    let measured = (sums[sums.len() - 1] - sums[0]) / (t[t.len() - 1] - t[0]);
    let exponent = (1.0 + h * h / 2.0 + h * (1.0 + h * h / 4.0).sqrt()).ln() / h;
    assert!((measured / exponent - 1.0).abs() < 1e-12, "{measured} {exponent}");
    let mut stepper = Stepper::new(&sys, Method::Verlet, &[0.0], &[0.0], &Options::new(1e160, 4)).unwrap();
    let mut tangent = Tangent::new(Method::Verlet, &sys).unwrap();
    let mut x = vec![1.0, 0.0];
    let overflowed = stepper.advance_with_tangent(4, &mut tangent, &mut x, || Ok(()));
    assert!(
        matches!(overflowed, Err(Error::Divergence { step: 1, .. })),
        "{overflowed:?}"
    );
    assert_eq!(stepper.steps(), 1, "the step that overflowed the vectors is kept");
}
