//! Ensembles: every member bit for bit its single run, whatever the threads and chunks; failures
//! and interrupts per member; bad input refused before any member starts.

use varmech::integrators::{
    integrate, integrate_ensemble, integrate_watching, Detector, Ensemble, EventSpec, Failure, General, MemberEvents,
    MemberWatch, Members, Method, NativeEvent, Options, Outcome, Parallel, Poll, Shared, Trajectory, Watch,
};
use varmech::scenes::{DampedDrivenPendulum, DoublePendulum, HarmonicOscillator};
use varmech::{Error, ModelError};

fn never() -> Result<(), ModelError> {
    Ok(())
}

/// The ensemble of the members, rows of (q0, p0), with `models` by `method`, without events.
fn run_ensemble<M: Members + ?Sized>(
    models: &M,
    method: Method,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    parallel: Parallel,
    poll: impl Poll,
) -> Result<Ensemble, Error> {
    integrate_ensemble(models, method, q0, p0, options, parallel, &MemberWatch::default(), poll)
}

/// `members` initial states of the double pendulum about its scene's, row by row.
fn rows(members: usize) -> (Vec<f64>, Vec<f64>) {
    let p = DoublePendulum::problem();
    let (mut q0, mut p0) = (Vec::new(), Vec::new());
    for i in 0..members {
        let d = 1e-3 * i as f64;
        q0.extend(p.initial.q.iter().map(|x| x + d));
        p0.extend(p.initial.p.iter().map(|x| x - 0.5 * d));
    }
    (q0, p0)
}

/// The same saved states, bit for bit.
fn same_states(a: &Trajectory, b: &Trajectory) -> bool {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    bits(&a.t) == bits(&b.t) && bits(&a.q) == bits(&b.q) && bits(&a.p) == bits(&b.p)
}

/// The same run: its states, steps, Newton counts and final checkpoint.
fn same(a: &Trajectory, b: &Trajectory) -> bool {
    same_states(a, b) && a.steps == b.steps && a.newton == b.newton && a.checkpoint == b.checkpoint
}

fn failure(outcome: &Outcome) -> &Failure {
    outcome.as_ref().expect_err("a failed member")
}

#[test]
fn every_member_is_bit_for_bit_its_single_run_whatever_the_threads_and_chunks() {
    let p = DoublePendulum::problem();
    let sys = General(&p.system);
    let options = Options {
        save_every: 7,
        ..Options::new(0.01, 300)
    };
    let members = 20;
    let (q0, p0) = rows(members);
    let singles: Vec<Trajectory> = (0..members)
        .map(|i| {
            let rows = 2 * i..2 * i + 2;
            integrate(&sys, Method::Midpoint, &q0[rows.clone()], &p0[rows], &options, never).unwrap()
        })
        .collect();
    for workers in [1, 2] {
        for chunk_size in [1, 7, 64] {
            let parallel = Parallel {
                workers: Some(workers),
                chunk_size: Some(chunk_size),
            };
            let ensemble =
                run_ensemble(&Shared(&sys), Method::Midpoint, (&q0, &p0), &options, parallel, never).unwrap();
            assert!(ensemble.interrupted.is_none());
            assert_eq!(ensemble.members.len(), members);
            for (i, (member, single)) in ensemble.members.iter().zip(&singles).enumerate() {
                let member = member.as_ref().unwrap();
                assert!(
                    same(member, single),
                    "member {i}, workers {workers}, chunk {chunk_size}"
                );
            }
        }
    }
}

#[test]
fn a_member_past_its_stability_limit_fails_alone_with_its_step_and_partial_trajectory() {
    // Verlet is stable on q'' = −ω²q for hω < 2: at h = 0.1, ω = 30 (hω = 3) grows by
    // |λ| = (hω)²/2 − 1 + √(((hω)²/2 − 1)² − 1) ≈ 6.85 a step and trips the energy check.
    let omegas = [1.0, 2.0, 30.0, 0.5];
    let models: Vec<HarmonicOscillator> = omegas.iter().map(|&w| HarmonicOscillator::new(w).unwrap()).collect();
    let options = Options::new(0.1, 200);
    let (q0, p0) = (vec![0.0; 4], vec![1.0; 4]);
    let ensemble = run_ensemble(
        models.as_slice(),
        Method::Verlet,
        (&q0, &p0),
        &options,
        Parallel::default(),
        never,
    )
    .unwrap();
    for (i, member) in ensemble.members.iter().enumerate() {
        let single = integrate(&models[i], Method::Verlet, &[0.0], &[1.0], &options, never);
        match (member, single) {
            (Ok(member), Ok(single)) => {
                assert_ne!(i, 2);
                assert_eq!(member.steps, 200);
                assert!(same(member, &single));
            }
            (Err(member), Err(single)) => {
                assert_eq!(i, 2);
                let Error::Divergence { step, .. } = member.error else {
                    panic!("member 2 diverges: {}", member.error)
                };
                assert!((1..20).contains(&step), "step {step}");
                assert_eq!(member.partial.len(), step + 1);
                assert!(same(&member.partial, &single.partial));
            }
            (member, single) => panic!("member {i}: {member:?} against {single:?}"),
        }
    }
}

