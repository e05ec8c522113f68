//! The heavy symmetric top in Euler angles (θ, φ, ψ), θ from the upward vertical: a general
//! Lagrangian with two cyclic angles, checked against its exact derivatives, its conserved
//! momenta, its steady precessions and the turning points of its nutation.

use crate::common;

use common::InvariantStatistics;
use varmech::diagnostics::Verdict;
use varmech::integrators::{Method, NewtonOptions, Options, Trajectory};
use varmech::model::Lagrangian;
use varmech::scenes::{HeavyTop, Problem, State};

/// Generic states: θ on both sides of π/2, every velocity non-zero.
const STATES: [([f64; 3], [f64; 3]); 3] = [
    ([0.7, 0.3, -1.1], [0.4, -1.3, 2.2]),
    ([2.1, -4.0, 0.5], [-0.9, 0.6, -3.1]),
    ([0.25, 1.0, 2.0], [1.7, 2.5, 0.8]),
];

fn top() -> HeavyTop {
    HeavyTop::new(1.3, 0.6, 0.8).unwrap()
}

fn energy(sys: &HeavyTop, traj: &Trajectory) -> Vec<f64> {
    common::along(traj, |q, p| sys.energy(q, p, 0.0).unwrap())
}

fn thetas(traj: &Trajectory) -> Vec<f64> {
    (0..traj.len()).map(|k| traj.q_at(k)[0]).collect()
}

/// The state at angles q with velocities v.
fn state(sys: &HeavyTop, q: [f64; 3], v: [f64; 3]) -> State {
    let mut p = vec![0.0; 3];
    sys.dl_dv(&q, &v, 0.0, &mut p).unwrap();
    State {
        t: 0.0,
        q: q.to_vec(),
        p,
    }
}

#[test]
fn the_hessians_are_the_derivatives_of_the_gradients() {
    let sys = top();
    for (q, v) in STATES {
        let (h, worst) = common::assert_hessians(&sys, &q, &v, 1e-7);
        let e = 1e-6;
        // L_qq̇ is also ∂p/∂q: entry (i, j) = ∂pⱼ/∂qᵢ, the transpose of what the loop checked.
        let lv = |q: &[f64], out: &mut [f64]| sys.dl_dv(q, &v, 0.0, out).unwrap();
        for i in 0..3 {
            let (mut qp, mut qm) = (q, q);
            qp[i] += e;
            qm[i] -= e;
            let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
            lv(&qp, &mut a);
            lv(&qm, &mut b);
            for j in 0..3 {
                let d = (a[j] - b[j]) / (2.0 * e);
                assert!((h.qv[(i, j)] - d).abs() < 1e-7 * d.abs().max(1.0), "∂p_{j}/∂q_{i}");
            }
        }
        println!("q = {q:?}: largest relative gap to central differences {worst:.1e}");
    }
}

#[test]
fn the_velocity_inverts_the_legendre_transform_to_round_off() {
    let sys = top();
    for (q, v) in STATES {
        let (mut p, mut back, mut p_back) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        sys.dl_dv(&q, &v, 0.0, &mut p).unwrap();
        sys.velocity(&q, &p, 0.0, &mut back).unwrap();
        sys.dl_dv(&q, &back, 0.0, &mut p_back).unwrap();
        let scale = v.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        let gap = v.iter().zip(&back).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale;
        let p_gap = p.iter().zip(&p_back).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        println!("q = {q:?}: |Δq̇|/|q̇| = {gap:.1e}, |Δp| = {p_gap:.1e}");
        assert!(gap <= 1e-15, "{v:?} → {p:?} → {back:?}");
        assert!(p_gap <= 1e-15 * p.iter().fold(1.0_f64, |m, x| m.max(x.abs())));
    }
    // The energy function p·q̇ − L is the energy ½I₁(θ̇² + sin²θ φ̇²) + ½I₃ω₃² + Mgl cos θ.
    let (q, v) = STATES[0];
    let mut p = [0.0; 3];
    sys.dl_dv(&q, &v, 0.0, &mut p).unwrap();
    let (s, c) = q[0].sin_cos();
    let spin = v[2] + v[1] * c;
    let exact = 0.5 * 1.3 * (v[0] * v[0] + s * s * v[1] * v[1]) + 0.5 * 0.6 * spin * spin + 0.8 * c;
    assert!((sys.energy(&q, &p, 0.0).unwrap() - exact).abs() <= 1e-15 * exact.abs());
    // sin θ = 0 is refused by name, not divided by.
    let err = sys.velocity(&[0.0, 0.0, 0.0], &p, 0.0, &mut [0.0; 3]).unwrap_err();
    assert!(err.to_string().contains("singular"), "{err}");
}

