//! The native step loop allocates nothing (with or without events): a long run makes exactly as many allocations as a
//! run of 100 steps (the set-up's), whatever the method, and so does RATTLE's on a chain and the
//! discrete Lagrange–d'Alembert step's on the rolling scenes and, with a holonomic constraint
//! too, on the skate; a
//! stepper's steps make none at all, nor does taking it apart, resuming and resetting it, nor
//! does a discrete energy E_d once made. A run with contacts allocates nothing in its steps
//! either, impacts included, but for the growth of its output (the impacts and the states at
//! them). Steps that carry tangent vectors allocate nothing after the first, which sizes the
//! tangent map's buffers.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ops::Deref;

use varmech::integrators::{
    integrate, integrate_watching, Contact, Contacts, Detector, DiscreteEnergy, Dynamics, EventSpec, Friction, General,
    Law, Method, ModelKind, NativeEvent, Options, Slip, SlipRows, Stepper, StepperState, Tangent, Trajectory, Watch,
    Watcher,
};
use varmech::model::Routhian;
use varmech::scenes::{self, NBody, NonholonomicScene, Problem, SceneModel};

#[path = "common/contacts.rs"]
#[allow(dead_code)] // the others serve the impact and hold tests
mod contacts;
#[path = "common/skate.rs"]
#[allow(dead_code)] // the skate's other forms serve the mixed-constraints tests
mod skate;
#[path = "common/tapes.rs"]
mod tapes;

struct Counting;

