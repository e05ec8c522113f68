//! General Lagrangians with the implicit variational integrators: the double pendulum, whose
//! mass matrix depends on the configuration.

use crate::common;

use nalgebra::DMatrix;
use varmech::integrators::{Method, NewtonOptions, Options, Trajectory};
use varmech::model::{Lagrangian, Natural, NaturalSystem};
use varmech::scenes::DoublePendulum;
use varmech::{Error, ModelError};

fn run<L: Lagrangian>(
    sys: &L,
    method: Method,
    steps: usize,
    t_end: f64,
    save_every: usize,
) -> Result<Trajectory, Error> {
    run_with(sys, method, steps, t_end, save_every, NewtonOptions::default())
}

fn run_with<L: Lagrangian>(
    sys: &L,
    method: Method,
    steps: usize,
    t_end: f64,
    save_every: usize,
    newton: NewtonOptions,
) -> Result<Trajectory, Error> {
    let problem = DoublePendulum::problem();
    let options = Options {
        save_every,
        newton,
        ..Options::new(t_end / steps as f64, steps)
    };
    common::run_general_with(sys, &problem.initial, method, &options)
}

#[test]
fn galerkin_integrators_converge_at_orders_four_and_six_to_the_reference() {
    let problem = DoublePendulum::problem();
    let (reference, _) = problem.reference.as_ref().unwrap();
    // Galerkin-6 gets two halvings here: a third would end at 6e-11, against a reference
    // accurate to about 1e-11 (its three halvings are measured at T = 3, in the next test).
    for (method, n0, halvings) in [(Method::Galerkin4, 500, 3), (Method::Galerkin6, 500, 2)] {
        common::assert_method_order(method, n0, halvings, |steps| {
            let traj = run(&problem.system, method, steps, problem.t_end, steps).unwrap();
            common::final_error(&traj, &reference.q, &reference.p)
        });
    }
}

#[test]
fn galerkin6_converges_at_order_six_over_three_halvings_to_a_self_converged_reference() {
    let problem = DoublePendulum::problem();
    let (published, _) = problem.reference.as_ref().unwrap();
    // The pendulum is chaotic: by T = 10 it amplifies a change of 1e-14 in the initial state to
    // 1e-10, so no double-precision run is much closer than 1e-11 to the true state there, and
    // Galerkin-6's asymptotic range (errors below about 3e-6) spans only two halvings above that.
    // At T = 3 round-off costs about 1e-12: the order is measured there, against the state at
    // T = 3 of a run at h = 1/800 whose state at T = 10 reproduces the published reference.
    let t_order = 3.0;
    // Newton solved to round-off (it stops once a fresh step no longer contracts): the default
    // 1e-14 a step, amplified, would show at 1e-12.
    let to_round_off = NewtonOptions {
        tolerance: 1e-16,
        ..NewtonOptions::default()
    };
    // Saved every 2400 steps: T = 3 is the second state, T = 10 the last.
    let reference = run_with(&problem.system, Method::Galerkin6, 8000, 10.0, 2400, to_round_off).unwrap();
    assert!((reference.t[1] - t_order).abs() < 1e-12, "saved at {:?}", reference.t);
    let (q_ref, p_ref) = (reference.q_at(1), reference.p_at(1));

    // (θ, θ̇) at T = 10 against the published ones (11 decimals, accurate to about 1e-11). The
    // bound adds this run's own round-off there, which scatters up to 3e-11 with the fine step
    // and the Newton tolerance.
    let angles_and_rates = |q: &[f64], p: &[f64]| {
        let mut v = vec![0.0; 2];
        problem.system.velocity(q, p, 0.0, &mut v).unwrap();
        [q, &v].concat()
    };
    let end = reference.len() - 1;
    let deviation = angles_and_rates(reference.q_at(end), reference.p_at(end))
        .iter()
        .zip(angles_and_rates(&published.q, &published.p))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);

    // Self-convergence at T = 3: the same run at h/2.
    let halved = run_with(&problem.system, Method::Galerkin6, 4800, t_order, 4800, to_round_off).unwrap();
    let own = common::final_error(&halved, q_ref, p_ref);

    // From h = 1/16, where the error (5e-6) has become asymptotic, to h = 1/128 (2e-11).
    let errors: Vec<f64> = (0..4)
        .map(|k| {
            let steps = 48 << k;
            let traj = run(&problem.system, Method::Galerkin6, steps, t_order, steps).unwrap();
            common::final_error(&traj, q_ref, p_ref)
        })
        .collect();
    println!(
        "Galerkin-6 reference: max |Δ(θ, θ̇)| = {deviation:.2e} from the published one at T = 10; \
         h vs h/2 at T = {t_order}: {own:.2e}"
    );
    assert!(deviation <= 4e-11, "{deviation:e}");
    assert!(own <= errors[3] / 10.0, "reference {own:e} against errors {errors:?}");
    common::assert_order(
        &format!("Galerkin-6 at T = {t_order}, h = 1/16 to 1/128"),
        &errors,
        6.0,
        0.3,
    );
}

