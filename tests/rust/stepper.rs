//! The stepper takes `integrate`'s steps: stepping one at a time, advancing n, and taking the
//! stepper apart and resuming it in between all land on `integrate`'s final state bit for bit;
//! `reset` and `set_dt` make it a fresh stepper; malformed arguments are typed errors.

use varmech::integrators::{integrate, Dynamics, General, Method, Options, Stepper, StepperState};
use varmech::scenes::{planar_chain, DoublePendulum, FermiPastaUlam, HarmonicOscillator, HeavyTop, Kepler};
use varmech::Error;

/// Bits of a state, so that -0.0 ≠ 0.0 and equality means the same floating-point numbers.
fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// t, q, p, steps and the work counts of a stepper, bit for bit.
fn snapshot(s: &StepperState) -> (u64, Vec<u64>, Vec<u64>, usize, u64, u64) {
    (
        s.t().to_bits(),
        bits(s.q()),
        bits(s.p()),
        s.steps(),
        s.force_evaluations(),
        s.newton_iterations(),
    )
}

/// `integrate`'s final state over `steps` steps, and the same from a stepper stepped one at a
/// time, advanced at once, and taken apart and resumed (owned, then borrowed) on the way.
fn agrees_with_integrate<S: Dynamics + ?Sized>(sys: &S, method: Method, q0: &[f64], p0: &[f64], dt: f64, steps: usize) {
    let options = Options {
        save_every: steps,
        t0: 0.25,
        ..Options::new(dt, steps)
    };
    let traj = integrate(sys, method, q0, p0, &options, || Ok(())).unwrap();
    let last = traj.len() - 1;
    let reference = (
        traj.t[last].to_bits(),
        bits(traj.q_at(last)),
        bits(traj.p_at(last)),
        traj.steps,
        traj.force_evaluations,
        traj.newton_iterations,
    );

    let mut one_by_one = Stepper::new(sys, method, q0, p0, &options).unwrap();
    for _ in 0..steps {
        one_by_one.step().unwrap();
    }
    assert_eq!(snapshot(&one_by_one), reference, "{method:?}: step() × {steps}");

    let mut at_once = Stepper::new(sys, method, q0, p0, &options).unwrap();
    at_once.advance(steps, || Ok(())).unwrap();
    assert_eq!(snapshot(&at_once), reference, "{method:?}: advance({steps})");

    let mut first = Stepper::new(sys, method, q0, p0, &options).unwrap();
    first.advance(steps / 3, || Ok(())).unwrap();
    let mut state = first.into_state();
    let mut second = Stepper::resume(sys, &mut state).unwrap();
    second.advance(steps / 3, || Ok(())).unwrap();
    let mut third = Stepper::resume(sys, state).unwrap();
    third.advance(steps - 2 * (steps / 3), || Ok(())).unwrap();
    assert_eq!(snapshot(&third), reference, "{method:?}: taken apart and resumed");
}

#[test]
fn verlet_on_kepler_takes_integrates_steps() {
    let kepler = Kepler::problem(0.6).unwrap();
    agrees_with_integrate(
        &kepler.system,
        Method::Verlet,
        &kepler.initial.q,
        &kepler.initial.p,
        0.01,
        1000,
    );
}

#[test]
fn the_midpoint_rule_on_the_double_pendulum_takes_integrates_steps() {
    let pendulum = DoublePendulum::problem();
    let sys = General(&pendulum.system);
    agrees_with_integrate(
        &sys,
        Method::Midpoint,
        &pendulum.initial.q,
        &pendulum.initial.p,
        0.01,
        300,
    );
}

/// The two-point DEL methods run up to 4 coordinates in a loop of fixed-size arrays
/// (`Stepper::advance`, `integrate`) and step one at a time by the general step
/// (`Stepper::step`): the same bits and counts at every size, with exact second derivatives
/// (the pendulums, the top) and by differences (the oscillator, FPU through L = T − V), and
/// beyond 4 (FPU's 6) where both take the general step.
#[test]
fn the_two_point_del_methods_take_integrates_steps_at_every_size() {
    let oscillator = HarmonicOscillator::problem(1.3).unwrap();
    let pendulum = DoublePendulum::problem();
    let top = HeavyTop::problem();
    let fpu4 = FermiPastaUlam::new(2, 20.0).unwrap();
    let fpu6 = FermiPastaUlam::problem();
    /// A model, its (q0, p0) and the step.
    type Case<'a> = (&'a dyn Dynamics, &'a [f64], &'a [f64], f64);
    let cases: [Case; 5] = [
        (
            &General(&oscillator.system),
            &oscillator.initial.q,
            &oscillator.initial.p,
            0.1,
        ),
        (
            &General(&pendulum.system),
            &pendulum.initial.q,
            &pendulum.initial.p,
            0.01,
        ),
        (&General(&top.system), &top.initial.q, &top.initial.p, 0.01),
        (&General(&fpu4), &[0.3, 0.0, -0.2, 0.1], &[0.0, 1.0, 0.5, -0.4], 0.01),
        (&General(&fpu6.system), &fpu6.initial.q, &fpu6.initial.p, 0.01),
    ];
    for (sys, q0, p0, dt) in cases {
        assert_eq!(sys.dim(), q0.len());
        for method in [Method::Midpoint, Method::Trapezoid] {
            agrees_with_integrate(sys, method, q0, p0, dt, 300);
        }
    }
}