thread_local! {
    /// Allocations made by this thread: the tests run in parallel, each counts its own.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocated() -> usize {
    ALLOCATIONS.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // `try_with`: a thread being torn down has no counter left, and is not counted.
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by one run of `method` on `sys` from (q0, p0).
fn counted<S: Dynamics>(sys: &S, method: Method, q0: &[f64], p0: &[f64], options: &Options) -> usize {
    let before = allocated();
    let traj = integrate(sys, method, q0, p0, options, || Ok(())).unwrap();
    let count = allocated() - before;
    assert_eq!(traj.steps, options.steps);
    count
}

/// Allocations made by one run of `method` on a scene's `problem` from its initial state.
fn counted_from<S: Dynamics>(problem: &Problem<S>, method: Method, options: &Options) -> usize {
    counted(&problem.system, method, &problem.initial.q, &problem.initial.p, options)
}

fn allocations(method: Method, steps: usize, max_energy_error: Option<f64>) -> usize {
    let problem = NBody::outer_solar_system();
    let options = Options {
        save_every: 10,
        max_energy_error,
        ..Options::new(10.0, steps)
    };
    counted_from(&problem, method, &options)
}

#[test]
fn the_step_loop_allocates_nothing() {
    for method in Method::ALL.into_iter().chain(Method::WISDOM_HOLMAN) {
        // Newton's difference Jacobians make the implicit methods slow on 18 coordinates; a
        // shorter long run proves the same.
        let long_steps = if method.info().implicit { 2_000 } else { 100_000 };
        as_many_long_as_short(allocations, method, long_steps);
    }
}

/// Asserts that a run of `long_steps` steps of `method` makes as many `allocations` as a run of
/// 100, with and without an energy check. The check runs at every saved state; its tolerance is
/// one it cannot reach, since explicit Euler's energy error reaches the kinetic energy within
/// the long run.
fn as_many_long_as_short(allocations: fn(Method, usize, Option<f64>) -> usize, method: Method, long_steps: usize) {
    for check in [None, Some(f64::MAX)] {
        let short = allocations(method, 100, check);
        let long = allocations(method, long_steps, check);
        assert_eq!(
            short, long,
            "{method:?}: {short} allocations for 100 steps, {long} for {long_steps}"
        );
    }
}

/// As [`allocations`], for a constrained method on the planar chain of eight links.
fn constrained_allocations(method: Method, steps: usize, max_energy_error: Option<f64>) -> usize {
    let problem = scenes::planar_chain(8).unwrap();
    let mut options = Options {
        save_every: 10,
        max_energy_error,
        ..Options::new(0.01, steps)
    };
    if method == Method::Shake {
        // SHAKE's one-constraint-at-a-time sweeps converge slowly along a chain: on eight
        // links they do not reach the default 1e-14 within 50 sweeps, but reach 1e-10 in about
        // 44 a step.
        options.newton.tolerance = 1e-10;
        options.newton.max_iterations = 1_000;
    }
    counted_from(&problem, method, &options)
}

#[test]
fn the_constrained_step_loop_allocates_nothing() {
    for method in Method::CONSTRAINED {
        // SHAKE's forty-odd sweeps a step make it the slow one; a shorter long run proves the same.
        let long_steps = if method == Method::Shake { 2_000 } else { 10_000 };
        as_many_long_as_short(constrained_allocations, method, long_steps);
    }
}

#[test]
fn the_compiled_step_loop_allocates_nothing() {
    // Compiled models evaluate in a thread's scratch, grown on its first evaluation: a first
    // run warms it, and then runs of any length make the same allocations. As for every
    // general Lagrangian, the energy check at saved states solves the inverse Legendre
    // transform with a fresh Newton workspace; the steps are what this proves allocation-free.
    let problem = scenes::Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let options = |steps| Options {
        save_every: 10,
        max_energy_error: None,
        ..Options::new(0.01, steps)
    };
    for jit in [false, true] {
        let separable = tapes::kepler(1.0, jit);
        let lagrangian = tapes::pendulum_lagrangian();
        counted(&separable, Method::Verlet, q0, p0, &options(10));
        counted(&General(&lagrangian), Method::Midpoint, &[0.0], &[1.0], &options(10));
        for method in [Method::Verlet, Method::KahanLi8, Method::Midpoint] {
            let (short, long) = (
                counted(&separable, method, q0, p0, &options(100)),
                counted(&separable, method, q0, p0, &options(10_000)),
            );
            assert_eq!(
                short, long,
                "{method:?}, jit {jit}: {short} allocations for 100 steps, {long} for 10 000"
            );
        }
        for method in [Method::Midpoint, Method::Galerkin4] {
            let sys = General(&lagrangian);
            let (short, long) = (
                counted(&sys, method, &[0.0], &[1.0], &options(100)),
                counted(&sys, method, &[0.0], &[1.0], &options(10_000)),
            );
            assert_eq!(
                short, long,
                "{method:?} (Lagrangian): {short} allocations for 100 steps, {long} for 10 000"
            );
        }
    }
}

#[test]
fn the_routh_reduced_step_loop_allocates_nothing() {
    // The heavy top with φ and ψ ignored: each evaluation of R solves for (φ̇, ψ̇) in place.
    let problem = scenes::HeavyTop::problem();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let r = Routhian::new(&problem.system, &[1, 2], &p0[1..], &[0.0, 0.0]).unwrap();
    for method in [
        Method::Midpoint,
        Method::Trapezoid,
        Method::Galerkin4,
        Method::Galerkin6,
    ] {
        let run = |steps| {
            // The energy check at saved states solves the inverse Legendre transform with a
            // fresh Newton workspace; the steps are what this proves allocation-free.
            let options = Options {
                save_every: 10,
                max_energy_error: None,
                ..Options::new(0.01, steps)
            };
            counted(&General(&r), method, &q0[..1], &p0[..1], &options)
        };
        let (short, long) = (run(100), run(5_000));
        assert_eq!(
            short, long,
            "{method:?}: {short} allocations for 100 steps, {long} for 5000"
        );
    }
}

/// Allocations made by `steps` steps of `stepper` (one by `step`, the others by `advance`),
/// after a first step that sizes what a method sizes on first use.
fn stepper_allocations<M: Deref<Target: Dynamics>>(mut stepper: Stepper<M>, steps: usize) -> usize {
    stepper.step().unwrap();
    let before = allocated();
    stepper.step().unwrap();
    stepper.advance(steps - 1, || Ok(())).unwrap();
    let count = allocated() - before;
    assert_eq!(stepper.steps(), steps + 1);
    count
}

#[test]
fn the_stepper_allocates_nothing() {
    let problem = NBody::outer_solar_system();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let options = Options::new(10.0, 0);
    for method in Method::ALL.into_iter().chain(Method::WISDOM_HOLMAN) {
        let stepper = Stepper::new(&problem.system, method, q0, p0, &options).unwrap();
        let count = stepper_allocations(stepper, 200);
        assert_eq!(count, 0, "{method:?}: {count} allocations in 200 steps");
    }
    // A stepper that owns its model.
    let stepper = Stepper::new(Box::new(problem.system.clone()), Method::Verlet, q0, p0, &options).unwrap();
    assert_eq!(stepper_allocations(stepper, 200), 0);

    let chain = scenes::planar_chain(8).unwrap();
    for method in Method::CONSTRAINED {
        let mut options = Options::new(0.01, 0);
        if method == Method::Shake {
            // As in `constrained_allocations`.
            options.newton.tolerance = 1e-10;
            options.newton.max_iterations = 1_000;
        }
        let stepper = Stepper::new(&chain.system, method, &chain.initial.q, &chain.initial.p, &options).unwrap();
        let count = stepper_allocations(stepper, 200);
        assert_eq!(count, 0, "{method:?}: {count} allocations in 200 steps");
    }
}

#[test]
fn resuming_and_resetting_a_stepper_allocates_nothing() {
    let problem = NBody::outer_solar_system();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    for method in [Method::Verlet, Method::Midpoint, Method::WisdomHolmanCorrected] {
        let mut first = Stepper::new(&problem.system, method, q0, p0, &Options::new(10.0, 0)).unwrap();
        first.step().unwrap();
        let mut state: StepperState = first.into_state();
        let before = allocated();
        let mut borrowed = Stepper::resume(&problem.system, &mut state).unwrap();
        borrowed.advance(50, || Ok(())).unwrap();
        borrowed.reset(0.0, q0, p0).unwrap();
        borrowed.set_dt(5.0).unwrap();
        borrowed.advance(50, || Ok(())).unwrap();
        let mut owned = Stepper::resume(&problem.system, state).unwrap();
        owned.step().unwrap();
        let count = allocated() - before;
        assert_eq!(count, 0, "{method:?}: {count} allocations");
        assert_eq!(owned.steps(), 51);
    }
}

/// The allocations of a run of `steps` steps of `sys` from `start` watching `events` (none of
/// which may occur), every 10th state saved.
fn event_allocations<S: Dynamics>(
    sys: &S,
    method: Method,
    start: (&[f64], &[f64]),
    dt: f64,
    steps: usize,
    events: Vec<(NativeEvent, i8)>,
) -> usize {
    let options = Options {
        save_every: 10,
        ..Options::new(dt, steps)
    };
    let specs = events
        .iter()
        .enumerate()
        .map(|(i, (_, direction))| EventSpec {
            name: format!("event {i}"),
            direction: *direction,
            terminal: 1,
        })
        .collect();
    let functions = events.into_iter().map(|(e, _)| e).collect::<Vec<_>>();
    let mut detector = Detector::new(Box::new(functions), specs).unwrap();
    let before = allocated();
    let traj = integrate_watching(
        sys,
        method,
        start.0,
        start.1,
        &options,
        || Ok(()),
        Watch::events(&mut detector),
    )
    .unwrap();
    assert!(traj.events.is_empty() && traj.steps == steps);
    allocated() - before
}

/// A run with built-in events (an escape, an ellipsoid) that never occur allocates per run, not
/// per step: the events' values, the state before each step and the partial steps' stepper are made once.
#[test]
fn the_event_loop_allocates_nothing() {
    let problem = NBody::outer_solar_system();
    let run = |steps: usize| {
        let groups = (0..6).map(|b| vec![3 * b, 3 * b + 1, 3 * b + 2]).collect::<Vec<_>>();
        let escape = NativeEvent::Escape { radius: 1e6, groups };
        // The Sun's position leaving a large ellipsoid about the origin.
        let ellipsoid = NativeEvent::Ellipsoid {
            coordinates: vec![0, 1, 2],
            centre: vec![0.0; 3],
            semi_axes: vec![1e6, 2e6, 3e6],
            inside: true,
        };
        let start = (&problem.initial.q[..], &problem.initial.p[..]);
        event_allocations(
            &problem.system,
            Method::Verlet,
            start,
            10.0,
            steps,
            vec![(escape, 1), (ellipsoid, -1)],
        )
    };
    assert_eq!(run(100), run(10_000));
}

/// A run watching a multiplier (λ of a link of the planar chain, which never reaches 0 within
/// the run) allocates per run, not per step: the reaction's buffers are made at the run's start.
#[test]
fn a_multiplier_event_allocates_nothing_in_the_step_loop() {
    let problem = scenes::planar_chain(8).unwrap();
    let run = |steps: usize| {
        let multiplier = NativeEvent::Multiplier { row: 0, reaction: None };
        let start = (&problem.initial.q[..], &problem.initial.p[..]);
        event_allocations(
            &problem.system,
            Method::Rattle,
            start,
            0.01,
            steps,
            vec![(multiplier, 1)],
        )
    };
    assert_eq!(run(100), run(2_000));
}

/// As [`counted`], for a nonholonomic catalogue scene (its ∂A/∂q by central differences, on
/// per-thread scratch).
fn nonholonomic_allocations(name: &str, method: Method, steps: usize) -> usize {
    let problem = scenes::lookup(name).unwrap().setup().build().unwrap();
    let options = Options {
        save_every: 10,
        ..Options::new(0.01, steps)
    };
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    match &problem.system {
        SceneModel::Nonholonomic(NonholonomicScene::RollingDisk(s)) => counted(s, method, q0, p0, &options),
        SceneModel::Nonholonomic(NonholonomicScene::ChaplyginSleigh(s)) => counted(s, method, q0, p0, &options),
        SceneModel::Nonholonomic(NonholonomicScene::RollingSphere(s)) => counted(s, method, q0, p0, &options),
        other => panic!("{name} is not nonholonomic: {other:?}"),
    }
}

#[test]
fn the_nonholonomic_step_loop_allocates_nothing() {
    let methods = Method::ALL.into_iter().filter(|&m| ModelKind::Nonholonomic.admits(m));
    for method in methods {
        for name in [
            "rolling_disk",
            "chaplygin_sleigh",
            "rolling_sphere",
            "ball_on_turntable",
        ] {
            // A first run sizes the per-thread scratch of the differences and the Legendre transform.
            nonholonomic_allocations(name, method, 10);
            let (short, long) = (
                nonholonomic_allocations(name, method, 100),
                nonholonomic_allocations(name, method, 5_000),
            );
            assert_eq!(
                short, long,
                "{name}, {method:?}: {short} allocations for 100 steps, {long} for 5000"
            );
        }
    }
}

#[test]
fn the_mixed_constraints_step_loop_allocates_nothing() {
    // The skate: g(q) = 0 and A(q)q̇ = 0 together, the Jacobian by differences of the equations.
    let (model, q0, p0) = skate::skate();
    let methods = Method::ALL.into_iter().filter(|&m| ModelKind::Nonholonomic.admits(m));
    for method in methods {
        let run = |steps| {
            let options = Options {
                save_every: 10,
                ..Options::new(0.01, steps)
            };
            counted(&model, method, &q0, &p0, &options)
        };
        run(10);
        let (short, long) = (run(100), run(5_000));
        assert_eq!(
            short, long,
            "{method:?}: {short} allocations for 100 steps, {long} for 5000"
        );
    }
}

/// Allocations made by 1 000 evaluations of `method`'s discrete energy on `sys`, after a first
/// one (which may grow a thread's scratch, as the inverse Legendre transform's).
fn discrete_energy_allocations<S: Dynamics>(sys: &S, method: Method, start: (&[f64], &[f64])) -> usize {
    let mut energy = DiscreteEnergy::new(method, start.0.len()).unwrap();
    let end: (Vec<f64>, Vec<f64>) = (start.0.iter().map(|x| x + 0.01).collect(), start.1.to_vec());
    let mut evaluate = || energy.energy(sys, 0.0, 0.01, start, (&end.0, &end.1)).unwrap();
    evaluate();
    let before = allocated();
    for _ in 0..1000 {
        std::hint::black_box(evaluate());
    }
    allocated() - before
}

#[test]
fn the_discrete_energy_allocates_nothing() {
    let kepler = scenes::Kepler::problem(0.6).unwrap();
    let start = (&kepler.initial.q[..], &kepler.initial.p[..]);
    let double = scenes::DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let pendulum = tapes::pendulum_lagrangian();
    for method in Method::ALL.into_iter().filter(|m| DiscreteEnergy::new(*m, 2).is_some()) {
        assert_eq!(
            discrete_energy_allocations(&kepler.system, method, start),
            0,
            "{method:?}"
        );
    }
    for method in [Method::Midpoint, Method::Trapezoid] {
        let natural = discrete_energy_allocations(&General(&double), method, (&[0.7, -0.4], &[1.3, 0.8]));
        let compiled = discrete_energy_allocations(&General(&pendulum), method, (&[0.3], &[0.7]));
        assert_eq!((natural, compiled), (0, 0), "{method:?}: natural, compiled");
    }
}

/// Allocations of a run of `steps` steps of 0.01 of the free particle from (q0, p0) in the
/// table |q| ≤ `radius` (reflect law), and its impacts.
fn billiard(steps: usize, radius: f64) -> (usize, usize) {
    let free = scenes::EllipticBilliard::new(1.0, 1.0).unwrap();
    let contacts = contacts::table(radius, Law::Reflect);
    let options = Options {
        save_every: 100,
        ..Options::new(0.01, steps)
    };
    let watch = Watch {
        events: None,
        contacts: Some(&contacts),
        ..Watch::default()
    };
    let before = allocated();
    let traj = integrate_watching(
        &free,
        Method::Verlet,
        &[0.3, -0.2],
        &[0.6, 0.8],
        &options,
        || Ok(()),
        watch,
    )
    .unwrap();
    (allocated() - before, traj.impacts.len())
}

#[test]
fn contacts_allocate_nothing_in_the_step_loop() {
    // A table never reached: a long run allocates as much as a short one.
    let (short, none) = billiard(100, 1e6);
    let (long, _) = billiard(100_000, 1e6);
    assert_eq!(none, 0);
    assert_eq!(long, short, "{long} allocations in 100 000 steps, {short} in 100");
    // Thousands of impacts: only the output grows, each of its 9 columns (the impacts' 6, the
    // saved states' 3) doubling its storage now and then.
    let (short, few) = billiard(1000, 1.0);
    let (long, many) = billiard(100_000, 1.0);
    assert!(few >= 5 && many >= 500, "{few}, {many} impacts");
    let doublings = 9 * ((many as f64).log2().ceil() as usize + 1);
    assert!(
        long - short <= doublings,
        "{} allocations for {many} impacts",
        long - short
    );
}

/// Allocations of a run of `model` from (q0, p0) of `steps` steps of h watching `contact`, held
/// closed from the start and never released, saving its first and last states: that run.
fn held_run<S: Dynamics>(
    model: &S,
    contact: Contact<'static>,
    (q0, p0): (&[f64], &[f64]),
    (h, steps): (f64, usize),
) -> (usize, Trajectory) {
    let contacts = Contacts::new(vec![contact]).unwrap();
    let options = Options {
        save_every: steps,
        ..Options::new(h, steps)
    };
    let watch = Watch {
        contacts: Some(&contacts),
        ..Watch::default()
    };
    let before = allocated();
    let traj = integrate_watching(model, Method::Verlet, q0, p0, &options, || Ok(()), watch).unwrap();
    let count = allocated() - before;
    assert!(traj.impacts.is_empty() && traj.impacts.switches.is_empty());
    (count, traj)
}

/// Allocations of a run of `steps` steps of 0.01 of the ball resting on its floor (e = 0.5).
fn resting(steps: usize) -> usize {
    let ball = scenes::BouncingBall::new(9.81).unwrap();
    let (count, traj) = held_run(
        &ball,
        contacts::wall(0, 0.0, 0.5, Law::Reflect, "floor"),
        (&[0.0], &[0.0]),
        (0.01, steps),
    );
    assert_eq!((traj.q_at(1)[0], traj.p_at(1)[0]), (0.0, 0.0));
    count
}

#[test]
fn a_held_contact_allocates_nothing_in_the_step_loop() {
    // The held steps (RATTLE on the floor) and the multiplier checked after each: a long run
    // allocates as much as a short one.
    assert_eq!(resting(100_000), resting(100));
}

/// The unit circle's tangent (−y, x)/|q|, a slip row that turns with q.
struct Turning;

impl SlipRows for Turning {
    fn count(&self) -> usize {
        1
    }

    fn jacobian(&self, q: &[f64], out: &mut [f64]) -> Result<(), varmech::ModelError> {
        let size = q[0].hypot(q[1]);
        out.copy_from_slice(&[-q[1] / size, q[0] / size]);
        Ok(())
    }
}

/// Allocations of a run of `steps` steps of 0.001 of a particle sliding inside a rough circle
/// (μ = 0.5, no other force: N = mv²/r changes with the speed), along `slip`.
fn sliding(slip: Slip, steps: usize) -> usize {
    let free = scenes::FreeBody::new(vec![1.0, 1.0]).unwrap();
    let rim = Contact {
        friction: Some(Friction {
            static_coefficient: 0.5,
            kinetic: 0.5,
            slip,
        }),
        ..contacts::ellipsoid(1.0, true, 0.0, Law::Reflect, "rim")
    };
    let (count, traj) = held_run(&free, rim, (&[1.0, 0.0], &[0.0, 1.0]), (0.001, steps));
    assert!(traj.work[1] < 0.0);
    count
}

#[test]
fn a_sliding_contact_with_friction_allocates_nothing_in_the_step_loop() {
    // The held steps with the friction's fixed point and the multipliers of each: a long run
    // allocates as much as a short one.
    assert_eq!(sliding(Slip::Tangent, 20_000), sliding(Slip::Tangent, 100));
    // Slip rows that turn with q: called through their Arc, into the held step's buffers.
    let turning = || Slip::Field(std::sync::Arc::new(Turning));
    assert_eq!(sliding(turning(), 20_000), sliding(turning(), 100));
}

/// Allocations of `steps` steps of `stepper` through a watcher of a wall q_k ≥ −10⁹ that it
/// never reaches, after a first call (which sizes the watcher's buffers).
fn watched_allocations<M>(model: M, mut stepper: Stepper<M>, coordinate: usize, steps: usize) -> usize
where
    M: Deref<Target: Dynamics> + Copy,
{
    let far = contacts::wall(coordinate, -1e9, 1.0, Law::Reflect, "far");
    let contacts = Contacts::new(vec![far]).unwrap();
    let watch = Watch {
        contacts: Some(&contacts),
        ..Watch::default()
    };
    let mut watcher = Watcher::begin(model, &mut stepper, watch, "q0").unwrap();
    let mut record = Trajectory::default();
    let mut poll = || Ok(());
    watcher.advance(&mut stepper, 1, &mut record, &mut poll).unwrap();
    let before = allocated();
    watcher.advance(&mut stepper, steps, &mut record, &mut poll).unwrap();
    let count = allocated() - before;
    assert_eq!((stepper.steps(), record.impacts.len()), (steps + 1, 0));
    count
}

#[test]
fn a_stepper_watching_a_contact_never_hit_allocates_nothing() {
    // Each loop the steps may take: fixed-size kick–drift (the billiard), step by step (18
    // coordinates), the method's own variables (Wisdom–Holman), the fixed-size DEL loop (the
    // double pendulum) and a constrained model's (RATTLE on the chain).
    let free = scenes::EllipticBilliard::new(1.0, 1.0).unwrap();
    let stepper = Stepper::new(&free, Method::Verlet, &[0.3, -0.2], &[0.6, 0.8], &Options::new(0.01, 0)).unwrap();
    assert_eq!(watched_allocations(&free, stepper, 0, 10_000), 0);
    let problem = NBody::outer_solar_system();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    for method in [Method::Verlet, Method::WisdomHolmanCorrected] {
        let stepper = Stepper::new(&problem.system, method, q0, p0, &Options::new(10.0, 0)).unwrap();
        let count = watched_allocations(&problem.system, stepper, 4, 2000);
        assert_eq!(count, 0, "{method:?}: {count} allocations");
    }
    let double = scenes::DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let general = General(&double);
    let stepper = Stepper::new(
        &general,
        Method::Midpoint,
        &[0.7, -0.4],
        &[1.3, 0.8],
        &Options::new(0.01, 0),
    )
    .unwrap();
    assert_eq!(watched_allocations(&general, stepper, 0, 2000), 0);
    let chain = scenes::planar_chain(8).unwrap();
    let stepper = Stepper::new(
        &chain.system,
        Method::Rattle,
        &chain.initial.q,
        &chain.initial.p,
        &Options::new(0.01, 0),
    )
    .unwrap();
    assert_eq!(watched_allocations(&chain.system, stepper, 1, 2000), 0);
}

#[test]
fn steps_with_tangent_vectors_allocate_nothing_after_the_first() {
    let hh = scenes::HenonHeiles::new();
    let double = scenes::DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let general = General(&double);
    let cases: [(&dyn Dynamics, Method); 4] = [
        (&hh, Method::Verlet),
        (&hh, Method::Yoshida4),
        (&general, Method::Midpoint),
        (&general, Method::Galerkin4),
    ];
    let chain = scenes::planar_chain(2).unwrap();
    let start = |sys: &dyn Dynamics| match sys.dim() {
        2 => (vec![0.1, -0.2], vec![0.3, 0.25]),
        _ => (chain.initial.q.clone(), chain.initial.p.clone()),
    };
    for (sys, method) in cases
        .into_iter()
        .chain([(&chain.system as &dyn Dynamics, Method::Rattle)])
    {
        let mut tangent = Tangent::new(method, sys).unwrap();
        let (q0, p0) = start(sys);
        let mut stepper = Stepper::new(sys, method, &q0, &p0, &Options::new(0.01, 0)).unwrap();
        let mut x = vec![0.5; 16];
        stepper.step_with_tangent(&mut tangent, &mut x).unwrap();
        let before = allocated();
        for _ in 0..1000 {
            stepper.step_with_tangent(&mut tangent, &mut x).unwrap();
            x.iter_mut().for_each(|v| *v *= 1e-3);
        }
        assert_eq!(allocated() - before, 0, "{method:?}");
        // Carried in the method's own loop (a kick–drift step's shears), likewise.
        let before = allocated();
        stepper
            .advance_with_tangent_below(1000, (&mut tangent, &mut x), 1e100, || Ok(()))
            .unwrap();
        assert_eq!(allocated() - before, 0, "{method:?} in the method's loop");
    }
}