#[test]
fn a_drive_amplitude_sweep_equals_its_separate_runs() {
    let amplitudes = [0.9, 1.07, 1.15, 1.35, 1.45, 1.5];
    let pendulums: Vec<DampedDrivenPendulum> = amplitudes
        .iter()
        .map(|&a| DampedDrivenPendulum::problem(0.5, a, 2.0 / 3.0).unwrap().system)
        .collect();
    let models: Vec<General<'_, DampedDrivenPendulum>> = pendulums.iter().map(General).collect();
    let options = Options {
        save_every: 10,
        ..Options::new(0.05, 2000)
    };
    let initial = DampedDrivenPendulum::problem(0.5, 1.5, 2.0 / 3.0).unwrap().initial;
    let q0 = initial.q.repeat(amplitudes.len());
    let p0 = initial.p.repeat(amplitudes.len());
    let parallel = Parallel {
        workers: Some(2),
        chunk_size: Some(4),
    };
    let ensemble = run_ensemble(
        models.as_slice(),
        Method::Midpoint,
        (&q0, &p0),
        &options,
        parallel,
        never,
    )
    .unwrap();
    let finals: Vec<f64> = ensemble
        .members
        .iter()
        .zip(&models)
        .map(|(member, sys)| {
            let member = member.as_ref().unwrap();
            let single = integrate(sys, Method::Midpoint, &initial.q, &initial.p, &options, never).unwrap();
            assert!(same(member, &single));
            member.q[member.q.len() - 1]
        })
        .collect();
    // The drive matters: no two amplitudes end at the same angle.
    for (i, a) in finals.iter().enumerate() {
        assert!(finals[i + 1..].iter().all(|b| (a - b).abs() > 1e-3), "{finals:?}");
    }
}

#[test]
fn an_interrupt_stops_every_member_keeping_a_prefix_of_its_run() {
    let p = DoublePendulum::problem();
    let sys = General(&p.system);
    // Long enough that no member ends before the first poll, 10 ms in.
    let options = Options {
        save_every: 100,
        ..Options::new(1e-4, 50_000_000)
    };
    let members = 3;
    let (q0, p0) = rows(members);
    let parallel = Parallel {
        workers: Some(2),
        chunk_size: None,
    };
    let stop = || Err::<(), ModelError>("stop".into());
    let ensemble = run_ensemble(&Shared(&sys), Method::Midpoint, (&q0, &p0), &options, parallel, stop).unwrap();
    assert_eq!(ensemble.interrupted.unwrap().to_string(), "stop");
    for (i, member) in ensemble.members.iter().enumerate() {
        let Failure { error, partial } = failure(member);
        let Error::Interrupted { step, .. } = *error else {
            panic!("member {i} is interrupted: {error}")
        };
        assert!(step < options.steps);
        // What was computed is kept: the states of a run to the step where it stopped, bit for bit.
        if partial.len() > 1 {
            let rows = 2 * i..2 * i + 2;
            let to_stop = Options {
                steps: partial.steps,
                ..options.clone()
            };
            let single = integrate(&sys, Method::Midpoint, &q0[rows.clone()], &p0[rows], &to_stop, never).unwrap();
            assert!(same_states(partial, &single), "member {i}");
        }
    }
    assert!(
        ensemble.members.iter().any(|m| failure(m).partial.len() > 1),
        "the running members kept their states"
    );
}

