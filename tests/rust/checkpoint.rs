//! Checkpoints: a run of N steps resumed from its checkpoint for M more is the run of N + M
//! steps, bit for bit (states, Newton iterations, evaluations, work), for every method family
//! and model kind; damaged checkpoints are refused.

use varmech::integrators::{integrate, resume, Checkpoint, Dynamics, General, Method, Options, Trajectory};
use varmech::model::Routhian;
use varmech::scenes::{planar_chain, DampedDrivenPendulum, DoublePendulum, Kepler, NBody, SphericalPendulum};
use varmech::Error;

/// Runs N + M steps at once, and N steps then M more from the checkpoint (through its bytes);
/// the two must agree to the bit on every state the whole run saves and on every count.
///
/// N = 100 is off the saving cadence (17), N = 102 on it. Off it, the first run saves a state the
/// whole run does not, and the corrected Wisdom–Holman methods pay their corrector's kicks once
/// more to show it: their evaluation counts are then compared only on the cadence.
fn resumes_bit_for_bit<S: Dynamics + ?Sized>(case: &str, sys: &S, method: Method, q0: &[f64], p0: &[f64], dt: f64) {
    for n in [100, 102] {
        resumes_from(&format!("{case}, N = {n}"), sys, method, q0, p0, dt, n);
    }
}

fn resumes_from<S: Dynamics + ?Sized>(case: &str, sys: &S, method: Method, q0: &[f64], p0: &[f64], dt: f64, n: usize) {
    let (m, every) = (150, 17);
    let options = |steps| Options {
        save_every: every,
        ..Options::new(dt, steps)
    };
    let run = |steps| {
        integrate(sys, method, q0, p0, &options(steps), || Ok(())).unwrap_or_else(|f| panic!("{case}: {}", f.error))
    };
    let whole = run(n + m);
    let first = run(n);
    let checkpoint = Checkpoint::from_bytes(&first.checkpoint).unwrap();
    let second = resume(sys, checkpoint, m, every, || Ok(())).unwrap_or_else(|f| panic!("{case}: {}", f.error));

    // The first run's last state (step N) is saved by the whole run only on its cadence; the
    // second run starts with it.
    let keep = first.len() - usize::from(!n.is_multiple_of(every));
    let joined = |column: &dyn Fn(&Trajectory) -> Vec<u64>, width: usize| -> Vec<u64> {
        let (a, b) = (column(&first), column(&second));
        a[..keep * width].iter().chain(&b[width..]).copied().collect()
    };
    let d = sys.dim();
    assert_eq!(joined(&|t| bits(&t.t), 1), bits(&whole.t), "{case}: t");
    assert_eq!(joined(&|t| bits(&t.q), d), bits(&whole.q), "{case}: q");
    assert_eq!(joined(&|t| bits(&t.p), d), bits(&whole.p), "{case}: p");
    assert_eq!(
        joined(&|t| t.newton_at_saves().to_vec(), 1),
        whole.newton_at_saves().to_vec(),
        "{case}: Newton"
    );
    assert_eq!(
        joined(&|t| bits(&t.work_at_saves()), 1),
        bits(&whole.work_at_saves()),
        "{case}: work"
    );
    assert_eq!(
        (second.steps, second.newton_iterations),
        (whole.steps, whole.newton_iterations),
        "{case}: counts"
    );
    let synchronising = matches!(method, Method::WisdomHolmanCorrected | Method::WisdomHolmanLazyKernel);
    if !n.is_multiple_of(every) && synchronising {
        return;
    }
    assert_eq!(second.force_evaluations, whole.force_evaluations, "{case}: evaluations");
    // The stepper's whole state; the energy check's running scale saw one state more.
    let state = |t: &Trajectory| Checkpoint::of(sys, Checkpoint::from_bytes(&t.checkpoint).unwrap().state()).to_bytes();
    assert!(
        state(&second) == state(&whole),
        "{case}: the final stepper states differ"
    );
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn every_method_family_resumes_bit_for_bit() {
    let kepler = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&kepler.initial.q, &kepler.initial.p);
    let dt = 2.0 * std::f64::consts::PI / 100.0;
    for method in crate::common::FAMILIES {
        resumes_bit_for_bit(&format!("kepler {method:?}"), &kepler.system, method, q0, p0, dt);
    }

    let dp = DoublePendulum::problem();
    for method in [Method::Midpoint, Method::Trapezoid, Method::Galerkin6] {
        let case = format!("double pendulum {method:?}");
        resumes_bit_for_bit(&case, &General(&dp.system), method, &dp.initial.q, &dp.initial.p, 0.01);
    }
    let forced = DampedDrivenPendulum::problem(0.5, 1.5, 2.0 / 3.0).unwrap();
    let (q0, p0) = (&forced.initial.q, &forced.initial.p);
    resumes_bit_for_bit(
        "forced pendulum",
        &General(&forced.system),
        Method::Midpoint,
        q0,
        p0,
        0.05,
    );

    let chain = planar_chain(2).unwrap();
    for method in Method::CONSTRAINED {
        let case = format!("planar chain {method:?}");
        resumes_bit_for_bit(&case, &chain.system, method, &chain.initial.q, &chain.initial.p, 0.01);
    }
    crate::common::with_rigid_body(|sys, s| resumes_bit_for_bit("rigid body", sys, Method::Midpoint, &s.q, &s.p, 0.01));

    // Routh-reduced: the spherical pendulum's θ alone, at p_φ = μ.
    let sp = SphericalPendulum::problem();
    let r = Routhian::new(&sp.system, &[1], &[sp.initial.p[1]], &[0.0]).unwrap();
    let (q0, p0) = ([sp.initial.q[0]], [sp.initial.p[0]]);
    resumes_bit_for_bit("Routhian", &General(&r), Method::Midpoint, &q0, &p0, 0.01);

    // The Wisdom–Holman methods keep their own variables between saves.
    let solar = NBody::outer_solar_system();
    for method in Method::WISDOM_HOLMAN {
        let case = format!("outer solar system {method:?}");
        resumes_bit_for_bit(&case, &solar.system, method, &solar.initial.q, &solar.initial.p, 100.0);
    }
}

