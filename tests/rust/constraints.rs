//! Holonomic constraints: RATTLE holds g(q) = 0 and G(q)M⁻¹p = 0 to round-off and stays
//! symplectic; SHAKE with a loose tolerance drifts in energy; compositions raise the order.

use crate::common;

use varmech::integrators::{integrate, Dynamics, General, Method, Options, Trajectory};
use varmech::model::Lagrangian;
use varmech::model::{Constrained, Distances, Residuals};
use varmech::scenes::{self, LinkedMasses, Pendulum, PointMasses, Problem, RigidBody};
use varmech::Error;

fn run(
    p: &Problem<LinkedMasses>,
    method: Method,
    h: f64,
    steps: usize,
    save_every: usize,
    tolerance: Option<f64>,
) -> Trajectory {
    let mut options = Options {
        save_every,
        ..Options::new(h, steps)
    };
    if let Some(tolerance) = tolerance {
        options.newton.tolerance = tolerance;
    }
    integrate(&p.system, method, &p.initial.q, &p.initial.p, &options, || Ok(()))
        .unwrap_or_else(|f| panic!("{method:?}: {}", f.error))
}

/// max over the saved states of |g(q)|∞ and |G(q)M⁻¹p|∞.
fn residuals(sys: &LinkedMasses, traj: &Trajectory) -> (f64, f64) {
    (0..traj.len())
        .map(|k| sys.constraint_residuals(traj.q_at(k), traj.p_at(k)).unwrap().unwrap())
        .fold((0.0, 0.0), |(a, b), r| (a.max(r.position), b.max(r.velocity)))
}

/// The energy errors H − H₀ at the saved states, and their least-squares slope in t.
fn energy_drift(sys: &LinkedMasses, traj: &Trajectory) -> (f64, f64) {
    let e: Vec<f64> = common::along(traj, |q, p| varmech::model::hamiltonian(&sys.system, q, p).unwrap());
    let errors: Vec<f64> = e.iter().map(|x| x - e[0]).collect();
    let n = errors.len() as f64;
    let (mt, me) = (traj.t.iter().sum::<f64>() / n, errors.iter().sum::<f64>() / n);
    let cov: f64 = traj.t.iter().zip(&errors).map(|(t, e)| (t - mt) * (e - me)).sum();
    let var: f64 = traj.t.iter().map(|t| (t - mt).powi(2)).sum();
    (errors.iter().fold(0.0, |a, x| a.max(x.abs())), cov / var)
}

#[test]
fn rattle_holds_the_cartesian_pendulum_on_its_constraints_to_round_off() {
    // reference/scenes.json: h = 0.1, T = 10⁴; RATTLE to 1e-15 keeps both residuals ≤ 1e-15,
    // a maximal energy error of 0.0061 and a drift below 1e-9 per unit time.
    let p = scenes::cartesian_pendulum();
    let steps = 100_000;
    let traj = run(&p, Method::Rattle, 0.1, steps, 10, None);
    let (position, velocity) = residuals(&p.system, &traj);
    let (max_error, drift) = energy_drift(&p.system, &traj);
    let newton = traj.newton_iterations as f64 / steps as f64;
    println!("RATTLE: |g| ≤ {position:.1e}, |GM⁻¹p| ≤ {velocity:.1e}, max |ΔH| = {max_error:.4}, drift {drift:.1e}/time, {newton:.2} Newton iterations a step");
    assert!(position <= 1e-14 && velocity <= 1e-14, "{position:e}, {velocity:e}");
    common::assert_within_factor("max energy error", max_error, 0.0061, 1.2);
    assert!(drift.abs() < 1e-9, "{drift:e}");
    assert!(newton <= 3.5, "{newton}");
}

#[test]
fn shake_with_a_loose_tolerance_drifts_in_energy() {
    // reference/scenes.json: SHAKE to 1e-4 drifts at about 6e-7 per unit time. Ours stops as
    // soon as |g|∞ ≤ 1e-4 (g = ½(|x|² − l²)), from the last step's multiplier, and drifts at
    // 7.7e-8: a thousand times RATTLE's rate, which is round-off.
    let p = scenes::cartesian_pendulum();
    let shake = run(&p, Method::Shake, 0.1, 100_000, 10, Some(1e-4));
    let rattle = run(&p, Method::Rattle, 0.1, 100_000, 10, None);
    let (position, velocity) = residuals(&p.system, &shake);
    let ((max_error, drift), (_, rattle_drift)) = (energy_drift(&p.system, &shake), energy_drift(&p.system, &rattle));
    println!(
        "SHAKE 1e-4: |g| ≤ {position:.1e}, |GM⁻¹p| ≤ {velocity:.1e}, max |ΔH| = {max_error:.4}, drift {drift:.2e}/time \
         against RATTLE's {rattle_drift:.1e}"
    );
    assert!(position <= 1e-4);
    assert!(
        drift.abs() > 100.0 * rattle_drift.abs(),
        "{drift:e} against {rattle_drift:e}"
    );
}

