//! The energy a run of an L that depends on t tracks (−Σ∂L_d/∂t on each rule's quadrature, in
//! `Trajectory::work`): E − E₀ − W falls at the method's order on a parametric oscillator, with
//! ∂L/∂t exact and differenced, and the run's energy check holds it.

use varmech::integrators::{integrate, General, Method, Options};
use varmech::model::Lagrangian;
use varmech::ModelError;

/// q̈ = −ω(t)²q, ω = 1 + ½ sin t; `exact`: ∂L/∂t given, else the trait's difference.
struct Parametric {
    exact: bool,
}

fn omega(t: f64) -> f64 {
    1.0 + 0.5 * t.sin()
}

impl Lagrangian for Parametric {
    fn dim(&self) -> usize {
        1
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        Ok(0.5 * v[0] * v[0] - 0.5 * omega(t).powi(2) * q[0] * q[0])
    }

    fn dl_dq(&self, q: &[f64], _v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = -omega(t).powi(2) * q[0];
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out[0] = v[0];
        Ok(())
    }

    fn is_time_dependent(&self) -> bool {
        true
    }

    fn dl_dt(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        if self.exact {
            Ok(-omega(t) * 0.5 * t.cos() * q[0] * q[0])
        } else {
            varmech::model::differenced_dl_dt(self, q, v, t)
        }
    }
}

/// max |E − E₀ − W| over a run to t = 20 at step h.
fn balance(model: &Parametric, method: Method, h: f64) -> f64 {
    let steps = (20.0 / h).round() as usize;
    let traj = integrate(&General(model), method, &[1.0], &[0.0], &Options::new(h, steps), || {
        Ok(())
    })
    .unwrap();
    let energy = |k: usize| model.energy(traj.q_at(k), traj.p_at(k), traj.t[k]).unwrap();
    let e0 = energy(0);
    (0..traj.len())
        .map(|k| (energy(k) - e0 - traj.work[k]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_balance_of_a_parametric_oscillator_falls_at_each_rules_order() {
    for (method, order, exact) in [
        (Method::Midpoint, 2.0, false),
        (Method::Trapezoid, 2.0, false),
        (Method::Galerkin4, 4.0, true),
        (Method::Galerkin6, 6.0, true),
    ] {
        let model = Parametric { exact };
        let errors: Vec<f64> = [0.1, 0.05, 0.025].iter().map(|&h| balance(&model, method, h)).collect();
        for pair in errors.windows(2) {
            let measured = (pair[0] / pair[1]).log2();
            assert!((measured - order).abs() < 0.25, "{method:?}: {errors:?}");
        }
    }
}
