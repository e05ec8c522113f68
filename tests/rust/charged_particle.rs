//! A charged particle in a magnetic field normal to the plane, L = ½|q̇|² + A(q)·q̇: the gyration
//! phase of the midpoint rule in a uniform field, the absence of a parasitic mode in the
//! trapezoidal rule, the discrete Noether theorem for the rotation about the origin, and the
//! orders of the implicit methods in a non-uniform field.

use crate::common;

use common::InvariantStatistics;
use varmech::integrators::{Method, Trajectory};
use varmech::model::Lagrangian;
use varmech::scenes::{ChargedParticle, Problem};

fn run(problem: &Problem<ChargedParticle>, method: Method, h: f64, steps: usize, save_every: usize) -> Trajectory {
    common::run_general(&problem.system, &problem.initial, method, h, steps, save_every)
        .unwrap_or_else(|e| panic!("{method:?} failed: {e}"))
}

/// The largest |a − b| over all saved positions of two runs.
fn max_position_difference(a: &Trajectory, b: &Trajectory) -> f64 {
    (0..a.len())
        .flat_map(|k| a.q_at(k).iter().zip(b.q_at(k)).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn midpoint_gyrates_by_two_arctan_half_h_omega_a_step_at_every_step_size() {
    // On q̈ = Ω(q̇_y, −q̇_x) the midpoint rule is the Cayley transform of the rotation: from the
    // exact circle's initial state it stays on the unit circle and turns by 2·arctan(hΩ/2).
    let problem = ChargedParticle::uniform_field(2.0).unwrap();
    let omega = problem.system.gyrofrequency();
    for h in [0.01, 0.1, 0.5, 1.0, 2.0, 3.0] {
        let traj = run(&problem, Method::Midpoint, h, 1000, 1);
        let turn = -2.0 * (0.5 * h * omega).atan();
        let (mut phase, mut radius) = (0.0_f64, 0.0_f64);
        for k in 0..traj.len() - 1 {
            let (a, b) = (traj.q_at(k), traj.q_at(k + 1));
            let step = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
            phase = phase.max((step - turn).abs());
            radius = radius.max((a[0].hypot(a[1]) - 1.0).abs());
        }
        println!("h = {h}: turn {turn:.15} a step, max phase error {phase:.2e}, max radius error {radius:.2e}");
        assert!(
            phase <= 1e-12 && radius <= 1e-12,
            "h = {h}: phase {phase:e}, radius {radius:e}"
        );
    }
}

#[test]
fn trapezoid_equals_midpoint_in_a_uniform_field() {
    // A is linear in q and there is no potential, so ½[L(q₀, v) + L(q₁, v)] = L(q̄, v): the two
    // discrete Lagrangians, and so their trajectories, coincide.
    let problem = ChargedParticle::uniform_field(2.0).unwrap();
    for h in [0.1, 1.0] {
        let a = run(&problem, Method::Midpoint, h, 1000, 1);
        let b = run(&problem, Method::Trapezoid, h, 1000, 1);
        let diff = max_position_difference(&a, &b);
        println!("h = {h}: max |q_midpoint − q_trapezoid| = {diff:.2e}");
        assert!(diff <= 1e-13, "h = {h}: {diff:e}");
    }
}

/// The alternating (period-2) part of the second differences d_k = q_{k+1} − 2q_k + q_{k−1},
/// relative to their size h²|q̈|: max |d_k − ½(d_{k−1} + d_{k+1})| / (2 max |d_k|). A smooth
/// d_k leaves O(h²) here; a parasitic mode (−1)^k r leaves r/(h²|q̈|).
fn alternating_part(traj: &Trajectory) -> f64 {
    let d: Vec<[f64; 2]> = (1..traj.len() - 1)
        .map(|k| {
            let (a, b, c) = (traj.q_at(k - 1), traj.q_at(k), traj.q_at(k + 1));
            [a[0] - 2.0 * b[0] + c[0], a[1] - 2.0 * b[1] + c[1]]
        })
        .collect();
    let size = d.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    let alternating = d
        .windows(3)
        .flat_map(|w| (0..2).map(move |i| (w[1][i] - 0.5 * (w[0][i] + w[2][i])).abs()))
        .fold(0.0, f64::max);
    alternating / (2.0 * size)
}

#[test]
fn trapezoid_has_no_parasitic_oscillation_in_a_non_uniform_field() {
    // L is regular, so the discrete Euler–Lagrange equations are a one-step map on (q, p): there
    // is no second, period-2 solution to excite. The alternating part of the second differences
    // is the O(h²) curvature of a smooth sequence, and shrinks at order 2.
    let problem = ChargedParticle::nonuniform_field();
    let t_end = 20.0;
    let runs: Vec<Trajectory> = (0..4)
        .map(|k| {
            let steps = 200 << k;
            run(&problem, Method::Trapezoid, t_end / steps as f64, steps, 1)
        })
        .collect();
    let parts: Vec<f64> = runs.iter().map(alternating_part).collect();
    assert!(parts[0] < 1e-2, "{parts:?}");
    common::assert_order("alternating part / h²|q̈|", &parts, 2.0, 0.3);
    // The measure would see a period-2 mode of amplitude 1e-7 on the finest run.
    let mut planted = runs[3].clone();
    for (k, q) in planted.q.chunks_exact_mut(2).enumerate() {
        q[0] += if k % 2 == 0 { 1e-7 } else { -1e-7 };
    }
    let seen = alternating_part(&planted);
    println!("with a planted (−1)^k·1e-7: {seen:.3e}");
    assert!(seen > 10.0 * parts[3], "{seen:e}");
}

#[test]
fn every_implicit_method_conserves_the_canonical_angular_momentum_to_round_off() {
    // Discrete Noether: every L_d here is invariant under rotations about the origin, so J
    // changes only by the rounding of each step's momentum increment, ~ε·h|∂L/∂q||q| = 5e-18.
    // From this state at h = 0.05 that rounding is biased and J drifts linearly, to 1.0e-12
    // (midpoint) and 1.4e-12 (trapezoid) after 10⁵ steps; from other states it random-walks
    // to ~1e-13. The energy error is O(h²) and stays in its band.
    let problem = ChargedParticle::nonuniform_field();
    let rotation = problem.system.symmetries()[0];
    let steps = 100_000;
    for method in crate::common::IMPLICIT {
        let traj = run(&problem, method, 0.05, steps, 10);
        let j: Vec<f64> = common::along(&traj, |q, p| rotation.momentum(q, p));
        let stats = InvariantStatistics::new(&j);
        let e: Vec<f64> = common::along(&traj, |q, p| problem.system.energy(q, p, 0.0).unwrap());
        let energy = common::energy_statistics(&problem.system, &traj);
        println!(
            "{method:?}: J0 = {}, max |ΔJ/J| = {:.2e}; max |ΔE|/⟨T⟩ = {:.2e} ({:?})",
            stats.initial, stats.max_rel_error, energy.max_rel_error, energy.verdict
        );
        assert!((stats.initial + 0.4375).abs() < 1e-15 && (e[0] - 0.5).abs() < 1e-15);
        assert!(
            stats.max_rel_error <= 2e-12,
            "{method:?}: J error {:e}",
            stats.max_rel_error
        );
        assert!(common::conserved(energy.verdict), "{method:?}: {energy:?}");
    }
}

#[test]
fn midpoint_and_galerkin4_converge_at_orders_two_and_four_in_a_non_uniform_field() {
    let problem = ChargedParticle::nonuniform_field();
    let t_end = 10.0;
    let at_end = |method, steps: usize| run(&problem, method, t_end / steps as f64, steps, steps);
    // The reference: Galerkin-6 at h = 0.005, self-converged to round-off.
    let reference = at_end(Method::Galerkin6, 2000);
    let check = at_end(Method::Galerkin6, 1000);
    let (q_ref, p_ref) = (reference.q_at(1), reference.p_at(1));
    let own = common::final_error(&check, q_ref, p_ref);
    println!("Galerkin-6 reference: h vs h/2 differ by {own:.2e}");
    assert!(own < 1e-13, "{own:e}");
    for (method, n0) in [(Method::Midpoint, 200), (Method::Galerkin4, 25)] {
        common::assert_method_order(method, n0, 3, |steps| {
            common::final_error(&at_end(method, steps), q_ref, p_ref)
        });
    }
}

#[test]
fn midpoint_reaches_the_exact_gyration_at_order_two() {
    let problem = ChargedParticle::uniform_field(1.0).unwrap();
    let (reference, _) = problem.reference.as_ref().unwrap();
    let errors: Vec<f64> = (0..4)
        .map(|k| {
            let steps = 100 << k;
            let traj = run(&problem, Method::Midpoint, problem.t_end / steps as f64, steps, steps);
            common::final_error(&traj, &reference.q, &reference.p)
        })
        .collect();
    common::assert_order("midpoint", &errors, 2.0, 0.05);
}

#[test]
fn exact_derivatives_match_central_differences_and_the_velocity_inverts_the_momentum() {
    use varmech::solve::difference::central_gradient;
    let sys = ChargedParticle::nonuniform_field().system;
    let (q, v) = ([0.7, -1.3], [0.4, 2.1]);
    let (mut exact, mut approx, mut work) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    sys.dl_dq(&q, &v, 0.0, &mut exact).unwrap();
    central_gradient(|x| sys.lagrangian(x, &v, 0.0), &q, &mut work, &mut approx).unwrap();
    assert!(
        exact.iter().zip(&approx).all(|(a, b)| (a - b).abs() < 1e-9),
        "{exact:?} vs {approx:?}"
    );
    sys.dl_dv(&q, &v, 0.0, &mut exact).unwrap();
    central_gradient(|x| sys.lagrangian(&q, x, 0.0), &v, &mut work, &mut approx).unwrap();
    assert!(
        exact.iter().zip(&approx).all(|(a, b)| (a - b).abs() < 1e-9),
        "{exact:?} vs {approx:?}"
    );
    let mut back = [0.0; 2];
    sys.velocity(&q, &exact, 0.0, &mut back).unwrap();
    assert!(
        back.iter().zip(&v).all(|(a, b)| (a - b).abs() < 1e-15),
        "{back:?} vs {v:?}"
    );
}

#[test]
fn parameters_are_validated_by_name() {
    for (result, name) in [
        (ChargedParticle::new(0.0, 1.0, 1.0, 0.0), "m"),
        (ChargedParticle::new(1.0, f64::NAN, 1.0, 0.0), "charge"),
        (ChargedParticle::new(1.0, 1.0, f64::INFINITY, 0.0), "B"),
        (ChargedParticle::new(1.0, 1.0, 1.0, f64::NAN), "kappa"),
    ] {
        match result {
            Err(varmech::Error::InvalidArgument { argument, .. }) => assert_eq!(argument, name),
            other => panic!("{name}: expected an invalid argument, got {other:?}"),
        }
    }
}