/// (x, y) at T = 10 of the pendulum released from rest at 2 rad, from the minimal coordinate
/// with Kahan–Li 8 at h = 1e-3 (error below 1e-13).
fn pendulum_reference() -> [f64; 2] {
    let options = Options {
        save_every: 10_000,
        ..Options::new(1e-3, 10_000)
    };
    let traj = integrate(&Pendulum::new(), Method::KahanLi8, &[2.0], &[0.0], &options, || Ok(())).unwrap();
    let theta = traj.q_at(1)[0];
    [theta.sin(), -theta.cos()]
}

#[test]
fn rattle_converges_at_order_two_and_its_composition_at_order_four() {
    let p = scenes::cartesian_pendulum();
    let reference = pendulum_reference();
    for (method, n0) in [(Method::Rattle, 200), (Method::Rattle4, 100)] {
        common::assert_method_order(method, n0, 3, |steps| {
            let traj = run(&p, method, 10.0 / steps as f64, steps, steps, None);
            let q = traj.q_at(1);
            (q[0] - reference[0]).hypot(q[1] - reference[1])
        });
    }
}

#[test]
fn the_cartesian_spherical_pendulum_reaches_the_angle_reference_and_keeps_its_angular_momentum() {
    let p = scenes::cartesian_spherical_pendulum();
    let (reference, _) = p.reference.as_ref().unwrap();
    let lz = |q: &[f64], p: &[f64]| q[0] * p[1] - q[1] * p[0];
    let errors: Vec<f64> = (0..4)
        .map(|k| {
            let steps = 5000 << k;
            let traj = run(&p, Method::Rattle, 50.0 / steps as f64, steps, steps / 100, None);
            let l0 = lz(traj.q_at(0), traj.p_at(0));
            let drift = (0..traj.len())
                .map(|i| (lz(traj.q_at(i), traj.p_at(i)) - l0).abs())
                .fold(0.0, f64::max);
            assert!(drift <= 1e-12 * l0.abs(), "L_z drifts by {drift:e}");
            common::final_error(&traj, &reference.q, &[])
        })
        .collect();
    common::assert_order("RATTLE, spherical pendulum", &errors, 2.0, 0.3);
}

#[test]
fn chains_of_two_to_thirty_two_links_stay_on_their_constraints() {
    for links in [2, 8, 32] {
        let p = scenes::planar_chain(links).unwrap();
        let traj = run(&p, Method::Rattle, 0.01, 10_000, 100, None);
        let (position, velocity) = residuals(&p.system, &traj);
        let energies: Vec<f64> = (0..traj.len())
            .map(|k| varmech::model::hamiltonian(&p.system.system, traj.q_at(k), traj.p_at(k)).unwrap())
            .collect();
        let stats = common::energy_statistics(&p.system.system, &traj);
        let relative = common::relative_energy_error(&energies);
        println!(
            "{links} links: |g| ≤ {position:.1e}, |GM⁻¹p| ≤ {velocity:.1e}, max |ΔH/H₀| = {:.2e}, {}",
            relative.max, stats.verdict
        );
        assert!(
            position <= 1e-13 && velocity <= 1e-12,
            "{links} links: {position:e}, {velocity:e}"
        );
        assert!(common::conserved(stats.verdict), "{links} links: {stats:?}");
    }
}

#[test]
fn inconsistent_initial_data_is_refused_and_projection_makes_it_consistent() {
    let p = scenes::cartesian_pendulum();
    let (q_off, p_off) = ([1.0, 0.1], [0.3, 0.2]);
    let options = Options::new(0.1, 10);
    let error = integrate(&p.system, Method::Rattle, &q_off, &p.initial.p, &options, || Ok(()))
        .unwrap_err()
        .error;
    assert!(
        matches!(error, Error::InvalidArgument { argument: "q0", .. }),
        "{error}"
    );
    let error = integrate(&p.system, Method::Rattle, &p.initial.q, &p_off, &options, || Ok(()))
        .unwrap_err()
        .error;
    assert!(
        matches!(error, Error::InvalidArgument { argument: "p0", .. }),
        "{error}"
    );
    let error = integrate(&p.system, Method::Verlet, &p.initial.q, &p.initial.p, &options, || {
        Ok(())
    })
    .unwrap_err()
    .error;
    assert!(error.to_string().contains("ignore the constraints"), "{error}");
    let error = integrate(
        &p.system.system,
        Method::Rattle,
        &p.initial.q,
        &p.initial.p,
        &options,
        || Ok(()),
    )
    .unwrap_err()
    .error;
    assert!(error.to_string().contains("holonomic constraints"), "{error}");

    let (q, v) = Dynamics::project(&p.system, &q_off, &p_off).unwrap().unwrap();
    let Residuals { position, velocity, .. } = p.system.constraint_residuals(&q, &v).unwrap().unwrap();
    assert!(position <= 1e-15 && velocity <= 1e-15, "{position:e}, {velocity:e}");
    assert!(integrate(&p.system, Method::Rattle, &q, &v, &options, || Ok(())).is_ok());
    assert!(
        Dynamics::project(&p.system, &[0.0, 0.0], &[0.0, 0.0]).unwrap().is_err(),
        "the anchor has no nearest point"
    );
}

