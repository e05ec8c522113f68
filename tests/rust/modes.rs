//! Small oscillations in the core: equilibria by Newton on the generalized force, the
//! linearized equations and their modes against closed forms, and the step from the modes.

use varmech::diagnostics::{accurate_step, equilibrium, linearize, modes, phase_error, stable_step};
use varmech::integrators::{Method, NewtonOptions};
use varmech::scenes::DoublePendulum;

#[test]
fn the_double_pendulum_hangs_with_omega_squared_two_plus_or_minus_root_two_g_over_l() {
    let (l, g) = (0.8, 9.81);
    let pendulum = DoublePendulum::new(1.0, 1.0, l, l, g).unwrap();
    let found = equilibrium(&pendulum, &[0.3, -0.2], 0.0, &NewtonOptions::default()).unwrap();
    assert!(found.q.iter().all(|x| x.abs() < 1e-14), "{:?}", found.q);
    let linear = linearize(&pendulum, &found.q, 0.0).unwrap();
    assert!(linear.gyroscopic.iter().all(|x| *x == 0.0));
    let modes = modes(&linear).unwrap();
    for (omega, sign) in modes.frequencies.iter().zip([-1.0, 1.0]) {
        let exact = (2.0 + sign * 2.0_f64.sqrt()) * g / l;
        assert!((omega * omega / exact - 1.0).abs() < 1e-13, "{omega}");
    }
    assert_eq!(modes.inertia, [2, 0, 0]);
    // M-orthonormal shapes.
    let shapes = modes.shapes.unwrap();
    let gram = shapes.transpose() * &linear.mass * &shapes;
    assert!((gram - nalgebra::DMatrix::identity(2, 2)).amax() < 1e-13);
    // Upside down: both modes grow.
    let top = equilibrium(&pendulum, &[3.0, 3.3], 0.0, &NewtonOptions::default()).unwrap();
    let unstable = varmech::diagnostics::modes(&linearize(&pendulum, &top.q, 0.0).unwrap()).unwrap();
    assert_eq!(unstable.inertia, [0, 0, 2]);
    assert!(unstable.growth.iter().all(|s| *s > 0.0));
}

#[test]
fn the_steps_come_from_the_methods_limits_and_phase_errors() {
    assert_eq!(stable_step(Method::Verlet, 4.0).unwrap(), 0.5);
    assert!(stable_step(Method::Midpoint, 4.0).unwrap().is_infinite());
    assert!(stable_step(Method::ExplicitEuler, 4.0).is_err());
    // Verlet's angle a step is θ with cos θ = 1 − x²/2.
    for x in [0.1, 0.5, 1.5] {
        let exact = std::f64::consts::TAU * ((1.0 - x * x / 2.0_f64).acos() / x - 1.0);
        assert!((phase_error(Method::Verlet, x).unwrap() / exact - 1.0).abs() < 1e-9);
    }
    assert!(phase_error(Method::Verlet, 2.1).unwrap().is_infinite());
    let h = accurate_step(Method::Verlet, 2.0, 1e-3).unwrap();
    assert!((phase_error(Method::Verlet, 2.0 * h).unwrap() / 1e-3 - 1.0).abs() < 1e-5);
}