#[test]
fn invalid_parameters_are_named() {
    for (args, name) in [
        ((0.0, 1.0, 1.0), "i1"),
        ((1.0, f64::NAN, 1.0), "i3"),
        ((1.0, 1.0, f64::INFINITY), "mgl"),
    ] {
        match HeavyTop::new(args.0, args.1, args.2) {
            Err(varmech::Error::InvalidArgument { argument, .. }) => assert_eq!(argument, name),
            other => panic!("{args:?}: expected an invalid {name}, got {other:?}"),
        }
    }
}

#[test]
fn midpoint_conserves_both_cyclic_momenta_to_round_off_and_bounds_the_energy() {
    let problem = HeavyTop::problem();
    let sys = &problem.system;
    let steps = 10_000;
    let traj = common::run_general(sys, &problem.initial, Method::Midpoint, 0.01, steps, 10).unwrap();
    for (generator, name) in sys.symmetries().into_iter().zip(["p_φ", "p_ψ"]) {
        let values: Vec<f64> = common::along(&traj, |q, p| generator.momentum(q, p));
        let stats = InvariantStatistics::new(&values);
        println!(
            "{name}: J₀ = {}, max relative error {:.2e}",
            stats.initial, stats.max_rel_error
        );
        assert!(stats.max_rel_error <= 1e-12, "{name}: {stats:?}");
    }
    let stats = common::energy_statistics(sys, &traj);
    let e = common::relative_energy_error(&energy(sys, &traj));
    println!("energy over {steps} steps of h = 0.01: {e:?}, {stats:?}");
    assert_eq!(stats.verdict, Verdict::Bounded, "{stats:?}");
    assert!(e.last_tenth <= 2.0 * e.first_tenth, "{e:?}");
    // O(h²) at h = 0.01: 2.8e-8 relative.
    assert!(e.max <= 1e-7, "{e:?}");
}

#[test]
fn midpoint_and_galerkin4_converge_at_their_orders_to_a_self_converged_galerkin6_reference() {
    let problem = HeavyTop::problem();
    let sys = &problem.system;
    let t = 10.0;
    let to_round_off = NewtonOptions {
        tolerance: 1e-16,
        ..NewtonOptions::default()
    };
    let run = |method: Method, steps: usize, newton: NewtonOptions| {
        let options = Options {
            save_every: steps,
            newton,
            ..Options::new(t / steps as f64, steps)
        };
        common::run_general_with(sys, &problem.initial, method, &options).unwrap_or_else(|e| panic!("{method:?}: {e}"))
    };
    let reference = run(Method::Galerkin6, 4000, to_round_off);
    let end = reference.len() - 1;
    let (q_ref, p_ref) = (reference.q_at(end), reference.p_at(end));
    let halved = run(Method::Galerkin6, 8000, to_round_off);
    let own = common::final_error(&halved, q_ref, p_ref);
    println!("Galerkin-6 reference at T = {t}: h = {} vs h/2: {own:.2e}", t / 4000.0);

    let mut smallest = f64::INFINITY;
    for (method, n0, order) in [(Method::Midpoint, 500, 2.0), (Method::Galerkin4, 250, 4.0)] {
        let errors: Vec<f64> = (0..4)
            .map(|k| common::final_error(&run(method, n0 << k, NewtonOptions::default()), q_ref, p_ref))
            .collect();
        smallest = smallest.min(errors[3]);
        common::assert_order(&format!("{method:?} at T = {t}"), &errors, order, 0.2);
    }
    // The reference's own error (round-off, 5e-13) is below 2% of the smallest error measured.
    assert!(own <= smallest / 50.0, "reference {own:e}, smallest error {smallest:e}");
}

