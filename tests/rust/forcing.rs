//! Forced systems by the discrete Lagrange–d'Alembert principle: a damped linear oscillator,
//! L = ½q̇² − ½ω²q² with the Rayleigh force f = −c q̇.

use crate::common;

use varmech::integrators::{integrate, General, Method, Options, Trajectory};
use varmech::model::Lagrangian;
use varmech::ModelError;

const OMEGA: f64 = 1.0;
const C: f64 = 0.1;

struct Damped;

impl Lagrangian for Damped {
    fn dim(&self) -> usize {
        1
    }
    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(0.5 * v[0] * v[0] - 0.5 * OMEGA * OMEGA * q[0] * q[0])
    }
    fn dl_dq(&self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = -OMEGA * OMEGA * q[0];
        Ok(())
    }
    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = v[0];
        Ok(())
    }
    fn is_forced(&self) -> bool {
        true
    }
    fn force(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = -C * v[0];
        Ok(())
    }
}

fn run(method: Method, h: f64, steps: usize, save_every: usize) -> Trajectory {
    let options = Options {
        save_every,
        ..Options::new(h, steps)
    };
    integrate(&General(&Damped), method, &[1.0], &[0.0], &options, || Ok(())).unwrap()
}

fn energy(traj: &Trajectory, k: usize) -> f64 {
    Damped.energy(traj.q_at(k), traj.p_at(k), traj.t[k]).unwrap()
}

/// The exact energy from (q, q̇) = (1, 0): q = e^{−ct/2}(cos ω_d t + (c/2ω_d) sin ω_d t).
fn exact_energy(t: f64) -> f64 {
    let wd = (OMEGA * OMEGA - 0.25 * C * C).sqrt();
    let (s, c) = (wd * t).sin_cos();
    let decay = (-0.5 * C * t).exp();
    let q = decay * (c + 0.5 * C / wd * s);
    let v = -decay * (OMEGA * OMEGA / wd) * s;
    0.5 * (v * v + OMEGA * OMEGA * q * q)
}

#[test]
fn the_energy_balance_with_the_tracked_work_holds_to_round_off() {
    // For a quadratic L the midpoint rule's energy changes by exactly f(q̄, v)·δq a step, and
    // Galerkin's by its Gauss quadrature of the power f·q̇, exact on the polynomial solution.
    for method in [Method::Midpoint, Method::Galerkin4, Method::Galerkin6] {
        let traj = run(method, 0.1, 10_000, 10);
        assert!(
            traj.work.last().unwrap() < &-0.49,
            "almost all the energy is dissipated"
        );
        for k in 0..traj.len() {
            let balance = energy(&traj, k) - energy(&traj, 0) - traj.work[k];
            assert!(
                balance.abs() < 1e-14,
                "{method:?}, step {}: E − E₀ − W = {balance:e}",
                k * 10
            );
        }
    }
}

#[test]
fn the_discrete_energy_decay_matches_the_exact_rate_at_the_method_order() {
    let t_end = 20.0;
    for method in crate::common::IMPLICIT {
        let n0 = if method.info().order > 2 { 25 } else { 100 };
        let errors: Vec<f64> = (0..4)
            .map(|k| {
                let steps = n0 << k;
                let traj = run(method, t_end / steps as f64, steps, steps);
                (energy(&traj, 1) - exact_energy(t_end)).abs()
            })
            .collect();
        common::assert_order(&format!("{method:?}: energy"), &errors, method.info().order as f64, 0.3);
    }
}

#[test]
fn a_forced_system_checks_its_energy_balance() {
    // The damped oscillator loses most of its energy: its balance E − W holds, and the check
    // on it, at a tolerance far below the energy lost, never fires.
    let options = Options {
        max_energy_error: Some(1e-6),
        ..Options::new(0.1, 200)
    };
    let traj = integrate(&General(&Damped), Method::Midpoint, &[1.0], &[0.0], &options, || Ok(())).unwrap();
    let terms = varmech::diagnostics::energy_terms(&Damped, &traj).unwrap();
    assert!(terms[traj.len() - 1].energy < 0.5 * terms[0].energy);
    let balance = varmech::diagnostics::energy_statistics(&traj.t, &terms, &traj.work, traj.steps as u64).unwrap();
    assert!(balance.max_rel_error < 1e-6, "{balance:?}");
}

#[test]
fn a_motion_damped_through_the_subnormal_numbers_to_rest_keeps_converging() {
    // e^{−ct/2} falls below the smallest normal number (2.2e−308) at t ≈ 14 200 and below the
    // smallest subnormal at t ≈ 14 900: there the increments carry no relative precision, and
    // a relative test alone would never call Newton's corrections small enough.
    for method in [Method::Midpoint, Method::Trapezoid, Method::Galerkin4] {
        let traj = run(method, 0.1, 160_000, 1_000);
        let subnormal = traj.q.iter().any(|q| q.abs() < f64::MIN_POSITIVE && *q != 0.0);
        assert!(subnormal, "{method:?}: the run passes through the subnormal numbers");
        let last = traj.q_at(traj.len() - 1)[0];
        assert!(last.abs() < 1e-310, "{method:?}: at rest, q = {last:e}");
    }
}
