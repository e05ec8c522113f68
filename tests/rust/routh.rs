//! Routh reduction: the Routhian R = L − μ·ċ of a model with cyclic coordinates, integrated by
//! the DEL integrators, against closed forms, relative equilibria and the unreduced model.

use crate::common::{self, IMPLICIT};

use varmech::discrete::{DiscreteLagrangian, Midpoint, Trapezoidal};
use varmech::integrators::{integrate, Method, Options, Trajectory};
use varmech::model::{Hessians, Lagrangian, Routhian};
use varmech::scenes::{self, HeavyTop, SphericalPendulum, State};

/// The spherical pendulum (m = l = g = 1) and its Routhian at p_φ = μ.
fn spherical(mu: f64) -> (SphericalPendulum, f64) {
    (SphericalPendulum::new(1.0, 1.0, 1.0).unwrap(), mu)
}

/// Integrates the reduced model from (x₀, p_x₀), saving every state.
fn run_reduced<L: Lagrangian + ?Sized>(
    r: &Routhian<L>,
    x0: &[f64],
    px0: &[f64],
    method: Method,
    h: f64,
    steps: usize,
) -> Trajectory {
    let initial = State {
        t: 0.0,
        q: x0.to_vec(),
        p: px0.to_vec(),
    };
    common::run_general(r, &initial, method, h, steps, 1).unwrap()
}

/// The ignored coordinates along a reduced trajectory, from c₀ and the increments.
fn reconstruct<L: Lagrangian + ?Sized>(
    r: &Routhian<L>,
    traj: &Trajectory,
    c0: &[f64],
    method: Method,
) -> Vec<Vec<f64>> {
    let rule = match method {
        Method::Midpoint => Some(Midpoint.quadrature()),
        Method::Trapezoid => Some(Trapezoidal.quadrature()),
        _ => None,
    };
    let increments = r.cyclic_increments(&traj.t, &traj.q, &traj.p, rule).unwrap();
    let mut c = vec![c0.to_vec()];
    for d in increments.chunks_exact(c0.len()) {
        let next = c.last().unwrap().iter().zip(d).map(|(a, b)| a + b).collect();
        c.push(next);
    }
    c
}

#[test]
fn the_spherical_pendulums_routhian_is_its_closed_form() {
    let (sys, mu) = spherical(0.8496881019282854);
    let r = Routhian::new(&sys, &[1], &[mu], &[0.0]).unwrap();
    let mut out = [0.0];
    for (theta, thetadot) in [(1.0, 0.0), (0.4, -0.7), (2.5, 1.3)] {
        let s2 = f64::sin(theta).powi(2);
        let exact = 0.5 * thetadot * thetadot - mu * mu / (2.0 * s2) + f64::cos(theta);
        let value = r.lagrangian(&[theta], &[thetadot], 0.0).unwrap();
        assert!((value - exact).abs() <= 1e-14, "R = {value}, closed form {exact}");
        let amended = r.amended_potential(&[theta], 0.0).unwrap();
        assert!((amended - (mu * mu / (2.0 * s2) - f64::cos(theta))).abs() <= 1e-14);
        r.cyclic_velocity(&[theta], &[thetadot], 0.0, &mut out).unwrap();
        assert!((out[0] - mu / s2).abs() <= 1e-14 * out[0].abs());
        // ∂R/∂θ = μ² cos θ / sin³θ − sin θ, ∂R/∂θ̇ = θ̇.
        r.dl_dq(&[theta], &[thetadot], 0.0, &mut out).unwrap();
        let exact = mu * mu * theta.cos() / (s2 * theta.sin()) - theta.sin();
        assert!(
            (out[0] - exact).abs() <= 1e-13 * exact.abs().max(1.0),
            "{} vs {exact}",
            out[0]
        );
        r.dl_dv(&[theta], &[thetadot], 0.0, &mut out).unwrap();
        assert!((out[0] - thetadot).abs() <= 1e-15);
        // The energy of R is that of L: ½θ̇² + V_μ(θ).
        let e = r.energy(&[theta], &[thetadot], 0.0).unwrap();
        assert!((e - (0.5 * thetadot * thetadot + amended)).abs() <= 1e-14);
    }
}

