//! Helpers shared by the integration tests.

use varmech::integrators::{integrate, General, Method, Options, Trajectory};
use varmech::model::{Lagrangian, MechanicalSystem};
use varmech::scenes::{Problem, State};
use varmech::Error;

/// Integrates `problem` from its initial state with `steps` steps to `t_end`, keeping every
/// `save_every`-th state.
pub fn run<S: MechanicalSystem>(
    problem: &Problem<S>,
    method: Method,
    t_end: f64,
    steps: usize,
    save_every: usize,
) -> Trajectory {
    let options = Options {
        save_every,
        ..Options::new(t_end / steps as f64, steps)
    };
    integrate(
        &problem.system,
        method,
        &problem.initial.q,
        &problem.initial.p,
        &options,
        || Ok(()),
    )
    .unwrap_or_else(|f| panic!("{:?} failed: {}", method, f.error))
}

/// ‖(q, p) − (q_ref, p_ref)‖₂ at the last saved state.
pub fn final_error(traj: &Trajectory, q_ref: &[f64], p_ref: &[f64]) -> f64 {
    let k = traj.len() - 1;
    let dq = traj.q_at(k).iter().zip(q_ref).map(|(a, b)| (a - b).powi(2));
    let dp = traj.p_at(k).iter().zip(p_ref).map(|(a, b)| (a - b).powi(2));
    dq.chain(dp).sum::<f64>().sqrt()
}

/// Asserts `measured` is within a factor `factor` of `published`.
pub fn assert_within_factor(what: &str, measured: f64, published: f64, factor: f64) {
    assert!(
        measured <= factor * published && measured >= published / factor,
        "{what}: measured {measured:.3e}, published {published:.3e} (allowed factor {factor})"
    );
}

/// Asserts that errors at successively halved steps fall at `order` ± `tolerance`: each
/// observed order log₂(eₖ/eₖ₊₁) is in that band. Prints and returns the observed orders.
pub fn assert_order(what: &str, errors: &[f64], order: f64, tolerance: f64) -> Vec<f64> {
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("{what}: errors {errors:?}, orders {orders:.3?}");
    assert!(
        orders.iter().all(|p| (p - order).abs() <= tolerance),
        "{what}: orders {orders:.3?} (errors {errors:?}), expected {order} ± {tolerance}"
    );
    orders
}

/// Integrates the general Lagrangian `sys` from `initial` with `steps` steps of size h, keeping
/// every `save_every`-th state.
pub fn run_general<L: Lagrangian>(
    sys: &L,
    initial: &State,
    method: Method,
    h: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory, Error> {
    let options = Options {
        save_every,
        ..Options::new(h, steps)
    };
    integrate(&General(sys), method, &initial.q, &initial.p, &options, || Ok(())).map_err(|f| f.error)
}
