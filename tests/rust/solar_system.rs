//! The outer solar system over 500 000 days (HLW I.2.4) against the GNI reference state.

use crate::common;

use common::InvariantStatistics;
use common::{assert_within_factor, run};
use varmech::diagnostics::energies;
use varmech::integrators::Method;
use varmech::model::MechanicalSystem;
use varmech::scenes::NBody;

#[test]
fn initial_energy_matches_the_published_value() {
    let problem = NBody::outer_solar_system();
    let h0 = varmech::model::hamiltonian(&problem.system, &problem.initial.q, &problem.initial.p).unwrap();
    assert!((h0 / -3.215453183208163e-08 - 1.0).abs() < 1e-12, "E0 = {h0:e}");
}

/// Converges to the GNI reference state at order 8 (down to 2e-10 at h = 50 days), which checks
/// the data, the model and the reference together.
///
/// The published Kahan–Li 8 figures of `reference/outer_solar_system.json` (2.1e-6 at h = 200
/// days, energy 6.3e-11) are not reproducible with the standard Kahan–Li coefficients: an
/// independent NumPy loop of the same composition gives 1.551e-5 and varmech agrees with it to
/// 1e-10 (`tests/python/test_reference_crosscheck.py`); see reference/README.md.
#[test]
fn kahan_li_8_converges_to_the_reference_at_order_8() {
    let problem = NBody::outer_solar_system();
    let (reference, _) = problem.reference.as_ref().unwrap();
    // Velocities, as the reference is given: v = M⁻¹p.
    let velocity = |p: &[f64]| {
        let mut v = vec![0.0; p.len()];
        problem.system.mass().velocity(p, &mut v);
        v
    };
    let v_ref = velocity(&reference.p);
    let error = |h: f64| {
        let steps = (problem.t_end / h) as usize;
        let traj = run(&problem, Method::KahanLi8, problem.t_end, steps, 1);
        let k = traj.len() - 1;
        let (q, v) = (traj.q_at(k), velocity(traj.p_at(k)));
        let err = q
            .iter()
            .zip(&reference.q)
            .chain(v.iter().zip(&v_ref))
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>();
        (err.sqrt(), traj)
    };
    let (e200, traj) = error(200.0);
    let (e100, _) = error(100.0);
    let (e50, _) = error(50.0);
    for (coarse, fine) in [(e200, e100), (e100, e50)] {
        let order = (coarse / fine).log2();
        assert!(
            (order - 8.0).abs() <= 0.3,
            "observed order {order:.3} (errors {e200:.3e}, {e100:.3e}, {e50:.3e})"
        );
    }
    assert!(e50 < 1e-9, "error at h = 50 days: {e50:.3e}");

    let e = common::relative_energy_error(&energies(&problem.system, &traj).unwrap());
    assert!(e.max < 1e-9, "max relative energy error at h = 200 days: {:.3e}", e.max);

    for g in problem.system.symmetries() {
        let j: Vec<f64> = common::along(&traj, |q, p| g.momentum(q, p));
        let s = InvariantStatistics::new(&j);
        // Round-off relative to the largest momentum of a body times the number of steps' √.
        let scale = problem.initial.p.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(
            s.max_abs_error <= 1e-13 * scale,
            "{}: error {:.3e} (scale {scale:.3e})",
            g.name(),
            s.max_abs_error
        );
    }
}

#[test]
fn verlet_energy_errors_match_the_published_ones() {
    let problem = NBody::outer_solar_system();
    for (h, published) in [(100.0, 3.8e-4), (50.0, 1.0e-4), (20.0, 1.7e-5)] {
        let steps = (problem.t_end / h) as usize;
        let traj = run(&problem, Method::Verlet, problem.t_end, steps, 10);
        let e = common::relative_energy_error(&energies(&problem.system, &traj).unwrap());
        assert_within_factor(
            &format!("Verlet, h = {h}, max relative energy error"),
            e.max,
            published,
            3.0,
        );
    }
}
