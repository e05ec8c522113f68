//! The discrete Lagrange–d'Alembert variants against the reversible step (`midpoint`):
//! Cortés & Martínez's non-reversible step (`cortes_martinez`), McLachlan & Perlmutter's (2006)
//! contrast, and Yoshida's triple jump of the reversible step (`dla4`), on the nonholonomic
//! particle in a harmonic well, reversible (L even in q̇, A linear in it) and quasi-periodic.

use crate::common::{self, Potential};

use nalgebra::DMatrix;
use varmech::integrators::{integrate, Dynamics, Method, Options, Trajectory};
use varmech::model::{Lagrangian, Nonholonomic, VelocityConstraints};
use varmech::ModelError;

/// A unit mass in V = ½(x² + y² + z²).
fn well() -> Potential {
    Potential::unit(
        3,
        |q| 0.5 * q.iter().map(|x| x * x).sum::<f64>(),
        |q, grad| grad.copy_from_slice(q),
    )
}

/// The nonholonomic particle's constraint ż = y ẋ (Bloch 2003, §1.6): A(q) = (−y, 0, 1), whose
/// one derivative is ∂A/∂y = (−1, 0, 0).
struct Knife;

impl VelocityConstraints for Knife {
    fn count(&self) -> usize {
        1
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        (a[(0, 0)], a[(0, 1)], a[(0, 2)]) = (-q[1], 0.0, 1.0);
        Ok(())
    }

    fn derivative(&self, _q: &[f64], i: usize, out: &mut DMatrix<f64>) -> Result<(), ModelError> {
        out.fill(0.0);
        out[(0, 0)] = -f64::from(i == 1);
        Ok(())
    }
}

type Particle = Nonholonomic<Potential, Knife>;

fn particle() -> Particle {
    Nonholonomic {
        system: well(),
        constraints: Knife,
    }
}

/// From (0, 0.7, 0) with q̇ = (1, 0.3, 0.7), on the constraint: E = 1.035.
const Q0: [f64; 3] = [0.0, 0.7, 0.0];
const P0: [f64; 3] = [1.0, 0.3, 0.7];

/// `steps` steps of h from (q0, p0), every `save_every`-th state kept; no energy check (the
/// drifting method must be let drift).
fn run(method: Method, (q0, p0): (&[f64], &[f64]), h: f64, steps: usize, save_every: usize) -> Trajectory {
    let options = Options {
        save_every,
        max_energy_error: None,
        ..Options::new(h, steps)
    };
    integrate(&particle(), method, q0, p0, &options, || Ok(())).unwrap_or_else(|f| panic!("{method:?}: {}", f.error))
}

/// The energy errors E − E₀ at the saved states.
fn energy_errors(model: &Particle, traj: &Trajectory) -> Vec<f64> {
    let e: Vec<f64> = common::along(traj, |q, p| Lagrangian::energy(&model.system, q, p, 0.0).unwrap());
    e.iter().map(|x| x - e[0]).collect()
}

/// max over the saved states of |A(q)q̇| relative to ‖A‖∞‖q̇‖∞.
fn constraint_residual(model: &Particle, traj: &Trajectory) -> f64 {
    (0..traj.len())
        .map(|k| model.constraint_residuals(traj.q_at(k), traj.p_at(k)).unwrap().unwrap())
        .fold(0.0, |a, r| a.max(r.velocity / r.velocity_size))
}

/// ‖(q, p) − (q0, −p0)‖ after `steps` steps from (q0, p0), the momenta reversed, and `steps`
/// steps more: 0 for a symmetric step on a system reversible under p ↦ −p.
fn there_and_back(method: Method, h: f64, steps: usize) -> f64 {
    let there = run(method, (&Q0, &P0), h, steps, steps);
    let k = there.len() - 1;
    let back: Vec<f64> = there.p_at(k).iter().map(|p| -p).collect();
    let home = run(method, (there.q_at(k), &back), h, steps, steps);
    let reversed: Vec<f64> = P0.iter().map(|p| -p).collect();
    common::final_error(&home, &Q0, &reversed)
}

#[test]
fn the_reversible_steps_retrace_their_path_and_cortes_martinez_does_not() {
    // 100 steps of 0.1 (t = 10, a period and a half of the well), the momenta reversed, 100
    // more: the symmetric steps return to the start with reversed momenta to round-off; the
    // step with the constraint at its start misses by its own error, O(h) over the run.
    let misses = [Method::Midpoint, Method::Dla4, Method::CortesMartinez].map(|m| there_and_back(m, 0.1, 100));
    println!(
        "there and back (2 × 100 steps of 0.1): midpoint {:.1e}, dla4 {:.1e}, cortes_martinez {:.1e}",
        misses[0], misses[1], misses[2]
    );
    assert!(misses[0] <= 1e-13 && misses[1] <= 1e-13, "{misses:?}");
    assert!(misses[2] >= 1e-2, "{misses:?}");
}