#[test]
fn rattle_on_a_planar_chain_takes_integrates_steps() {
    let chain = planar_chain(4).unwrap();
    agrees_with_integrate(
        &chain.system,
        Method::Rattle,
        &chain.initial.q,
        &chain.initial.p,
        0.01,
        300,
    );
}

/// A stepper reset to (t0, q0, p0) with a new step, after steps from elsewhere, takes the
/// steps of a fresh stepper from there (the work counts go on, so they are not compared).
fn reset_is_a_fresh_start<S: Dynamics + ?Sized>(sys: &S, method: Method, q0: &[f64], p0: &[f64], dt: f64) {
    let options = Options::new(dt, 0);
    let mut run = Stepper::new(sys, method, q0, p0, &options).unwrap();
    run.advance(40, || Ok(())).unwrap();
    let (t1, q1, p1) = (run.t(), run.q().to_vec(), run.p().to_vec());
    run.advance(25, || Ok(())).unwrap();

    run.reset(t1, &q1, &p1).unwrap();
    run.set_dt(0.7 * dt).unwrap();
    run.advance(30, || Ok(())).unwrap();

    let fresh_options = Options {
        t0: t1,
        ..Options::new(0.7 * dt, 0)
    };
    let mut fresh = Stepper::new(sys, method, &q1, &p1, &fresh_options).unwrap();
    fresh.advance(30, || Ok(())).unwrap();
    assert_eq!(run.t().to_bits(), fresh.t().to_bits(), "{method:?}: t");
    assert_eq!(run.steps(), 30, "{method:?}: steps counted from the reset");
    assert_eq!(bits(run.q()), bits(fresh.q()), "{method:?}: q");
    assert_eq!(bits(run.p()), bits(fresh.p()), "{method:?}: p");
}

#[test]
fn reset_and_set_dt_give_a_fresh_stepper() {
    let kepler = Kepler::problem(0.6).unwrap();
    for method in [Method::Verlet, Method::KahanLi6, Method::Rk4, Method::Midpoint] {
        reset_is_a_fresh_start(&kepler.system, method, &kepler.initial.q, &kepler.initial.p, 0.01);
    }
    let pendulum = DoublePendulum::problem();
    for method in [Method::Midpoint, Method::Galerkin4] {
        reset_is_a_fresh_start(
            &General(&pendulum.system),
            method,
            &pendulum.initial.q,
            &pendulum.initial.p,
            0.01,
        );
    }
    let chain = planar_chain(4).unwrap();
    for method in [Method::Rattle, Method::Rattle4] {
        reset_is_a_fresh_start(&chain.system, method, &chain.initial.q, &chain.initial.p, 0.01);
    }
}

#[test]
fn set_dt_continues_from_the_current_time() {
    let kepler = Kepler::problem(0.6).unwrap();
    let options = Options {
        t0: 1.0,
        ..Options::new(0.01, 0)
    };
    let mut stepper = Stepper::new(
        &kepler.system,
        Method::Verlet,
        &kepler.initial.q,
        &kepler.initial.p,
        &options,
    )
    .unwrap();
    stepper.advance(10, || Ok(())).unwrap();
    let t10 = stepper.t();
    assert_eq!(t10, 1.0 + 10.0 * 0.01);
    stepper.set_dt(0.003).unwrap();
    assert_eq!(stepper.t(), t10);
    stepper.advance(7, || Ok(())).unwrap();
    assert_eq!(stepper.t(), t10 + 7.0 * 0.003);
    assert_eq!((stepper.steps(), stepper.dt()), (17, 0.003));
}

fn invalid_argument<T>(result: Result<T, Error>) -> &'static str {
    match result {
        Err(Error::InvalidArgument { argument, .. }) => argument,
        Err(e) => panic!("expected an invalid argument, got {e}"),
        Ok(_) => panic!("expected an invalid argument"),
    }
}

