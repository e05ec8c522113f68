//! Kepler problem, e = 0.6, over 200 periods (HLW's work–precision protocol).

use crate::common;

use std::f64::consts::PI;

use common::InvariantStatistics;
use common::{assert_within_factor, final_error, run};
use varmech::diagnostics::{energies, Verdict};
use varmech::integrators::Method;
use varmech::model::MechanicalSystem;
use varmech::scenes::Kepler;

fn steps_per_period(method: Method) -> usize {
    match method.info().order {
        1 => 2000,
        2 => 400,
        _ => 100,
    }
}

#[test]
fn symplectic_methods_conserve_angular_momentum_and_bound_the_energy() {
    let problem = Kepler::problem(0.6).unwrap();
    let rotation = problem.system.symmetries()[0];
    for method in Method::ALL.into_iter().filter(|m| m.info().symplectic) {
        let steps = 200 * steps_per_period(method);
        let traj = run(&problem, method, problem.t_end, steps, 10);
        let l: Vec<f64> = common::along(&traj, |q, p| rotation.momentum(q, p));
        let l_stats = InvariantStatistics::new(&l);
        assert!((l_stats.initial - 0.8).abs() < 1e-15);
        // Explicit methods conserve L to round-off; the implicit ones to the round-off of
        // their Newton solve each step, ~2e-16·|p| a step.
        let bound = if method.info().implicit { 1e-12 } else { 1e-13 };
        assert!(
            l_stats.max_rel_error <= bound,
            "{}: angular momentum error {:.3e}",
            method.info().name,
            l_stats.max_rel_error
        );

        let e = common::relative_energy_error(&energies(&problem.system, &traj).unwrap());
        assert!((e.initial + 0.5).abs() < 1e-15);
        assert!(
            e.last_tenth <= 2.0 * e.first_tenth,
            "{}: energy error grows from {:.3e} to {:.3e}",
            method.info().name,
            e.first_tenth,
            e.last_tenth
        );
        let stats = common::energy_statistics(&problem.system, &traj);
        assert!(common::conserved(stats.verdict), "{}: {stats:?}", method.info().name);
    }
}

#[test]
fn rk4_drifts_secularly_at_the_published_rate() {
    let problem = Kepler::problem(0.6).unwrap();
    let traj = run(&problem, Method::Rk4, problem.t_end, 200 * 100, 10);
    let e = common::energy_statistics(&problem.system, &traj);
    assert_eq!(e.verdict, Verdict::SecularDrift, "{e:?}");
    // The absolute drift rate per period of 2π.
    let per_period = e.drift_rate * 2.0 * PI;
    assert_within_factor("RK4 energy drift per period, h = 2π/100", -per_period, 1.05e-4, 1.2);
}

/// The published figure, 3.1e-7 "at h = 2π/80 (272k force evaluations)", is not what these
/// coefficients give at that step: a plain NumPy loop of the same composition ends at 1.016e-4
/// there, as varmech does, while SciPy's DOP853 reproduces its own published figure of the same
/// protocol (5.0e-6 with 189k evaluations). 3.1e-7 is the error at h = 2π/160; see
/// reference/README.md. Both facts are asserted: the published error at 2π/160, the
/// independent figure at 2π/80, and the order-8 ratio between them.
#[test]
fn kahan_li_8_reaches_the_published_error() {
    let problem = Kepler::problem(0.6).unwrap();
    let (reference, _) = problem.reference.as_ref().unwrap();
    let error = |steps_per_period: usize| {
        let steps = 200 * steps_per_period;
        let traj = run(&problem, Method::KahanLi8, problem.t_end, steps, steps);
        assert_eq!(traj.force_evaluations, 17 * steps as u64 + 1);
        final_error(&traj, &reference.q, &reference.p)
    };
    let (coarse, fine) = (error(80), error(160));
    assert_within_factor("Kahan–Li 8, h = 2π/160", fine, 3.1e-7, 3.0);
    assert_within_factor(
        "Kahan–Li 8, h = 2π/80 (NumPy loop of the same method)",
        coarse,
        1.016e-4,
        1.01,
    );
    assert!(
        ((coarse / fine).log2() - 8.0).abs() < 0.3,
        "order {}",
        (coarse / fine).log2()
    );
}
