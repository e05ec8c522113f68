//! Exact second derivatives: where a model supplies ∂²L/∂q², ∂²L/∂q∂q̇ and ∂²L/∂q̇², Newton's
//! Jacobian of the DEL equations is assembled from them instead of by differences.

use crate::common;

use varmech::integrators::{Method, Trajectory};
use varmech::model::Lagrangian;
use varmech::scenes::DoublePendulum;
use varmech::ModelError;

/// The double pendulum with its exact first derivatives but no second ones.
struct FirstDerivativesOnly(DoublePendulum);

impl Lagrangian for FirstDerivativesOnly {
    fn dim(&self) -> usize {
        2
    }
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        self.0.lagrangian(q, v, t)
    }
    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.0.dl_dq(q, v, t, out)
    }
    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.0.dl_dv(q, v, t, out)
    }
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        self.0.velocity(q, p, t, v)
    }
}

fn run<L: Lagrangian>(sys: &L, method: Method) -> Trajectory {
    common::run_general(sys, &DoublePendulum::problem().initial, method, 0.01, 500, 500)
        .unwrap_or_else(|e| panic!("{method:?}: {e}"))
}

#[test]
fn the_double_pendulum_hessians_are_the_derivatives_of_its_gradients() {
    let sys = DoublePendulum::problem().system;
    common::assert_hessians(&sys, &[0.3, -1.2], &[0.7, 2.5], 1e-7);
}

#[test]
fn an_exact_jacobian_finds_the_same_steps_with_fewer_evaluations() {
    let problem = DoublePendulum::problem();
    let differenced = FirstDerivativesOnly(problem.system.clone());
    for method in crate::common::IMPLICIT {
        let exact = run(&problem.system, method);
        let by_differences = run(&differenced, method);
        let k = exact.len() - 1;
        let gap = exact
            .q_at(k)
            .iter()
            .zip(by_differences.q_at(k))
            .chain(exact.p_at(k).iter().zip(by_differences.p_at(k)))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{method:?}: equations evaluated {} (exact Jacobian) vs {} (differences), Newton iterations {} vs {}, gap {gap:.1e}",
            exact.force_evaluations,
            by_differences.force_evaluations,
            exact.newton_iterations,
            by_differences.newton_iterations
        );
        assert!(gap < 1e-12, "{method:?}: the two Jacobians led to states {gap:e} apart");
        // Every step factorises at least one Jacobian, which costs 2 evaluations per unknown
        // (s·n of them) by differences and none when exact; the residuals cost one evaluation
        // per Newton iteration either way.
        let unknowns = 2 * (method.info().order as u64 / 2); // n = 2, s = order / 2
        let jacobian_work = |t: &varmech::integrators::Trajectory| t.force_evaluations - t.newton_iterations;
        assert!(
            jacobian_work(&by_differences) - jacobian_work(&exact) >= 2 * unknowns * 500,
            "{method:?}: {} vs {}",
            exact.force_evaluations,
            by_differences.force_evaluations
        );
    }
}