/// The checkpoint of 10 steps (h = 0.01) of `method` on Kepler's problem (e = 0.6).
fn kepler_checkpoint(method: Method) -> Vec<u8> {
    let kepler = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&kepler.initial.q, &kepler.initial.p);
    integrate(&kepler.system, method, q0, p0, &Options::new(0.01, 10), || Ok(()))
        .unwrap()
        .checkpoint
}

#[test]
fn damaged_checkpoints_are_refused_naming_the_checkpoint() {
    let bytes = kepler_checkpoint(Method::Midpoint);
    assert!(Checkpoint::from_bytes(&bytes).is_ok());
    let mut flipped = bytes.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 0x10;
    let mut other_format = bytes.clone();
    other_format[8] = other_format[8].wrapping_add(1);
    let cases = [
        ("empty", Vec::new()),
        ("truncated", bytes[..bytes.len() - 3].to_vec()),
        ("a flipped bit", flipped),
        ("another format", other_format),
        ("not a checkpoint", b"HDF5 and other things".to_vec()),
    ];
    for (case, damaged) in cases {
        match Checkpoint::from_bytes(&damaged) {
            Err(Error::InvalidArgument { argument, reason }) => {
                assert_eq!(argument, "checkpoint", "{case}");
                println!("{case}: {reason}");
            }
            other => panic!("{case}: {other:?}"),
        }
    }
}

#[test]
fn a_checkpoint_resumes_only_on_a_model_its_method_integrates() {
    let bytes = kepler_checkpoint(Method::Verlet);
    let dp = DoublePendulum::problem();
    // A general Lagrangian with as many coordinates, which Verlet does not integrate.
    let checkpoint = Checkpoint::from_bytes(&bytes).unwrap();
    let refused = resume(&General(&dp.system), checkpoint, 10, 1, || Ok(())).unwrap_err();
    assert!(
        matches!(refused.error, Error::InvalidArgument { argument: "method", .. }),
        "{}",
        refused.error
    );
    let solar = NBody::outer_solar_system();
    let checkpoint = Checkpoint::from_bytes(&bytes).unwrap();
    let refused = resume(&solar.system, checkpoint, 10, 1, || Ok(())).unwrap_err();
    assert!(
        matches!(refused.error, Error::InvalidArgument { argument: "model", .. }),
        "{}",
        refused.error
    );
}

/// A checkpoint's energy check goes on as the run's unless set: lifted, the continuation runs to
/// its end on the unbroken run's states; tightened, it stops sooner; given to a run that had
/// none, it is measured from the checkpoint. Explicit Euler on the oscillator multiplies the
/// energy by 1 + h² a step, so its check stops the unbroken run at step 49.
#[test]
fn a_checkpoints_energy_check_is_the_runs_unless_set() {
    use varmech::scenes::HarmonicOscillator;
    let sys = HarmonicOscillator::new(1.0).unwrap();
    let (q0, p0, dt) = ([0.0], [1.0], 0.1);
    let run = |steps, check: Option<f64>| {
        let options = Options {
            max_energy_error: check,
            ..Options::new(dt, steps)
        };
        integrate(&sys, Method::ExplicitEuler, &q0, &p0, &options, || Ok(()))
    };
    let stop = |result: Result<Trajectory, Box<varmech::integrators::Failure>>| match result {
        Err(failure) => match failure.error {
            Error::Divergence { step, .. } => step,
            other => panic!("not a divergence: {other}"),
        },
        Ok(_) => usize::MAX,
    };
    let unbroken = stop(run(2030, Some(1.0)));
    assert_eq!(unbroken, 49);
    let from = |check: Option<f64>| Checkpoint::from_bytes(&run(30, check).unwrap().checkpoint).unwrap();
    let go_on = |mut checkpoint: Checkpoint, set: Option<Option<f64>>| {
        if let Some(tolerance) = set {
            checkpoint.check_energy(tolerance);
        }
        resume(&sys, checkpoint, 2000, 1, || Ok(()))
    };
    assert_eq!(stop(go_on(from(Some(1.0)), None)), unbroken);
    let lifted = go_on(from(Some(1.0)), Some(None)).unwrap();
    let free = run(2030, None).unwrap();
    assert_eq!(bits(&lifted.q), bits(&free.q[30..]));
    let tighter = stop(go_on(from(Some(1.0)), Some(Some(0.5))));
    assert!(30 < tighter && tighter < unbroken, "{tighter}");
    // From step 30 the energy is 1.01³⁰ of the first; measured from there it takes as long again.
    let fresh = stop(go_on(from(None), Some(Some(1.0))));
    assert!(fresh > unbroken && fresh < 2030, "{fresh}");
}
