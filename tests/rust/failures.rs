//! Bad input gets a typed error naming the argument; a failing model or an interrupt stops the
//! run with the step, the time and every state up to the last good step.

use std::cell::Cell;

use varmech::integrators::{integrate, Method, Options};
use varmech::model::{Mass, MechanicalSystem};
use varmech::scenes::{Kepler, Pendulum};
use varmech::{Error, ModelError};

fn invalid_argument(q0: &[f64], p0: &[f64], options: &Options) -> &'static str {
    let sys = Kepler::new();
    match integrate(&sys, Method::Verlet, q0, p0, options, || Ok(())) {
        Err(f) => match f.error {
            Error::InvalidArgument { argument, .. } => argument,
            e => panic!("expected InvalidArgument, got {e}"),
        },
        Ok(_) => panic!("accepted bad input"),
    }
}

#[test]
fn bad_input_names_the_argument() {
    let ok = Options::new(0.1, 10);
    assert_eq!(invalid_argument(&[1.0], &[0.0, 1.0], &ok), "q0");
    assert_eq!(invalid_argument(&[1.0, 0.0], &[0.0, f64::NAN], &ok), "p0");
    assert_eq!(invalid_argument(&[f64::INFINITY, 0.0], &[0.0, 1.0], &ok), "q0");
    for dt in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(invalid_argument(&[1.0, 0.0], &[0.0, 1.0], &Options::new(dt, 10)), "dt");
    }
    assert_eq!(
        invalid_argument(
            &[1.0, 0.0],
            &[0.0, 1.0],
            &Options {
                save_every: 0,
                ..ok.clone()
            }
        ),
        "save_every"
    );
    assert_eq!(
        invalid_argument(
            &[1.0, 0.0],
            &[0.0, 1.0],
            &Options {
                max_energy_error: Some(-1.0),
                ..ok
            }
        ),
        "max_energy_error"
    );
    assert!(matches!(
        Method::from_name("leapfrog"),
        Err(Error::InvalidArgument { argument: "method", .. })
    ));
    assert!(matches!(
        Mass::diagonal(vec![1.0, 0.0]),
        Err(Error::InvalidArgument { argument: "mass", .. })
    ));
}

/// A pendulum whose gradient fails on its `fail_at`-th evaluation.
struct Failing {
    inner: Pendulum,
    calls: Cell<usize>,
    fail_at: usize,
}

#[derive(Debug)]
struct Boom;
impl std::fmt::Display for Boom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("boom")
    }
}
impl std::error::Error for Boom {}

impl MechanicalSystem for Failing {
    fn dim(&self) -> usize {
        1
    }
    fn mass(&self) -> &Mass {
        self.inner.mass()
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        self.inner.potential(q)
    }
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.calls.set(self.calls.get() + 1);
        if self.calls.get() == self.fail_at {
            return Err(Box::new(Boom));
        }
        self.inner.gradient(q, grad)
    }
}

#[test]
fn a_failing_model_keeps_every_good_step() {
    // Verlet evaluates once before step 1 and once per step: evaluation 8 is step 7's.
    let sys = Failing {
        inner: Pendulum::new(),
        calls: Cell::new(0),
        fail_at: 8,
    };
    let failure = integrate(&sys, Method::Verlet, &[0.0], &[1.0], &Options::new(0.1, 100), || Ok(())).unwrap_err();
    match &failure.error {
        Error::Model { step: 7, time, source } => {
            assert!((time - 0.6).abs() < 1e-12);
            assert!(source.downcast_ref::<Boom>().is_some(), "the model's own error is kept");
        }
        e => panic!("expected a model error at step 7, got {e}"),
    }
    assert_eq!(failure.partial.len(), 7, "states 0..=6 are kept");
    assert_eq!(failure.partial.steps, 6);
    // The kept states are those of an undisturbed run.
    let clean = integrate(
        &Pendulum::new(),
        Method::Verlet,
        &[0.0],
        &[1.0],
        &Options::new(0.1, 6),
        || Ok(()),
    )
    .unwrap();
    assert_eq!(failure.partial.q, clean.q);
    assert_eq!(failure.partial.p, clean.p);
}

#[test]
fn an_energy_threshold_stops_a_run_that_blows_up() {
    // Explicit Euler multiplies the oscillator's energy by 1 + h² a step.
    let sys = varmech::scenes::HarmonicOscillator::new(1.0).unwrap();
    let options = Options {
        max_energy_error: Some(1.0),
        ..Options::new(0.1, 10_000)
    };
    let failure = integrate(&sys, Method::ExplicitEuler, &[0.0], &[1.0], &options, || Ok(())).unwrap_err();
    // The documented rule, by hand: the first step k where |E_k − E₀| reaches the mean kinetic
    // energy p²/2 of the states 0..=k (Euler: q ← q + hp, p ← p − hq).
    let (mut q, mut p, mut kinetic, mut k) = (0.0_f64, 1.0_f64, 0.5_f64, 0_usize);
    while (0.5 * (q * q + p * p) - 0.5).abs() < kinetic / (k + 1) as f64 {
        (q, p, k) = (q + 0.1 * p, p - 0.1 * q, k + 1);
        kinetic += 0.5 * p * p;
    }
    assert!((40..70).contains(&k), "{k}");
    assert!(
        matches!(failure.error, Error::Divergence { step, .. } if step == k),
        "{} (expected step {k})",
        failure.error
    );
    assert_eq!(failure.partial.len(), k + 1);
}

#[test]
fn an_interrupt_stops_the_run_with_its_partial_trajectory() {
    let sys = Kepler::new();
    let mut polls = 0;
    let options = Options {
        save_every: 1000,
        ..Options::new(0.001, 1_000_000_000)
    };
    let failure = integrate(&sys, Method::Verlet, &[0.4, 0.0], &[0.0, 2.0], &options, || {
        polls += 1;
        if polls == 5 {
            Err("interrupted".into())
        } else {
            Ok(())
        }
    })
    .unwrap_err();
    match failure.error {
        Error::Interrupted { step, .. } => assert_eq!(failure.partial.steps, step - 1),
        e => panic!("expected an interrupt, got {e}"),
    }
    assert!(failure.partial.len() >= 2);
}