#[test]
fn malformed_arguments_are_refused_and_leave_the_state_alone() {
    let kepler = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&kepler.initial.q, &kepler.initial.p);
    let mut stepper = Stepper::new(&kepler.system, Method::Verlet, q0, p0, &Options::new(0.01, 0)).unwrap();
    stepper.advance(5, || Ok(())).unwrap();
    let before = snapshot(&stepper);
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(invalid_argument(stepper.set_dt(h)), "dt");
    }
    assert_eq!(invalid_argument(stepper.reset(0.0, &[1.0], p0)), "q0");
    assert_eq!(invalid_argument(stepper.reset(0.0, q0, &[f64::NAN, 0.0])), "p0");
    assert_eq!(invalid_argument(stepper.reset(f64::INFINITY, q0, p0)), "t0");
    assert_eq!(snapshot(&stepper), before);

    // A state resumes only on a model it fits: as many coordinates, a kind its method integrates.
    let mut state = stepper.into_state();
    let pendulum = DoublePendulum::problem();
    let lagrangian = General(&pendulum.system);
    assert_eq!(invalid_argument(Stepper::resume(&lagrangian, &mut state)), "method");
    let chain = planar_chain(4).unwrap();
    assert_eq!(invalid_argument(Stepper::resume(&chain.system, &mut state)), "model");
    assert_eq!(snapshot(&Stepper::resume(&kepler.system, state).unwrap()), before);
}

/// Steps shorter than 4 ulp of the run's times are refused naming `dt` (t₀ = 1.7·10⁹ s of Unix
/// time, steps of 0.1 µs: the times would repeat and the rows be lost), by a run, a resumed
/// run and a stepper alike; at 4 ulp every time is its own and every step's row is kept.
#[test]
fn steps_below_the_resolution_of_the_time_are_refused_and_those_above_keep_every_row() {
    let sho = HarmonicOscillator::problem(1.0).unwrap();
    let (q0, p0) = (&sho.initial.q, &sho.initial.p);
    let t0: f64 = 1.7e9;
    let ulp = f64::from_bits(t0.to_bits() + 1) - t0;
    let run = |t0: f64, dt: f64, steps: usize| {
        let options = Options {
            t0,
            ..Options::new(dt, steps)
        };
        integrate(&sho.system, Method::Verlet, q0, p0, &options, || Ok(())).map_err(|f| f.error)
    };
    for dt in [1e-7, 3.99 * ulp] {
        assert_eq!(invalid_argument(run(t0, dt, 1000)), "dt");
        assert_eq!(invalid_argument(run(-t0, dt, 1000)), "dt");
        let options = Options {
            t0,
            ..Options::new(dt, 0)
        };
        assert_eq!(
            invalid_argument(Stepper::new(&sho.system, Method::Verlet, q0, p0, &options)),
            "dt"
        );
    }
    let traj = run(t0, 4.0 * ulp, 1000).unwrap();
    assert_eq!((traj.t.len(), traj.steps), (1001, 1000));
    assert!(traj.t.windows(2).all(|w| w[1] > w[0]));
    // The same steps from t₀ = 0: the time is not read by the model, so the states are these.
    let from_zero = run(0.0, 4.0 * ulp, 1000).unwrap();
    assert_eq!(bits(&traj.q), bits(&from_zero.q));
    // A stepper, and a run resumed, whose steps would reach a time where 4 ulp passes dt.
    // Below 2⁵⁰ the floats are 1/8 apart, above it 1/4: steps of 0.6 pass below, not above.
    let edge = 2.0_f64.powi(50);
    let options = Options {
        t0: edge - 8.0 * 0.6,
        ..Options::new(0.6, 4)
    };
    let mut stepper = Stepper::new(&sho.system, Method::Verlet, q0, p0, &options).unwrap();
    stepper.advance(7, || Ok(())).unwrap();
    assert_eq!(invalid_argument(stepper.advance(2, || Ok(()))), "dt");
    assert_eq!(stepper.steps(), 7, "the refused call took no step");
    let first = integrate(&sho.system, Method::Verlet, q0, p0, &options, || Ok(())).unwrap();
    let checkpoint = varmech::integrators::Checkpoint::from_bytes(&first.checkpoint).unwrap();
    let resumed = varmech::integrators::resume(&sho.system, checkpoint, 10, 1, || Ok(()));
    assert_eq!(invalid_argument(resumed.map_err(|f| f.error)), "dt");
}