#[test]
fn steady_precession_keeps_theta_constant() {
    let sys = HeavyTop::problem().system;
    let (theta, omega3) = (0.5, 5.0);
    let (slow, fast) = sys.steady_precession(theta, omega3).unwrap();
    println!("θ = {theta}, ω₃ = {omega3}: φ̇ = {slow} (slow), {fast} (fast)");
    assert!(slow.abs() < fast.abs());
    // Both roots of I₁cos θ φ̇² − I₃ω₃φ̇ + Mgl = 0.
    for rate in [slow, fast] {
        let residual = theta.cos() * rate * rate - 0.5 * omega3 * rate + 1.0;
        assert!(residual.abs() < 1e-14, "{rate}: {residual:e}");
    }
    let drift = |rate: f64| {
        let v = [0.0, rate, omega3 - rate * theta.cos()];
        let initial = state(&sys, [theta, 0.0, 0.0], v);
        let traj = common::run_general(&sys, &initial, Method::Midpoint, 0.01, 1000, 1).unwrap();
        thetas(&traj).iter().fold(0.0_f64, |m, x| m.max((x - theta).abs()))
    };
    for (name, rate) in [("slow", slow), ("fast", fast)] {
        let d = drift(rate);
        println!("{name} precession φ̇ = {rate}: max |θ − θ₀| over 10³ steps = {d:.1e}");
        assert!(d <= 1e-10, "{name}: {d:e}");
    }
    // A rate off by 1e-6, or the fast-top approximation Mgl/(I₃ω₃), nutates visibly.
    let off = drift(slow + 1e-6);
    let approximate = drift(1.0 / (0.5 * omega3));
    println!("φ̇ off by 1e-6: {off:.1e}; φ̇ = Mgl/(I₃ω₃): {approximate:.1e}");
    assert!(off > 1e-8 && approximate > 1e-3, "{off:e}, {approximate:e}");

    // No real rate when I₃²ω₃² < 4I₁Mgl cos θ (a slow top); θ = π/2 has one finite rate.
    assert_eq!(sys.steady_precession(0.5, 1.0), None);
    assert_eq!(sys.steady_precession(0.0, 5.0), None);
    let (slow, fast) = sys.steady_precession(std::f64::consts::FRAC_PI_2, 5.0).unwrap();
    assert!((slow - 1.0 / 2.5).abs() < 1e-15 && fast.abs() > 1e15, "{slow}, {fast}");
}

#[test]
fn the_turning_points_are_the_roots_of_the_cubic_around_the_motion() {
    let sys = top();
    let (i1, i3, mgl) = (1.3, 0.6, 0.8);
    for (q, v) in STATES {
        let initial = state(&sys, q, v);
        let e = sys.energy(&initial.q, &initial.p, 0.0).unwrap();
        let (p_phi, p_psi) = (initial.p[1], initial.p[2]);
        let (theta_min, theta_max) = sys.turning_points(p_phi, p_psi, e).unwrap();
        // The state lies inside its band, and both ends are roots of u̇² = f(u).
        assert!(
            theta_min < q[0] && q[0] < theta_max,
            "{q:?}: [{theta_min}, {theta_max}]"
        );
        let (alpha, beta, a, b) = (
            (2.0 * e - p_psi * p_psi / i3) / i1,
            2.0 * mgl / i1,
            p_psi / i1,
            p_phi / i1,
        );
        let f = |u: f64| (1.0 - u * u) * (alpha - beta * u) - (b - a * u).powi(2);
        let df = |u: f64| -2.0 * u * (alpha - beta * u) - beta * (1.0 - u * u) + 2.0 * a * (b - a * u);
        for theta in [theta_min, theta_max] {
            let u = theta.cos();
            // f vanishes to the round-off of its evaluation, and u to that over |f′(u)|.
            let scale = alpha.abs() + beta.abs() + (a * a + b * b);
            assert!(f(u).abs() <= 1e-14 * scale, "f({u}) = {:e}", f(u));
            println!(
                "q = {q:?}: θ = {theta}, f(cos θ) = {:.1e}, δu ≈ {:.1e}",
                f(u),
                f(u).abs() / df(u).abs()
            );
        }
        // Less energy than the bottom of the effective potential: no motion.
        assert_eq!(sys.turning_points(p_phi, p_psi, e - 100.0), None);
    }

    // In steady precession the two turning points meet (a double root: to about √ε).
    let (theta, omega3) = (0.5, 5.0);
    let (slow, _) = HeavyTop::problem().system.steady_precession(theta, omega3).unwrap();
    let problem_top = HeavyTop::problem().system;
    let s = state(
        &problem_top,
        [theta, 0.0, 0.0],
        [0.0, slow, omega3 - slow * theta.cos()],
    );
    let e = problem_top.energy(&s.q, &s.p, 0.0).unwrap();
    let (lo, hi) = problem_top.turning_points(s.p[1], s.p[2], e).unwrap();
    println!("steady precession at θ = {theta}: turning points {lo}, {hi}");
    assert!((lo - theta).abs() < 1e-7 && (hi - theta).abs() < 1e-7, "{lo}, {hi}");

    // Released with θ̇₀ = φ̇₀ = 0 at u₀ = cos θ₀, f(u) = (u₀ − u)[β(1 − u²) − a²(u₀ − u)]: the
    // lower turning point solves βu² − a²u + a²u₀ − β = 0 in closed form.
    let problem = HeavyTop::problem();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let (theta_min, theta_max) = problem
        .system
        .turning_points(p0[1], p0[2], problem.system.energy(q0, p0, 0.0).unwrap())
        .unwrap();
    let (beta, a2, u0) = (2.0, 2.5_f64 * 2.5, q0[0].cos());
    let u1 = (a2 - (a2 * a2 - 4.0 * beta * (a2 * u0 - beta)).sqrt()) / (2.0 * beta);
    println!(
        "problem: θ_min = {theta_min}, θ_max = {theta_max}, closed form θ_max = {}",
        u1.acos()
    );
    assert!((theta_min - 0.3).abs() < 1e-14, "{theta_min}");
    assert!((theta_max - u1.acos()).abs() < 1e-14, "{theta_max} vs {}", u1.acos());
}