#[test]
fn over_a_long_run_the_reversible_energy_stays_bounded_and_cortes_martinez_drifts() {
    // 10⁵ steps of 0.1 (t = 10⁴). The reversible step's energy error oscillates in a band of
    // O(h²) that does not grow; Cortés–Martínez's drifts down (the particle loses its energy
    // like a damped one), by much more than that band, and more the longer it runs.
    let model = particle();
    let (h, steps, every) = (0.1, 100_000, 100);
    let reversible = run(Method::Midpoint, (&Q0, &P0), h, steps, every);
    let drifting = run(Method::CortesMartinez, (&Q0, &P0), h, steps, every);
    let bound = energy_errors(&model, &reversible)
        .iter()
        .fold(0.0_f64, |a, e| a.max(e.abs()));
    let stats = common::energy_statistics(&model.system, &reversible);
    let e = energy_errors(&model, &drifting);
    // |ΔE| at t = 10², 10³, 10⁴: it grows with t.
    let at = |t: f64| e[(t / (h * every as f64)).round() as usize].abs();
    let growth = [at(1e2), at(1e3), at(1e4)];
    let verdict = common::energy_statistics(&model.system, &drifting).verdict;
    println!(
        "energy over 10⁵ steps of 0.1: midpoint |ΔE| ≤ {bound:.2e} ({:?}); cortes_martinez |ΔE| at t = 1e2, 1e3, 1e4: {growth:?} ({verdict:?})",
        stats.verdict
    );
    assert!(common::conserved(stats.verdict), "{:?}", stats.verdict);
    assert!(bound <= 2.5e-3, "{bound:e}");
    assert!(
        growth[0] >= 20.0 * bound && growth[1] >= 1.5 * growth[0] && growth[2] >= growth[1],
        "{growth:?}"
    );
    // Both stay on the constraint to round-off over the run (4e-16 and 1.4e-14 measured).
    let residuals = [&reversible, &drifting].map(|traj| constraint_residual(&model, traj));
    println!("|A q̇| ≤ {residuals:?} ‖A‖‖q̇‖");
    assert!(residuals.iter().all(|r| *r <= 1e-13), "{residuals:?}");
}

#[test]
fn dla4_is_of_order_4_and_keeps_the_constraint_and_a_bounded_energy() {
    // Against dla4 with h = 1/1000 at T = 10 (its error ~1e-12), the state errors of dla4 fall
    // at order 4, midpoint's at 2 and cortes_martinez's at 1.
    let steps = |h: f64| (10.0 / h).round() as usize;
    let reference = run(Method::Dla4, (&Q0, &P0), 1e-3, 10_000, 10_000);
    let last = reference.len() - 1;
    let (q_ref, p_ref) = (reference.q_at(last), reference.p_at(last));
    let errors = |method| -> Vec<f64> {
        [0.1, 0.05, 0.025, 0.0125]
            .map(|h| common::final_error(&run(method, (&Q0, &P0), h, steps(h), steps(h)), q_ref, p_ref))
            .to_vec()
    };
    common::assert_order("dla4 at T = 10", &errors(Method::Dla4), 4.0, 0.1);
    common::assert_order("midpoint at T = 10", &errors(Method::Midpoint), 2.0, 0.1);
    common::assert_order("cortes_martinez at T = 10", &errors(Method::CortesMartinez), 1.0, 0.15);
    // 10⁵ composed steps of 0.1: every stage ends on the constraint; the energy error is bounded.
    let model = particle();
    let long = run(Method::Dla4, (&Q0, &P0), 0.1, 100_000, 100);
    let stats = common::energy_statistics(&model.system, &long);
    let residual = constraint_residual(&model, &long);
    println!(
        "dla4, 10⁵ steps of 0.1: max |ΔE| = {:.2e} ({:?}), |A q̇| ≤ {residual:.1e}",
        stats.max_abs_error, stats.verdict
    );
    assert!(common::conserved(stats.verdict), "{:?}", stats.verdict);
    assert!(stats.max_abs_error <= 3e-5, "{}", stats.max_abs_error);
    assert!(residual <= 1e-14, "{residual:e}");
}

#[test]
fn the_variants_take_velocity_constraints_alone() {
    // On a model without velocity constraints they are refused, naming the method.
    let well = well();
    for method in Method::NONHOLONOMIC {
        let err = integrate(&well, method, &Q0, &P0, &Options::new(0.1, 10), || Ok(())).unwrap_err();
        let message = err.error.to_string();
        assert!(
            message.starts_with("method:") && message.contains("velocity constraints"),
            "{message}"
        );
        assert_eq!(Method::from_name(method.info().name).unwrap(), method);
    }
}