#[test]
fn the_conical_pendulum_is_a_fixed_point_of_every_reduced_map() {
    // φ̇² = g/(l cos θ*) at rest in θ: p_φ = sin²θ* φ̇ puts θ* at a critical point of V_μ.
    let theta = 0.8_f64;
    let phidot = (1.0 / theta.cos()).sqrt();
    let (sys, mu) = spherical(theta.sin().powi(2) * phidot);
    for (factor, moves) in [(1.0, false), (1.0 + 1e-6, true)] {
        let r = Routhian::new(&sys, &[1], &[mu * factor], &[0.0]).unwrap();
        for method in IMPLICIT {
            let traj = run_reduced(&r, &[theta], &[0.0], method, 0.1, 1000);
            let drift = traj.q.iter().map(|x| (x - theta).abs()).fold(0.0, f64::max);
            if moves {
                assert!(drift > 1e-7, "{method:?}: a perturbed μ must move θ, moved {drift:e}");
                continue;
            }
            assert!(drift <= 1e-13, "{method:?}: θ moves by {drift:e}");
            // φ turns uniformly at φ̇: exactly for the two-point rules, to O(h⁵) per step for
            // the Hermite reconstruction (here exact too: θ is constant).
            let phi = reconstruct(&r, &traj, &[0.0], method);
            let err = (phi.last().unwrap()[0] - phidot * 100.0).abs();
            assert!(err <= 1e-11, "{method:?}: φ(100) off by {err:e}");
        }
    }
}

/// The (θ, φ) trajectory of the full spherical pendulum, saving every state.
fn run_full(method: Method, h: f64, steps: usize) -> Trajectory {
    let problem = SphericalPendulum::problem();
    common::run_general(&problem.system, &problem.initial, method, h, steps, 1).unwrap()
}

#[test]
fn reduce_then_discretize_is_discretize_then_reduce_for_the_midpoint_rule_only() {
    // Discretize-then-reduce: the unreduced DEL map on J = μ (its θ-equations are the discrete
    // Routhian's, R_d = L_d − μΔφ; Jalnapurkar, Leok, Marsden & West 2006). Reduce-then-
    // discretize: the DEL map of R. For the midpoint rule both are h·R at the midpoint.
    let problem = SphericalPendulum::problem();
    let mu = problem.initial.p[1];
    let r = Routhian::new(&problem.system, &[1], &[mu], &[0.0]).unwrap();
    let differences = |method: Method, h: f64| {
        let steps = (10.0 / h).round() as usize;
        let full = run_full(method, h, steps);
        let reduced = run_reduced(&r, &[1.0], &[0.0], method, h, steps);
        let phi = reconstruct(&r, &reduced, &[0.0], method);
        (0..full.len())
            .map(|k| {
                let dtheta = (full.q_at(k)[0] - reduced.q[k]).abs();
                let dp = (full.p_at(k)[0] - reduced.p[k]).abs();
                let dphi = (full.q_at(k)[1] - phi[k][0]).abs();
                dtheta.max(dp).max(dphi)
            })
            .fold(0.0, f64::max)
    };
    let midpoint = differences(Method::Midpoint, 0.01);
    println!("midpoint: reduced and unreduced differ by {midpoint:.2e} over 1000 steps");
    assert!(midpoint <= 1e-12, "midpoint: {midpoint:e}");
    // The trapezoid averages ∂L/∂φ̇ over the ends with one φ̇ (discrete), or φ̇ at each end
    // (reduced): two second-order maps that differ at O(h²). Galerkin-4 likewise at O(h⁴).
    for (method, order) in [(Method::Trapezoid, 2.0), (Method::Galerkin4, 4.0)] {
        let d: Vec<f64> = [0.04, 0.02, 0.01].iter().map(|&h| differences(method, h)).collect();
        common::assert_order(&format!("{method:?}: reduced − unreduced"), &d, order, 0.3);
    }
}