/// [`HeavyTop::problem`], its energy and the turning points (θ_min, θ_max) of its initial state
/// ([`HeavyTop::turning_points`]), printed.
pub(crate) fn released_top() -> (Problem<HeavyTop>, f64, (f64, f64)) {
    let problem = HeavyTop::problem();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let energy = problem.system.energy(q0, p0, 0.0).unwrap();
    let (theta_min, theta_max) = problem.system.turning_points(p0[1], p0[2], energy).unwrap();
    println!("turning points: θ_min = {theta_min:.12}, θ_max = {theta_max:.12}");
    (problem, energy, (theta_min, theta_max))
}

/// The run of [`HeavyTop::problem`] stays in the band [θ_min, θ_max] of
/// [`HeavyTop::turning_points`] and reaches both ends, each to O(h²): the midpoint rule keeps
/// p_φ and p_ψ exactly and a modified energy E + O(h²), and the saved states sample each turn
/// within h/2 of its extremum. Tolerance 0.02h² for both (measured at h = 0.02, 0.01, 0.005:
/// no excursion outside the band beyond 1.3e-15, and the largest θ short of θ_max by 0.0100h²).
#[test]
fn the_unreduced_midpoint_run_fills_the_nutation_band_of_the_turning_points() {
    let (problem, _, (theta_min, theta_max)) = released_top();
    let (sys, q0) = (&problem.system, &problem.initial.q);
    // Released with θ̇₀ = 0, θ₀ is a turning point (the upper one: φ̇₀ = 0 makes the cusps).
    assert!((theta_min - q0[0]).abs() < 1e-14, "{theta_min}");

    let mut short_of_max = Vec::new();
    for h in [0.02, 0.01, 0.005] {
        let steps = (problem.t_end / h).round() as usize;
        let traj = common::run_general(sys, &problem.initial, Method::Midpoint, h, steps, 1).unwrap();
        let theta = thetas(&traj);
        let tol = 0.02 * h * h;
        let lowest = theta.iter().copied().fold(f64::INFINITY, f64::min);
        let highest = theta.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // θ₀ = θ_min itself does not count as reaching θ_min: over the second half of the run.
        let later = &theta[theta.len() / 2..];
        let later_lowest = later.iter().copied().fold(f64::INFINITY, f64::min);
        // Nutations: upward crossings of the middle of the band.
        let middle = 0.5 * (theta_min + theta_max);
        let nutations = theta.windows(2).filter(|w| w[0] < middle && w[1] >= middle).count();
        println!(
            "h = {h}: θ_min − min θ = {:.2e}, max θ − θ_max = {:.2e}; over the second half θ_min is reached to {:.2e}, \
             θ_max to {:.2e} (= {:.4}h²); {nutations} nutations by T = {}",
            theta_min - lowest,
            highest - theta_max,
            later_lowest - theta_min,
            theta_max - highest,
            (theta_max - highest) / (h * h),
            problem.t_end
        );
        assert!(
            lowest >= theta_min - tol && highest <= theta_max + tol,
            "h = {h}: [{lowest}, {highest}]"
        );
        assert!((later_lowest - theta_min).abs() <= tol, "h = {h}: {later_lowest}");
        assert!((highest - theta_max).abs() <= tol, "h = {h}: {highest}");
        short_of_max.push((theta_max - highest).abs());
    }
    // The distance to θ_max falls like h².
    common::assert_order("max θ short of θ_max", &short_of_max, 2.0, 0.3);
}