#[test]
fn initial_energy_matches_the_published_value() {
    let p = DoublePendulum::problem();
    let e = p.system.energy(&p.initial.q, &p.initial.p, 0.0).unwrap();
    assert!((e + 40.218179175435154).abs() < 1e-12, "E0 = {e}");
}

#[test]
fn midpoint_and_trapezoid_converge_at_order_two_to_the_reference() {
    let problem = DoublePendulum::problem();
    let (reference, _) = problem.reference.as_ref().unwrap();
    for method in [Method::Midpoint, Method::Trapezoid] {
        let errors: Vec<f64> = (0..4)
            .map(|k| {
                let steps = 1000 << k;
                let traj = run(&problem.system, method, steps, problem.t_end, steps).unwrap();
                common::final_error(&traj, &reference.q, &reference.p)
            })
            .collect();
        common::assert_order(&format!("{method:?}"), &errors, 2.0, 0.3);
    }
}

/// The double pendulum with only L supplied: ∂L/∂q and ∂L/∂q̇ come from the trait's central
/// differences.
struct LagrangianOnly(DoublePendulum);

impl Lagrangian for LagrangianOnly {
    fn dim(&self) -> usize {
        2
    }
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        self.0.lagrangian(q, v, t)
    }
}

/// Asserts that `got` is `exact` to `tolerance` relative to max(1, |exact|), entry by entry.
fn assert_close(exact: &[f64], got: &[f64], tolerance: f64) {
    assert!(
        exact
            .iter()
            .zip(got)
            .all(|(a, b)| (a - b).abs() < tolerance * a.abs().max(1.0)),
        "{exact:?} vs {got:?}"
    );
}

#[test]
fn central_difference_derivatives_reproduce_the_exact_ones() {
    let problem = DoublePendulum::problem();
    let only = LagrangianOnly(problem.system.clone());
    let (q, v) = ([0.3, -1.2], [0.7, 2.5]);
    let (mut exact, mut approx) = ([0.0; 2], [0.0; 2]);
    problem.system.dl_dq(&q, &v, 0.0, &mut exact).unwrap();
    only.dl_dq(&q, &v, 0.0, &mut approx).unwrap();
    assert_close(&exact, &approx, 1e-8);
    problem.system.dl_dv(&q, &v, 0.0, &mut exact).unwrap();
    only.dl_dv(&q, &v, 0.0, &mut approx).unwrap();
    assert_close(&exact, &approx, 1e-8);

    // Over T = 2: the pendulum is chaotic, and later on its growth, not the derivatives, would
    // decide the difference.
    let a = run(&problem.system, Method::Midpoint, 200, 2.0, 200).unwrap();
    let b = run(&only, Method::Midpoint, 200, 2.0, 200).unwrap();
    let diff = common::final_error(&b, a.q_at(1), a.p_at(1));
    assert!(diff < 1e-7, "{diff:e}");
}