#[test]
fn three_models_of_the_spherical_pendulum_reach_the_reference_at_their_order() {
    // Cartesian with a constraint (RATTLE), angles (θ, φ), and θ alone with φ reconstructed.
    let problem = SphericalPendulum::problem();
    let (reference, _) = problem.reference.as_ref().unwrap();
    let mu = problem.initial.p[1];
    let r = Routhian::new(&problem.system, &[1], &[mu], &[0.0]).unwrap();
    let angle_error = |theta: f64, phi: f64| (theta - reference.q[0]).hypot(phi - reference.q[1]);
    for (method, order) in [(Method::Midpoint, 2.0), (Method::Galerkin4, 4.0)] {
        let (mut full, mut reduced) = (vec![], vec![]);
        for k in 0..4 {
            let steps = 1000 << k;
            let h = reference.t / steps as f64;
            let traj = run_full(method, h, steps);
            let q = traj.q_at(traj.len() - 1);
            full.push(angle_error(q[0], q[1]));
            let traj = run_reduced(&r, &[1.0], &[0.0], method, h, steps);
            let phi = reconstruct(&r, &traj, &[0.0], method);
            reduced.push(angle_error(*traj.q.last().unwrap(), phi.last().unwrap()[0]));
        }
        common::assert_order(&format!("{method:?}, (θ, φ)"), &full, order, 0.3);
        common::assert_order(&format!("{method:?}, θ reduced, φ reconstructed"), &reduced, order, 0.3);
    }
    let cartesian = scenes::cartesian_spherical_pendulum();
    let errors: Vec<f64> = (0..4)
        .map(|k| {
            let steps = 2000 << k;
            let options = Options::new(50.0 / steps as f64, steps);
            let (q0, p0) = (&cartesian.initial.q, &cartesian.initial.p);
            let traj = integrate(&cartesian.system, Method::Rattle, q0, p0, &options, || Ok(())).unwrap();
            let q = traj.q_at(traj.len() - 1);
            let (theta, phi) = ((-q[2]).acos(), q[1].atan2(q[0]));
            // φ is known modulo 2π in Cartesian coordinates.
            let turns = ((reference.q[1] - phi) / std::f64::consts::TAU).round();
            angle_error(theta, phi + turns * std::f64::consts::TAU)
        })
        .collect();
    common::assert_order("Rattle, Cartesian", &errors, 2.0, 0.3);
}

/// The momenta (p_φ, p_ψ) of the top's state at θ with velocities (θ̇, φ̇, ψ̇).
fn top_momenta(top: &HeavyTop, theta: f64, v: [f64; 3]) -> Vec<f64> {
    let mut p = vec![0.0; 3];
    top.dl_dv(&[theta, 0.0, 0.0], &v, 0.0, &mut p).unwrap();
    p[1..].to_vec()
}

#[test]
fn steady_precession_of_the_top_is_a_fixed_point_of_every_reduced_map() {
    // Goldstein's condition Mgl = φ̇(I₃ω₃ − I₁φ̇ cos θ), solved independently of the Routhian.
    let top = HeavyTop::new(1.0, 0.5, 1.0).unwrap();
    let (theta, omega3) = (0.5_f64, 5.0);
    let (slow, fast) = top.steady_precession(theta, omega3).unwrap();
    for phidot in [slow, fast] {
        let psidot = omega3 - phidot * theta.cos();
        let mu = top_momenta(&top, theta, [0.0, phidot, psidot]);
        let r = Routhian::new(&top, &[1, 2], &mu, &[0.0, 0.0]).unwrap();
        // θ* is a critical point of the amended potential.
        let e = 1e-5;
        let slope = (r.amended_potential(&[theta + e], 0.0).unwrap() - r.amended_potential(&[theta - e], 0.0).unwrap())
            / (2.0 * e);
        assert!(slope.abs() <= 1e-8, "V_μ'(θ*) = {slope:e}");
        for method in IMPLICIT {
            let traj = run_reduced(&r, &[theta], &[0.0], method, 0.01, 500);
            let drift = traj.q.iter().map(|x| (x - theta).abs()).fold(0.0, f64::max);
            assert!(drift <= 1e-12, "{method:?}, φ̇ = {phidot}: θ moves by {drift:e}");
            let angles = reconstruct(&r, &traj, &[0.0, 0.0], method);
            let last = angles.last().unwrap();
            let err = (last[0] - 5.0 * phidot).abs().max((last[1] - 5.0 * psidot).abs());
            assert!(
                err <= 1e-11 * (5.0 * phidot).abs().max(1.0),
                "{method:?}: (φ, ψ)(5) off by {err:e}"
            );
        }
    }
}