#[test]
fn bad_input_is_refused_naming_the_argument() {
    let p = DoublePendulum::problem();
    let sys = General(&p.system);
    let options = Options::new(0.01, 10);
    let (q0, p0) = rows(3);
    let named = |result: Result<_, Error>| match result {
        Err(Error::InvalidArgument { argument, .. }) => argument,
        other => panic!("expected an invalid argument, got {other:?}"),
    };
    let shared = Shared(&sys);
    let run = |q0: &[f64], p0: &[f64], options: &Options, parallel| {
        run_ensemble(&shared, Method::Midpoint, (q0, p0), options, parallel, never).map(|_| ())
    };
    let default = Parallel::default();
    assert_eq!(named(run(&q0[..5], &p0[..5], &options, default)), "q0");
    assert_eq!(named(run(&q0, &p0[..4], &options, default)), "p0");
    for workers in [Some(0), None] {
        let chunk_size = workers.map_or(Some(0), |_| None);
        let parallel = Parallel { workers, chunk_size };
        let expected = if workers.is_some() { "workers" } else { "chunk_size" };
        assert_eq!(named(run(&q0, &p0, &options, parallel)), expected);
    }
    let models = [HarmonicOscillator::new(1.0).unwrap()];
    let two = run_ensemble(
        &models[..],
        Method::Verlet,
        (&[0.0, 1.0], &[1.0, 0.0]),
        &options,
        default,
        never,
    );
    assert_eq!(named(two.map(|_| ())), "models");
    // 10⁶ members × 10⁹ saved states cannot fit: refused before anything runs.
    let huge = Options::new(1e-9, 1_000_000_000);
    let (q0, p0) = (vec![0.0; 2_000_000], vec![0.0; 2_000_000]);
    let err = run(&q0, &p0, &huge, default).unwrap_err().to_string();
    assert!(
        err.starts_with("save_every:") && err.contains("raise save_every"),
        "{err}"
    );
}

#[test]
fn members_watching_native_events_are_bit_for_bit_their_single_runs_with_events() {
    // The double pendulum's upper arm through the vertical, upward (an orbit's section), and a
    // terminal count of 3 on the lower arm's crossings: each member's crossings and its stop
    // are those of its single run, on 1 and 2 threads.
    let p = DoublePendulum::problem();
    let sys = General(&p.system);
    let members = 6;
    let q0: Vec<f64> = (0..members).flat_map(|i| [0.4 + 0.1 * i as f64, -0.3]).collect();
    let p0 = vec![0.0; 2 * members];
    let options = Options::new(0.01, 3000);
    let events = MemberEvents {
        functions: vec![
            NativeEvent::Crossing {
                coordinate: 0,
                value: 0.0,
            },
            NativeEvent::Crossing {
                coordinate: 1,
                value: 0.0,
            },
        ],
        specs: vec![
            EventSpec {
                name: "upper".into(),
                direction: 1,
                terminal: 0,
            },
            EventSpec {
                name: "lower".into(),
                direction: 0,
                terminal: 3,
            },
        ],
    };
    let watched = MemberWatch {
        events: events.clone(),
        ..MemberWatch::default()
    };
    for workers in [1, 2] {
        let parallel = Parallel {
            workers: Some(workers),
            chunk_size: None,
        };
        let ensemble = integrate_ensemble(
            &Shared(&sys),
            Method::Midpoint,
            &q0,
            &p0,
            &options,
            parallel,
            &watched,
            never,
        )
        .unwrap();
        for (i, member) in ensemble.members.iter().enumerate() {
            let mut detector = Detector::new(Box::new(events.functions.clone()), events.specs.clone()).unwrap();
            let rows = 2 * i..2 * i + 2;
            let single = integrate_watching(
                &sys,
                Method::Midpoint,
                &q0[rows.clone()],
                &p0[rows],
                &options,
                never,
                Watch::events(&mut detector),
            )
            .unwrap();
            let member = member.as_ref().unwrap();
            assert_eq!(member.events, single.events, "member {i}");
            assert_eq!(
                (&member.q, &member.p, member.steps),
                (&single.q, &single.p, single.steps),
                "member {i}"
            );
            assert!(
                single.terminated_by.is_some() && single.steps < 3000,
                "member {i} stops at its third crossing"
            );
            assert!(
                member.events.iter().any(|o| o.event == 0) || i < 2,
                "member {i} crossed the vertical upward"
            );
        }
    }
    // An event on a coordinate the model does not have is refused before anything runs.
    let bad = MemberEvents {
        functions: vec![NativeEvent::Crossing {
            coordinate: 2,
            value: 0.0,
        }],
        specs: vec![EventSpec {
            name: "third".into(),
            direction: 0,
            terminal: 0,
        }],
    };
    let err = integrate_ensemble(
        &Shared(&sys),
        Method::Midpoint,
        &q0,
        &p0,
        &options,
        Parallel::default(),
        &MemberWatch {
            events: bad,
            ..MemberWatch::default()
        },
        never,
    );
    assert!(
        matches!(err, Err(Error::InvalidArgument { argument: "events", .. })),
        "{err:?}"
    );
}