/// The Cartesian pendulum as a general Lagrangian on its constraint, for the implicit methods.
fn general(p: &Problem<LinkedMasses>) -> Constrained<General<'_, PointMasses>, Distances> {
    Constrained {
        system: General(&p.system.system),
        constraints: p.system.constraints.clone(),
    }
}

#[test]
fn the_constrained_del_equations_of_the_trapezoidal_rule_are_rattle() {
    let p = scenes::cartesian_pendulum();
    let sys = general(&p);
    let options = Options::new(0.1, 2000);
    let del = integrate(&sys, Method::Trapezoid, &p.initial.q, &p.initial.p, &options, || Ok(())).unwrap();
    let rattle = run(&p, Method::Rattle, 0.1, 2000, 1, None);
    let gap = (0..del.len())
        .flat_map(|k| {
            let (a, b) = ((del.q_at(k), del.p_at(k)), (rattle.q_at(k), rattle.p_at(k)));
            a.0.iter()
                .zip(b.0)
                .chain(a.1.iter().zip(b.1))
                .map(|(x, y)| (x - y).abs())
                .collect::<Vec<_>>()
        })
        .fold(0.0, f64::max);
    println!("trapezoid on the constraint vs RATTLE over 2000 steps: {gap:.1e}");
    assert!(gap < 1e-12, "{gap:e}");
    // Galerkin would lose its order with multipliers at the step's ends only, so it is refused.
    let refused = integrate(&sys, Method::Galerkin4, &p.initial.q, &p.initial.p, &options, || Ok(()))
        .unwrap_err()
        .error;
    assert!(refused.to_string().contains("use trapezoid"), "{refused}");
}

#[test]
fn the_rigid_body_in_quaternions_stays_on_the_unit_sphere_at_the_orders_of_its_methods() {
    let problem = RigidBody::problem();
    let sys = Constrained {
        system: General(&problem.system.system),
        constraints: problem.system.constraints.clone(),
    };
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let run = |method, steps: usize, t_end: f64, save_every| {
        let options = Options {
            save_every,
            ..Options::new(t_end / steps as f64, steps)
        };
        integrate(&sys, method, q0, p0, &options, || Ok(())).unwrap_or_else(|f| panic!("{method:?}: {}", f.error))
    };
    // Both constraint levels and the energy over 10⁴ steps of h = 0.01.
    for method in [Method::Trapezoid, Method::Midpoint] {
        let traj = run(method, 10_000, 100.0, 10);
        let (position, velocity) = (0..traj.len())
            .map(|k| sys.constraint_residuals(traj.q_at(k), traj.p_at(k)).unwrap().unwrap())
            .fold((0.0_f64, 0.0_f64), |(a, b), r| (a.max(r.position), b.max(r.velocity)));
        let e0 = problem.system.system.energy(q0, p0, 0.0).unwrap();
        let energy = (0..traj.len())
            .map(|k| (problem.system.system.energy(traj.q_at(k), traj.p_at(k), 0.0).unwrap() - e0).abs())
            .fold(0.0, f64::max);
        println!("rigid body, {method:?}: |g| ≤ {position:.1e}, |q·q̇| ≤ {velocity:.1e}, max |ΔE| = {energy:.2e}");
        assert!(
            position <= 1e-14 && velocity <= 1e-14,
            "{method:?}: {position:e}, {velocity:e}"
        );
        assert!(energy < 1e-3 * e0.abs(), "{method:?}: {energy:e}");
    }
    // Order 2 at T = 2, against Richardson's extrapolation of each method at h = 1/20000 and
    // 1/40000 (error O(h⁴), since both rules are symmetric).
    for method in [Method::Trapezoid, Method::Midpoint] {
        let (coarse, fine) = (run(method, 40_000, 2.0, 40_000), run(method, 80_000, 2.0, 80_000));
        let extrapolate = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| (4.0 * b - a) / 3.0).collect::<Vec<_>>();
        let (q_ref, p_ref) = (
            extrapolate(coarse.q_at(1), fine.q_at(1)),
            extrapolate(coarse.p_at(1), fine.p_at(1)),
        );
        let errors: Vec<f64> = (0..4)
            .map(|k| common::final_error(&run(method, 50 << k, 2.0, 50 << k), &q_ref, &p_ref))
            .collect();
        common::assert_order(&format!("rigid body, {method:?}"), &errors, 2.0, 0.3);
    }
}