/// The same double pendulum as a natural system (l = (2, 3), m = (1, 2)): M(θ), V and ∇V only;
/// ∂T/∂θ comes from the trait's differences of M.
struct NaturalDoublePendulum;

const G: f64 = 9.80665;

impl NaturalSystem for NaturalDoublePendulum {
    fn dim(&self) -> usize {
        2
    }
    fn mass_matrix(&self, q: &[f64], m: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let c = 2.0 * 2.0 * 3.0 * (q[0] - q[1]).cos();
        m.copy_from_slice(&[3.0 * 4.0, c, c, 2.0 * 9.0]);
        Ok(())
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(-3.0 * G * 2.0 * q[0].cos() - 2.0 * G * 3.0 * q[1].cos())
    }
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad[0] = 3.0 * G * 2.0 * q[0].sin();
        grad[1] = 2.0 * G * 3.0 * q[1].sin();
        Ok(())
    }
}

#[test]
fn a_natural_system_with_differenced_mass_derivative_matches_the_exact_lagrangian() {
    let problem = DoublePendulum::problem();
    let natural = Natural::new(NaturalDoublePendulum);
    let (q, v, p) = ([0.3, -1.2], [0.7, 2.5], [1.5, -0.4]);
    let (mut exact, mut got) = ([0.0; 2], [0.0; 2]);
    problem.system.dl_dv(&q, &v, 0.0, &mut exact).unwrap();
    natural.dl_dv(&q, &v, 0.0, &mut got).unwrap();
    assert_eq!(exact, got, "p = M(q)q̇ exactly");
    problem.system.velocity(&q, &p, 0.0, &mut exact).unwrap();
    natural.velocity(&q, &p, 0.0, &mut got).unwrap();
    assert!(
        exact.iter().zip(&got).all(|(a, b)| (a - b).abs() < 1e-14),
        "{exact:?} vs {got:?}"
    );
    problem.system.dl_dq(&q, &v, 0.0, &mut exact).unwrap();
    natural.dl_dq(&q, &v, 0.0, &mut got).unwrap();
    assert_close(&exact, &got, 1e-9);
    let e = |l: &dyn Lagrangian| l.energy(&problem.initial.q, &problem.initial.p, 0.0).unwrap();
    assert!((e(&problem.system) - e(&natural)).abs() < 1e-13 * e(&problem.system).abs());
    let a = run(&problem.system, Method::Midpoint, 200, 2.0, 200).unwrap();
    let b = run(&natural, Method::Midpoint, 200, 2.0, 200).unwrap();
    let diff = common::final_error(&b, a.q_at(1), a.p_at(1));
    assert!(diff < 1e-7, "{diff:e}");

    // A matrix that is not positive definite is refused by name.
    struct Indefinite;
    impl NaturalSystem for Indefinite {
        fn dim(&self) -> usize {
            1
        }
        fn mass_matrix(&self, _: &[f64], m: &mut DMatrix<f64>) -> Result<(), ModelError> {
            m[(0, 0)] = -1.0;
            Ok(())
        }
        fn potential(&self, _: &[f64]) -> Result<f64, ModelError> {
            Ok(0.0)
        }
        fn gradient(&self, _: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
            grad[0] = 0.0;
            Ok(())
        }
    }
    let err = Natural::new(Indefinite)
        .velocity(&[0.0], &[1.0], 0.0, &mut [0.0])
        .unwrap_err();
    assert!(err.to_string().contains("not symmetric positive definite"), "{err}");
}

#[test]
fn energy_stays_bounded_and_newton_converges_in_a_few_iterations() {
    let problem = DoublePendulum::problem();
    let steps = 100_000;
    let traj = run(&problem.system, Method::Midpoint, steps, 1000.0, 10).unwrap();
    let e: Vec<f64> = common::along(&traj, |q, p| problem.system.energy(q, p, 0.0).unwrap());
    let stats = common::energy_statistics(&problem.system, &traj);
    assert_eq!(stats.verdict, varmech::diagnostics::Verdict::Bounded, "{stats:?}");
    // O(h²) at h = 0.01 on this fast pendulum: 3.5e-3, in a band that does not grow.
    let relative = common::relative_energy_error(&e);
    assert!(relative.max < 1e-2, "{relative:?}");
    let per_step = traj.newton_iterations as f64 / steps as f64;
    assert!((1.0..=4.0).contains(&per_step), "{per_step} Newton iterations a step");
}

