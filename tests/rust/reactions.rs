//! Forces of constraint: the multipliers λ of a saved state against the pendulum's tension, at
//! the method's order, with the power of the constraint force at round-off.

use varmech::integrators::{integrate, Dynamics, Method, Options, Trajectory};
use varmech::scenes::{self, LinkedMasses, Problem};

fn run(p: &Problem<LinkedMasses>, method: Method, h: f64, t_end: f64) -> Trajectory {
    let steps = (t_end / h).round() as usize;
    integrate(
        &p.system,
        method,
        &p.initial.q,
        &p.initial.p,
        &Options::new(h, steps),
        || Ok(()),
    )
    .unwrap_or_else(|f| panic!("{method:?}: {}", f.error))
}

/// The tension of the unit pendulum (m = l = g = 1) at a state on its circle: T = g cos θ + |v|²,
/// cos θ = −y. The constraint ½(|x|² − l²) = 0 has G = xᵀ, so its force λx is the string's
/// pull −Tx: λ = −T.
fn tension(q: &[f64], p: &[f64]) -> f64 {
    -q[1] + p[0] * p[0] + p[1] * p[1]
}

#[test]
fn the_multiplier_of_each_saved_state_is_the_pendulums_tension_and_does_no_work() {
    let p = scenes::cartesian_pendulum();
    let traj = run(&p, Method::Rattle, 0.01, 10.0);
    let mut worst: (f64, f64) = (0.0, 0.0);
    let r = p.system.reactions(&traj.t, &traj.q, &traj.p).unwrap().unwrap();
    assert_eq!(r.multipliers.len(), traj.len());
    for k in 0..traj.len() {
        let (q, lambda) = (traj.q_at(k), r.multipliers[k]);
        let t = tension(q, traj.p_at(k));
        worst.0 = worst.0.max((lambda + t).abs() / t.abs().max(1.0));
        for (f, x) in r.force[2 * k..2 * k + 2].iter().zip(q) {
            assert!((f - lambda * x).abs() <= 1e-14 * t.abs().max(1.0));
        }
        worst.1 = worst.1.max(r.power[k].abs() / r.power_size[k].max(f64::MIN_POSITIVE));
    }
    // The fourth-order difference along the motion: about 1e-12; the power: RATTLE keeps
    // G(q)M⁻¹p = 0 to round-off.
    assert!(worst.0 < 1e-11, "λ against the tension: {:e}", worst.0);
    assert!(worst.1 < 1e-12, "power against its size: {:e}", worst.1);
}

#[test]
fn the_multipliers_converge_at_the_methods_order() {
    let p = scenes::cartesian_pendulum();
    let end = |traj: &Trajectory| {
        let r = p.system.reactions(&traj.t, &traj.q, &traj.p).unwrap().unwrap();
        r.multipliers[traj.len() - 1]
    };
    let reference = end(&run(&p, Method::Rattle4, 1e-4, 1.0));
    for (method, order, steps) in [
        (Method::Rattle, 2.0, [0.02, 0.01, 0.005]),
        (Method::Rattle4, 4.0, [0.04, 0.02, 0.01]),
    ] {
        let errors: Vec<f64> = steps
            .iter()
            .map(|&h| (end(&run(&p, method, h, 1.0)) - reference).abs())
            .collect();
        for pair in errors.windows(2) {
            let measured = (pair[0] / pair[1]).log2();
            assert!(
                (measured - order).abs() < 0.1,
                "{method:?}: order {measured:.3} ({errors:?})"
            );
        }
    }
}