#[test]
fn the_reduced_top_nutates_between_the_turning_points_of_its_effective_energy() {
    let (problem, energy, (theta_min, theta_max)) = crate::heavy_top::released_top();
    let (top, q0, p0) = (&problem.system, &problem.initial.q, &problem.initial.p);
    let r = Routhian::new(top, &[1, 2], &p0[1..], &[0.0, 0.0]).unwrap();
    let reduced_energy = r.energy(&q0[..1], &p0[..1], 0.0).unwrap();
    assert!((reduced_energy - energy).abs() <= 1e-14 * energy.abs());
    // Measured: midpoint (h = 0.01) 1.0e-6 off θ_max, energy band 2e-7; Galerkin-4 (h = 0.005)
    // 3.5e-9 and 1.7e-13. θ_min = θ₀ is met to round-off.
    let cases = [
        (Method::Midpoint, 0.01, 1e-5, 1e-6),
        (Method::Galerkin4, 0.005, 2e-8, 1e-12),
    ];
    for (method, h, tolerance, energy_tolerance) in cases {
        let steps = (problem.t_end / h).round() as usize;
        let traj = run_reduced(&r, &q0[..1], &p0[..1], method, h, steps);
        let (lo, hi) = traj
            .q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        println!(
            "{method:?}, h = {h}: θ ∈ [{lo:.9}, {hi:.9}], off by {:.1e} and {:.1e}",
            lo - theta_min,
            hi - theta_max
        );
        assert!((lo - theta_min).abs() <= tolerance && (hi - theta_max).abs() <= tolerance);
        let e: Vec<f64> = (0..traj.len())
            .map(|k| r.energy(&traj.q[k..k + 1], &traj.p[k..k + 1], 0.0).unwrap())
            .collect();
        let band = e.iter().map(|x| (x - energy).abs()).fold(0.0, f64::max);
        println!("{method:?}: energy band {band:.1e}");
        assert!(band <= energy_tolerance, "{method:?}: energy band {band:e}");
    }
}

#[test]
fn ignoring_the_spin_alone_keeps_a_gyroscopic_coupling_with_exact_hessians() {
    // Ignore ψ only: R(θ, φ) has M_φψ = I₃ cos θ ≠ 0, so ∂²L/∂φ̇∂ψ̇ enters every Schur
    // complement. The exact Hessians of R match differences of its exact first derivatives.
    let problem = HeavyTop::problem();
    let top = &problem.system;
    let r = Routhian::new(top, &[2], &problem.initial.p[2..], &[0.0]).unwrap();
    let (x, v) = ([0.4, 0.3], [0.2, -0.7]);
    let mut exact = Hessians::zeros(2);
    assert!(r.hessians(&x, &v, 0.0, &mut exact).unwrap());
    let (mut plus, mut minus) = ([0.0; 2], [0.0; 2]);
    let e = 1e-6;
    for j in 0..2 {
        for (slot, block) in [(0, 0), (1, 1)] {
            // slot 0 perturbs x, slot 1 perturbs ẋ; rows from ∂R/∂x (qq, qv) and ∂R/∂ẋ (vv).
            let (mut xp, mut vp, mut xm, mut vm) = (x, v, x, v);
            if slot == 0 {
                xp[j] += e;
                xm[j] -= e;
            } else {
                vp[j] += e;
                vm[j] -= e;
            }
            for (derivative, matrix) in [(0, if block == 0 { &exact.qq } else { &exact.qv }), (1, &exact.vv)] {
                if derivative == 1 && slot == 0 {
                    continue;
                }
                if derivative == 0 {
                    r.dl_dq(&xp, &vp, 0.0, &mut plus).unwrap();
                    r.dl_dq(&xm, &vm, 0.0, &mut minus).unwrap();
                } else {
                    r.dl_dv(&xp, &vp, 0.0, &mut plus).unwrap();
                    r.dl_dv(&xm, &vm, 0.0, &mut minus).unwrap();
                }
                for i in 0..2 {
                    let differenced = (plus[i] - minus[i]) / (2.0 * e);
                    assert!(
                        (differenced - matrix[(i, j)]).abs() <= 1e-7 * differenced.abs().max(1.0),
                        "block {block}, derivative {derivative}, ({i}, {j}): {differenced} vs {}",
                        matrix[(i, j)]
                    );
                }
            }
        }
    }
    // And the midpoint rule on R is the midpoint rule on L, to round-off.
    let full = common::run_general(top, &problem.initial, Method::Midpoint, 0.01, 1000, 1).unwrap();
    let traj = run_reduced(
        &r,
        &problem.initial.q[..2],
        &problem.initial.p[..2],
        Method::Midpoint,
        0.01,
        1000,
    );
    let psi = reconstruct(&r, &traj, &[0.0], Method::Midpoint);
    let diff = (0..full.len())
        .map(|k| {
            let (qf, qr) = (full.q_at(k), &traj.q[2 * k..2 * k + 2]);
            (qf[0] - qr[0])
                .abs()
                .max((qf[1] - qr[1]).abs())
                .max((qf[2] - psi[k][0]).abs())
        })
        .fold(0.0, f64::max);
    assert!(diff <= 1e-11, "reduced and unreduced midpoint differ by {diff:e}");
}