#[test]
fn explicit_methods_need_a_mechanical_system() {
    let problem = DoublePendulum::problem();
    match run(&problem.system, Method::Verlet, 10, 1.0, 1) {
        Err(Error::InvalidArgument { argument: "method", .. }) => {}
        other => panic!("expected an invalid method, got {other:?}"),
    }
}

#[test]
fn the_energy_function_of_a_general_lagrangian_uses_the_inverse_legendre_transform() {
    // The default Newton solve of ∂L/∂q̇ = p agrees with the closed form M(θ)⁻¹p.
    let problem = DoublePendulum::problem();
    let only = LagrangianOnly(problem.system.clone());
    let (q, p) = ([0.3, -1.2], [2.0, -7.0]);
    let (mut exact, mut newton) = ([0.0; 2], [0.0; 2]);
    problem.system.velocity(&q, &p, 0.0, &mut exact).unwrap();
    only.velocity(&q, &p, 0.0, &mut newton).unwrap();
    assert!(
        exact.iter().zip(&newton).all(|(a, b)| (a - b).abs() < 1e-8),
        "{exact:?} vs {newton:?}"
    );
    let (e1, e2) = (
        problem.system.energy(&q, &p, 0.0).unwrap(),
        only.energy(&q, &p, 0.0).unwrap(),
    );
    assert!((e1 - e2).abs() < 1e-8 * e1.abs());
    // The energy threshold works for general Lagrangians too: a huge step blows the energy up.
    let options = Options {
        max_energy_error: Some(1e-6),
        ..Options::new(0.1, 100)
    };
    let error = common::run_general_with(&problem.system, &problem.initial, Method::Midpoint, &options).unwrap_err();
    assert!(matches!(error, Error::Divergence { .. }), "{error}");
}

#[test]
fn spherical_pendulum_conserves_its_azimuthal_momentum_and_reaches_the_reference() {
    use common::InvariantStatistics;
    use varmech::scenes::SphericalPendulum;
    let problem = SphericalPendulum::problem();
    let (reference, _) = problem.reference.as_ref().unwrap();
    let cyclic = problem.system.symmetries()[0];
    let run = |method, steps: usize, t_end: f64, save_every| {
        common::run_general(
            &problem.system,
            &problem.initial,
            method,
            t_end / steps as f64,
            steps,
            save_every,
        )
        .unwrap()
    };
    // Discrete Noether: p_φ to round-off over 10⁵ steps; the energy stays in a band.
    let traj = run(Method::Midpoint, 100_000, 1000.0, 10);
    let j: Vec<f64> = common::along(&traj, |q, p| cyclic.momentum(q, p));
    let stats = InvariantStatistics::new(&j);
    assert!((stats.initial - 0.8496881019282854).abs() < 1e-15);
    assert!(stats.max_rel_error <= 1e-12, "p_φ error {:.3e}", stats.max_rel_error);
    let e: Vec<f64> = common::along(&traj, |q, p| problem.system.energy(q, p, 0.0).unwrap());
    assert!((e[0] + 0.030489444711168545).abs() < 1e-15);
    assert!(common::conserved(
        common::energy_statistics(&problem.system, &traj).verdict
    ));
    // The angles at T = 50 converge to the reference at order 2.
    for method in [Method::Midpoint, Method::Trapezoid] {
        let errors: Vec<f64> = (0..4)
            .map(|k| {
                let steps = 2000 << k;
                let traj = run(method, steps, reference.t, steps);
                traj.q_at(1)
                    .iter()
                    .zip(&reference.q)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        common::assert_order(&format!("{method:?}: spherical pendulum angles"), &errors, 2.0, 0.3);
    }
}
