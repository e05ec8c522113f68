//! Small oscillations in the core: equilibria by Newton on the generalized force, the
//! linearized equations and their modes against closed forms (on constraints too), the fastest
//! frequency by Lanczos against the dense modes', and the step from the modes.

use varmech::diagnostics::{accurate_step, equilibrium, linearize, modes, phase_error, stable_step, Model, Shapes};
use varmech::integrators::{Dynamics, General, Method, NewtonOptions};
use varmech::scenes::{cartesian_spherical_pendulum, planar_chain, DoublePendulum, FermiPastaUlam};

#[test]
fn the_double_pendulum_hangs_with_omega_squared_two_plus_or_minus_root_two_g_over_l() {
    let (l, g) = (0.8, 9.81);
    let pendulum = DoublePendulum::new(1.0, 1.0, l, l, g).unwrap();
    let model = Model::from(&pendulum);
    let found = equilibrium(model, &[0.3, -0.2], 0.0, &NewtonOptions::default()).unwrap();
    assert!(found.q.iter().all(|x| x.abs() < 1e-14), "{:?}", found.q);
    let linear = linearize(model, &found.q, 0.0).unwrap();
    assert!(linear.gyroscopic.iter().all(|x| *x == 0.0));
    let modes = modes(&linear).unwrap();
    for (omega, sign) in modes.frequencies.iter().zip([-1.0, 1.0]) {
        let exact = (2.0 + sign * 2.0_f64.sqrt()) * g / l;
        assert!((omega * omega / exact - 1.0).abs() < 1e-13, "{omega}");
    }
    assert_eq!(modes.inertia, [2, 0, 0]);
    // M-orthonormal shapes.
    let Shapes::Real(shapes) = modes.shapes else {
        panic!("complex shapes")
    };
    let gram = shapes.transpose() * &linear.mass * &shapes;
    assert!((gram - nalgebra::DMatrix::identity(2, 2)).amax() < 1e-13);
    // Upside down: both modes grow.
    let top = equilibrium(model, &[3.0, 3.3], 0.0, &NewtonOptions::default()).unwrap();
    let unstable = varmech::diagnostics::modes(&linearize(model, &top.q, 0.0).unwrap()).unwrap();
    assert_eq!(unstable.inertia, [0, 0, 2]);
    assert!(unstable.growth.iter().all(|s| *s > 0.0));
}

#[test]
fn the_spherical_pendulum_in_cartesian_coordinates_has_two_modes_on_its_sphere_and_none_across() {
    // m = l = g = 1 on |x| = 1: the tension λ = −1 (g = ½(|x|² − 1), ∇g = x: ṗ = −e_z + λx = 0 at the bottom).
    let scene = cartesian_spherical_pendulum().system;
    let model = Model::of(&scene).unwrap();
    // A guess off the sphere is brought onto it.
    let found = equilibrium(model, &[0.1, -0.05, -0.7], 0.0, &NewtonOptions::default()).unwrap();
    assert!(
        (found.q[0].abs() + found.q[1].abs() + (found.q[2] + 1.0).abs()) < 1e-14,
        "{:?}",
        found.q
    );
    assert!((found.multipliers[0] + 1.0).abs() < 1e-13, "{:?}", found.multipliers);
    let linear = linearize(model, &found.q, 0.0).unwrap();
    assert_eq!(linear.basis.shape(), (3, 2));
    assert!((linear.multipliers[0] - found.multipliers[0]).abs() < 1e-10);
    let modes = modes(&linear).unwrap();
    assert_eq!(modes.frequencies.len(), 2);
    assert!(
        modes.frequencies.iter().all(|w| (w - 1.0).abs() < 1e-9),
        "{:?}",
        modes.frequencies
    );
    let Shapes::Real(shapes) = modes.shapes else {
        panic!("complex shapes")
    };
    // Horizontal shapes, unit kinetic energy.
    assert!(shapes.row(2).amax() < 1e-13 && (shapes.column(0).norm() - 1.0).abs() < 1e-12);
    assert!((Model::of(&scene).unwrap().fastest(&found.q, 0.0).unwrap().omega - 1.0).abs() < 1e-8);
}

