//! Large steps near a separatrix: the pendulum q̈ = −sin q started at rest at q₀ = 3, just below
//! the top (E₀ = −cos 3 = 0.990, the separatrix is at E = 1).
//!
//! The midpoint rule's DEL equation for q₁ given (q₀, p₀) is F(q₁) = p₀ − v − (h/2) sin q̄ = 0
//! with v = (q₁ − q₀)/h, q̄ = (q₀ + q₁)/2, and F'(q₁) = −1/h − (h/4) cos q̄, whose continuum sign
//! is negative. For h < 2 F is monotone and the step's solution unique; for h > 2 F' changes sign
//! where cos q̄ < −4/h², i.e. near the top, and the equation has several solutions there.

use varmech::integrators::{
    integrate, integrate_watching, Detector, EventSpec, Failure, Method, NativeEvent, Options, Trajectory, Watch,
};
use varmech::scenes::Pendulum;
use varmech::Error;

const Q0: f64 = 3.0;

fn run(method: Method, h: f64, steps: usize, max_energy_error: Option<f64>) -> Result<Trajectory, Box<Failure>> {
    let options = Options {
        max_energy_error,
        ..Options::new(h, steps)
    };
    integrate(&Pendulum::new(), method, &[Q0], &[0.0], &options, || Ok(()))
}

#[test]
fn a_midpoint_step_beyond_the_fold_is_refused_as_a_spurious_branch() {
    for h in [2.5, 3.0, 4.0, 8.0] {
        // The first step lands beyond the fold: the pendulum would jump over the top although
        // E < 1. The run stops there and keeps the initial state.
        match run(Method::Midpoint, h, 100, None).map_err(|f| *f) {
            Err(Failure {
                error: Error::SpuriousBranch { step: 1, time, .. },
                partial,
            }) => {
                assert_eq!(time, 0.0);
                assert_eq!(partial.len(), 1);
            }
            Err(Failure { error: e, .. }) => panic!("h = {h}: expected a spurious branch at step 1, got {e}"),
            Ok(traj) => panic!("h = {h}: ran silently to q = {:?}", traj.q_at(traj.len() - 1)),
        }
    }
    // At h = 2 the fold is only reached at q̄ = π exactly; Newton's method fails at the near-
    // singular Jacobian instead, and says so.
    for h in [2.0, 2.2] {
        let result = run(Method::Midpoint, h, 100, None).map_err(|f| *f);
        assert!(
            matches!(
                &result,
                Err(Failure {
                    error: Error::Convergence { .. } | Error::SpuriousBranch { .. },
                    ..
                })
            ),
            "h = {h}: {:?}",
            result.map(|t| t.len()).map_err(|f| f.error.to_string())
        );
    }
}

#[test]
fn below_the_fold_no_step_is_flagged() {
    // F' < 0 everywhere for h < 2: every step has one solution and none may be refused (the
    // run ends in rotation after many steps because its energy error reaches the separatrix,
    // which only an energy bound can tell; see the next test).
    for h in [0.1, 0.5, 1.0, 1.5] {
        let traj =
            run(Method::Midpoint, h, (400.0 / h) as usize, None).unwrap_or_else(|f| panic!("h = {h}: {}", f.error));
        assert_eq!(traj.steps, (400.0 / h) as usize);
    }
}

#[test]
fn with_an_energy_bound_no_implicit_method_silently_goes_over_the_top() {
    // A state with |q| ≥ π has passed the top, impossible at E₀ < 1. The crossing is a jump of
    // the energy error that stays, not growth, which the run's energy check lets run; a terminal
    // event at a 1% energy error (the separatrix is 1% above E₀) stops it: every run from h = 0.5
    // to 4 either stops with a typed error or at the event, or stays in libration, and every
    // state it returns is in libration.
    for method in crate::common::IMPLICIT {
        for h in [0.5, 1.0, 1.5, 2.0, 2.01, 2.5, 3.0, 4.0] {
            let steps = (400.0 / h) as usize;
            let bound = NativeEvent::EnergyError {
                bound: 0.01,
                initial: f64::NAN,
            };
            bound.check("bound", 1).unwrap();
            let spec = EventSpec {
                name: "|E - E0| > 0.01".into(),
                direction: 1,
                terminal: 1,
            };
            let mut detector = Detector::new(Box::new(vec![bound]), vec![spec]).unwrap();
            let run = integrate_watching(
                &Pendulum::new(),
                method,
                &[Q0],
                &[0.0],
                &Options::new(h, steps),
                || Ok(()),
                Watch::events(&mut detector),
            );
            let traj = match run.map_err(|f| *f) {
                Ok(traj) => traj,
                Err(Failure {
                    error: Error::Divergence { .. } | Error::Convergence { .. } | Error::SpuriousBranch { .. },
                    partial,
                }) => partial,
                Err(f) => panic!("{method:?}, h = {h}: {}", f.error),
            };
            let top = (0..traj.len()).map(|k| traj.q_at(k)[0].abs()).fold(0.0, f64::max);
            assert!(top < std::f64::consts::PI, "{method:?}, h = {h}: |q| reached {top}");
        }
    }
}
