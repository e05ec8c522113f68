//! The energy a run of an L that depends on t tracks (−Σ∂L_d/∂t on each rule's quadrature, in
//! `Trajectory::work`): E − E₀ − W falls at the method's order on a parametric oscillator, with
//! ∂L/∂t exact and differenced, and the run's energy check holds it.

use std::cell::Cell;

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

/// [`Parametric`] (∂L/∂t exact) that also gives ∂L/∂t with its gradients, as a compiled L of t
/// does, counting how often each is asked for.
struct Counted {
    model: Parametric,
    gradients: Cell<usize>,
    with_dl_dt: Cell<usize>,
    dl_dt: Cell<usize>,
}

impl Lagrangian for Counted {
    fn dim(&self) -> usize {
        1
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        self.model.lagrangian(q, v, t)
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.model.dl_dq(q, v, t, out)
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.model.dl_dv(q, v, t, out)
    }

    fn gradients(&self, q: &[f64], v: &[f64], t: f64, dq: &mut [f64], dv: &mut [f64]) -> Result<(), ModelError> {
        self.gradients.set(self.gradients.get() + 1);
        self.model.gradients(q, v, t, dq, dv)
    }

    fn gradients_and_dl_dt(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<Option<f64>, ModelError> {
        self.with_dl_dt.set(self.with_dl_dt.get() + 1);
        self.model.gradients(q, v, t, dq, dv)?;
        self.model.dl_dt(q, v, t).map(Some)
    }

    fn is_time_dependent(&self) -> bool {
        true
    }

    fn dl_dt(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        self.dl_dt.set(self.dl_dt.get() + 1);
        self.model.dl_dt(q, v, t)
    }
}

#[test]
fn newton_takes_dl_dt_only_at_its_last_evaluation() {
    // The midpoint rule: Newton asks for ∂L/∂t once a step, at the evaluation its correction
    // ends on (the solution), and the gradients alone at its other evaluations; Galerkin's
    // rule once a node and step, at the solution. The balance is the same, to the bit, as
    // the model's own ∂L/∂t evaluated apart (the trait's default, `Parametric`).
    let steps = 400;
    for (method, nodes) in [(Method::Midpoint, 1), (Method::Galerkin4, 2)] {
        let counted = Counted {
            model: Parametric { exact: true },
            gradients: Cell::new(0),
            with_dl_dt: Cell::new(0),
            dl_dt: Cell::new(0),
        };
        fn run<L: Lagrangian>(model: &L, method: Method, steps: usize) -> varmech::integrators::Trajectory {
            integrate(
                &General(model),
                method,
                &[1.0],
                &[0.0],
                &Options::new(0.05, steps),
                || Ok(()),
            )
            .unwrap()
        }
        let (traj, plain) = (
            run(&counted, method, steps),
            run(&Parametric { exact: true }, method, steps),
        );
        assert_eq!(counted.with_dl_dt.get(), nodes * steps, "{method:?}");
        assert_eq!(counted.dl_dt.get(), 0, "{method:?}");
        assert!(counted.gradients.get() >= 2 * nodes * steps, "{method:?}");
        let bits = |w: &[f64]| w.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&traj.work), bits(&plain.work), "{method:?}");
        assert_eq!(bits(&traj.q), bits(&plain.q), "{method:?}");
    }
}