#[test]
fn the_fastest_frequency_by_lanczos_is_the_dense_modes_largest() {
    let fpu = FermiPastaUlam::problem();
    let chain = planar_chain(6).unwrap();
    let pendulum = DoublePendulum::new(1.0, 2.0, 1.0, 0.5, 9.81).unwrap();
    let general = General(&pendulum);
    let cases: [(&dyn Dynamics, Vec<f64>); 3] = [
        (&fpu.system, fpu.initial.q.clone()),
        (&chain.system, chain.initial.q.clone()),
        (&general, vec![0.4, -1.1]),
    ];
    for (system, q) in cases {
        let model = Model::of(system).unwrap();
        let dense = modes(&linearize(model, &q, 0.0).unwrap()).unwrap();
        let largest = dense
            .frequencies
            .iter()
            .zip(&dense.growth)
            .fold(0.0_f64, |a, (w, s)| a.max(w.hypot(*s)));
        let fastest = model.fastest(&q, 0.0).unwrap();
        assert!(fastest.converged, "{fastest:?}");
        assert!(
            (fastest.omega / largest - 1.0).abs() < 1e-6,
            "{fastest:?} against {largest}"
        );
    }
    // The FPU chain at rest: its stiff springs alone, ω = 50.
    let at_rest = Model::of(&fpu.system).unwrap().fastest(&[0.0; 6], 0.0).unwrap();
    assert!((at_rest.omega / 50.0 - 1.0).abs() < 1e-7, "{at_rest:?}");
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

/// The fastest frequency at enormous stiffness, where the squares of the Lanczos products leave
/// the floats (κ of 10¹⁵⁴ on): the double pendulum's ω_max scales as √g, at g = 10²⁰⁰ and
/// 10³⁰⁰ as at g = 1, never 0.
#[test]
fn the_fastest_frequency_at_enormous_stiffness_is_the_scaled_one() {
    let q = [0.4, -1.1];
    let omega = |g: f64| {
        let pendulum = DoublePendulum::new(1.0, 2.0, 1.0, 0.5, g).unwrap();
        Model::of(&General(&pendulum)).unwrap().fastest(&q, 0.0).unwrap().omega
    };
    let unit = omega(1.0);
    for g in [1e160, 1e200, 1e300] {
        let scaled = omega(g) / g.sqrt();
        assert!((scaled / unit - 1.0).abs() < 1e-6, "g = {g:e}: {scaled} against {unit}");
    }
}

/// L = ½q̇² − ½kq², whose ∂²L/∂q² it gives as −`factor`·k.
struct WrongStiffness {
    k: f64,
    factor: f64,
}

impl varmech::model::Lagrangian for WrongStiffness {
    fn dim(&self) -> usize {
        1
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, varmech::ModelError> {
        Ok(0.5 * v[0] * v[0] - 0.5 * self.k * q[0] * q[0])
    }

    fn hessians(
        &self,
        _q: &[f64],
        _v: &[f64],
        _t: f64,
        out: &mut varmech::model::Hessians,
    ) -> Result<bool, varmech::ModelError> {
        out.qq[(0, 0)] = -self.factor * self.k;
        out.qv[(0, 0)] = 0.0;
        out.vv[(0, 0)] = 1.0;
        Ok(true)
    }
}

#[test]
fn an_equilibrium_search_with_wrong_hessians_names_them_not_the_guess() {
    // K given as 0.45k: Newton's corrections grow by 1 − 1/0.45 ≈ −1.22 from every guess,
    // however near the minimum (to 2e4 times it in the 50 iterations), a course that alone
    // reads as a guess outside Newton's region. Checked against differences of the balance, the
    // Jacobian disagrees: the Hessians are named (found by tests/rust/properties.rs).
    let model = WrongStiffness { k: 3.0, factor: 0.45 };
    for guess in [1e-6, 1e-8] {
        let error = equilibrium(Model::from(&model), &[guess], 0.0, &NewtonOptions::default()).unwrap_err();
        let text = error.to_string();
        assert!(
            text.contains("second derivatives (hessians) are not those of its first"),
            "{text}"
        );
        assert!(!text.contains("start nearer"), "{text}");
    }
    // The right Hessians find q = 0.
    let right = WrongStiffness { k: 3.0, factor: 1.0 };
    let found = equilibrium(Model::from(&right), &[0.5], 0.0, &NewtonOptions::default()).unwrap();
    assert!(found.q[0].abs() < 1e-14, "{:?}", found.q);
}
