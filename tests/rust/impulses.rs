//! The schedule of a run ([`Schedule`]): impulses at given times, each splitting the step that
//! holds it (the method's order kept across the blow), and samples (`t_eval`), the method's
//! partial steps to the requested times, taken through impacts; both composed with contacts and
//! carried by a resumed run bit for bit.

use nalgebra::DMatrix;
use varmech::integrators::{
    impulsive, integrate, integrate_watching, resume_watching, Blow, Checkpoint, Contacts, Failure, Generalized,
    Impulse, Law, MemberWatch, Method, NativeContact, NativeSurface, Options, Schedule, Struck, Trajectory, Watch,
};
use varmech::model::Lagrangian;
use varmech::scenes::{BouncingBall, DoublePendulum, HarmonicOscillator};
use varmech::Error;

use crate::common::contacts::floor;
use crate::common::verlet_ensemble;
use crate::impacts::{drop_ball, with_contacts};

fn blow(t: f64, p: &[f64]) -> Impulse<'static> {
    Impulse {
        t,
        blow: Box::new(Generalized(p.to_vec())),
    }
}

fn scheduled<'w>(schedule: &'w Schedule<'static>) -> Watch<'w, 'static, 'static> {
    Watch {
        schedule: Some(schedule),
        ..Watch::default()
    }
}

/// The watch of `contacts` and `schedule`.
fn both<'w>(contacts: &'w Contacts<'static>, schedule: &'w Schedule<'static>) -> Watch<'w, 'static, 'static> {
    Watch {
        contacts: Some(contacts),
        ..scheduled(schedule)
    }
}

/// The run of the oscillator q̈ = −q from (0, 1) with `schedule`.
fn run_oscillator(method: Method, options: &Options, schedule: &Schedule<'static>) -> Result<Trajectory, Box<Failure>> {
    let oscillator = HarmonicOscillator::new(1.0).unwrap();
    integrate_watching(
        &oscillator,
        method,
        &[0.0],
        &[1.0],
        options,
        || Ok(()),
        scheduled(schedule),
    )
}

/// The oscillator q̈ = −q from (0, 1), struck by Δp = `kick` at t*: its state at t.
fn oscillator_after_blow(t: f64, t_star: f64, kick: f64) -> (f64, f64) {
    let (q, p) = (t_star.sin(), t_star.cos() + kick);
    let s = t - t_star;
    (q * s.cos() + p * s.sin(), -q * s.sin() + p * s.cos())
}

#[test]
fn an_impulse_between_grid_points_keeps_the_methods_order() {
    let (t_star, kick, t_end) = (1.2345, 0.7, 6.0);
    let exact = oscillator_after_blow(t_end, t_star, kick);
    for (method, order, h) in [(Method::Verlet, 2.0, 0.02), (Method::KahanLi6, 6.0, 0.2)] {
        let errors: Vec<f64> = [h, h / 2.0, h / 4.0]
            .iter()
            .map(|&dt| {
                let schedule = Schedule::new(vec![blow(t_star, &[kick])], vec![]).unwrap();
                let options = Options::new(dt, (t_end / dt).round() as usize);
                let traj = run_oscillator(method, &options, &schedule).unwrap();
                // The jump is saved: two rows at t*, their momenta differing by the blow.
                let rows: Vec<usize> = (0..traj.len()).filter(|&k| traj.t[k] == t_star).collect();
                assert_eq!(rows.len(), 2);
                assert!((traj.p_at(rows[1])[0] - traj.p_at(rows[0])[0] - kick).abs() <= 1e-14);
                assert_eq!(traj.q_at(rows[0]), traj.q_at(rows[1]));
                let last = traj.len() - 1;
                (traj.q_at(last)[0] - exact.0)
                    .abs()
                    .max((traj.p_at(last)[0] - exact.1).abs())
            })
            .collect();
        for w in errors.windows(2) {
            let measured = (w[0] / w[1]).log2();
            assert!((measured - order).abs() < 0.3, "{method:?}: {errors:?}");
        }
    }
}

#[test]
fn an_impulse_on_the_grid_and_at_t0_jumps_there_and_the_run_goes_on_as_a_new_one() {
    let oscillator = HarmonicOscillator::new(1.0).unwrap();
    let dt = 0.05;
    let schedule = Schedule::new(vec![blow(40.0 * dt, &[0.4]), blow(0.0, &[0.5])], vec![]).unwrap();
    let options = Options::new(dt, 200);
    let traj = run_oscillator(Method::Verlet, &options, &schedule).unwrap();
    // Rows: t0 before and after the first blow, 39 steps, t₄₀ before and after, 160 steps.
    assert_eq!(traj.len(), 2 + 39 + 2 + 160);
    assert_eq!((traj.p_at(0)[0], traj.p_at(1)[0]), (1.0, 1.5));
    let before = integrate(
        &oscillator,
        Method::Verlet,
        &[0.0],
        &[1.5],
        &Options::new(dt, 40),
        || Ok(()),
    )
    .unwrap();
    assert_eq!(&traj.q[1..42], &before.q[..]);
    let end = before.len() - 1;
    let after = Options {
        t0: before.t[end],
        ..Options::new(dt, 160)
    };
    let p = [before.p_at(end)[0] + 0.4];
    let rest = integrate(&oscillator, Method::Verlet, before.q_at(end), &p, &after, || Ok(())).unwrap();
    assert_eq!(traj.p_at(42), &p[..]);
    assert_eq!(traj.q[42..], rest.q[..]);
    assert_eq!(traj.p[42..], rest.p[..]);
}

#[test]
fn a_blow_at_a_point_gives_the_components_of_its_jacobian_or_of_central_differences() {
    // A rod of length 2 on a table, (x, y, θ), struck across an end: P = Jᵀ I = (0, 1, cos θ).
    let point = |q: &[f64], x: &mut [f64]| {
        (x[0], x[1]) = (q[0] + q[2].cos(), q[1] + q[2].sin());
        Ok(())
    };
    let jacobian = |q: &[f64], j: &mut [f64]| {
        j.copy_from_slice(&[1.0, 0.0, -q[2].sin(), 0.0, 1.0, q[2].cos()]);
        Ok(())
    };
    let q = [0.3, -0.2, 0.4];
    let exact = [0.0, 1.0, 0.4f64.cos()];
    let given = Struck {
        point: Box::new(point),
        jacobian: Some(Box::new(jacobian)),
        impulse: vec![0.0, 1.0],
    };
    let differenced = Struck {
        point: Box::new(point),
        jacobian: None,
        impulse: vec![0.0, 1.0],
    };
    let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
    given.components(&q, &mut a).unwrap();
    differenced.components(&q, &mut b).unwrap();
    assert_eq!(a, exact);
    // Central differences: error O(ε^(2/3)) ≈ 4e-11.
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9), "{b:?}");
}

#[test]
fn lagranges_impulsive_equations_give_m_dv_equal_to_p_and_carnots_loss_on_engaging() {
    // The double pendulum's M(q) depends on q: a blow P gives M Δq̇ = P and T⁺ − T⁻ =
    // ½(p⁺·q̇⁺ − p⁻·q̇⁻); the first joint gripped suddenly (A = [1, 0]) stops it, losing
    // Carnot's ½Δq̇ᵀMΔq̇ (Byerly, Arts. 26–31).
    let double = DoublePendulum::new(1.0, 2.0, 2.0, 3.0, 9.80665).unwrap();
    let model: &dyn Lagrangian = &double;
    let (q, p, blow) = ([0.7, -0.4], [0.2, 0.1], [0.5, -0.3]);
    let after = impulsive::respond(model, 0.0, (&q, &p), &Generalized(blow.to_vec())).unwrap();
    let minv = impulsive::inverse_mass(model, &q, 0.0).unwrap();
    let dv = nalgebra::DVector::from_iterator(2, after.v.iter().zip(&after.v_before).map(|(a, b)| a - b));
    let recovered = minv.lu().solve(&dv).unwrap();
    assert!(
        (recovered[0] - blow[0]).abs() < 1e-13 && (recovered[1] - blow[1]).abs() < 1e-13,
        "{recovered}"
    );
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let change = 0.5 * (dot(&after.p, &after.v) - dot(&p, &after.v_before));
    // T = E − V: round-off of |V| ≈ 30 (measured 1.8e-14).
    assert!(
        (after.kinetic_change - change).abs() < 1e-12,
        "{} {change}",
        after.kinetic_change
    );

    let grip = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
    let engaged = impulsive::engage(model, 0.0, (&q, &p), &grip).unwrap().unwrap();
    assert!(engaged.v[0].abs() < 1e-15, "{:?}", engaged.v);
    assert!(engaged.energy_lost > 0.0);
    assert!((engaged.energy_lost - engaged.carnot).abs() < 1e-12, "{engaged:?}");
    // Δp = Aᵀλ: the second momentum does not change.
    assert_eq!(engaged.p[1], p[1]);
    let dependent = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 2.0, 0.0]);
    assert_eq!(impulsive::engage(model, 0.0, (&q, &p), &dependent).unwrap(), None);
}

/// The step count and state of a ball's run's checkpoint (its energy check aside: a run of
/// samples checks it at other steps).
fn end_state(traj: &Trajectory) -> (usize, Vec<f64>, Vec<f64>) {
    let ball = BouncingBall::new(9.81).unwrap();
    let state = Checkpoint::from_bytes(&traj.checkpoint)
        .unwrap()
        .into_state(&ball)
        .unwrap();
    (state.steps(), state.q().to_vec(), state.p().to_vec())
}

/// The ball dropped from h₀ = 1 at rest, bouncing elastically: its exact height and momentum.
fn ball_at(t: f64, g: f64) -> (f64, f64) {
    let fall = (2.0 / g).sqrt();
    let s = ((t + fall) % (2.0 * fall)) - fall;
    (1.0 - 0.5 * g * s * s, -g * s)
}

#[test]
fn samples_are_taken_through_impacts_to_round_off_on_the_bouncing_ball() {
    // Verlet is exact on the parabola and the impacts are located to round-off, so the samples,
    // partial steps from the last impact before them, are the exact motion to round-off.
    let g = 9.81;
    let contacts = floor(1.0, Law::Reflect);
    let times: Vec<f64> = (0..200).map(|k| 0.0137 + 0.0499 * k as f64).collect();
    let schedule = Schedule::new(vec![], times.clone()).unwrap();
    let options = Options::new(0.01, 1000);
    let watch = both(&contacts, &schedule);
    let traj = drop_ball(&options, watch).unwrap();
    assert_eq!(traj.t, times, "the samples alone are saved");
    assert!(traj.impacts.len() >= 4);
    for (k, &t) in times.iter().enumerate() {
        let (q, p) = ball_at(t, g);
        assert!(
            (traj.q_at(k)[0] - q).abs() < 1e-11 && (traj.p_at(k)[0] - p).abs() < 1e-10,
            "t = {t}"
        );
    }
    // The run goes on to its end, whatever it samples.
    let plain = drop_ball(&options, with_contacts(&contacts)).unwrap();
    assert_eq!(end_state(&traj), end_state(&plain));
    assert_eq!(traj.impacts, plain.impacts);
}

#[test]
fn samples_on_the_grid_are_the_runs_own_states_to_the_bit() {
    let oscillator = HarmonicOscillator::new(1.0).unwrap();
    let options = Options::new(0.01, 300);
    let run = integrate(&oscillator, Method::KahanLi8, &[0.0], &[1.0], &options, || Ok(())).unwrap();
    let picked = [0, 7, 8, 150, 300];
    let schedule = Schedule::new(vec![], picked.iter().map(|&k| run.t[k]).collect()).unwrap();
    let at = run_oscillator(Method::KahanLi8, &options, &schedule).unwrap();
    for (row, &k) in picked.iter().enumerate() {
        assert_eq!((at.q_at(row), at.p_at(row)), (run.q_at(k), run.p_at(k)));
    }
}

#[test]
fn a_ball_struck_up_in_flight_bounces_higher_and_the_energy_check_discounts_the_blow() {
    // Struck at t = 0.2 by Δp = 3 (unit mass), the ball's energy rises by ½((p + 3)² − p²);
    // the run's energy check (on by default) judges the smooth motion alone.
    let g = 9.81;
    let contacts = floor(1.0, Law::Reflect);
    let schedule = Schedule::new(vec![blow(0.2, &[3.0])], vec![]).unwrap();
    let watch = both(&contacts, &schedule);
    let traj = drop_ball(&Options::new(0.01, 500), watch).unwrap();
    let p = -g * 0.2 + 3.0;
    let energy = g * (1.0 - 0.5 * g * 0.04) + 0.5 * p * p;
    let last = traj.len() - 1;
    let e = 0.5 * traj.p_at(last)[0].powi(2) + g * traj.q_at(last)[0];
    assert!((e - energy).abs() < 1e-10, "{e} against {energy}");
    assert!(!traj.impacts.is_empty());
}

#[test]
fn a_resumed_run_takes_the_impulses_and_samples_after_its_start_bit_for_bit() {
    let g = 9.81;
    let ball = BouncingBall::new(g).unwrap();
    let contacts = floor(1.0, Law::Reflect);
    // Impulses inside a step, at the checkpoint's time (the first run's) and after it.
    let impulses = || vec![blow(0.1234, &[1.0]), blow(2.0, &[-0.5]), blow(3.0001, &[0.25])];
    let samples: Vec<f64> = (1..40).map(|k| 0.1 * k as f64 + 0.003).collect();
    let run = |schedule: &Schedule<'static>, steps: usize, from: Option<Vec<u8>>| -> Trajectory {
        let watch = both(&contacts, schedule);
        match from {
            None => drop_ball(&Options::new(0.01, steps), watch),
            Some(bytes) => {
                let checkpoint = Checkpoint::from_bytes(&bytes).unwrap();
                resume_watching(&ball, checkpoint, steps, 1, || Ok(()), watch)
            }
        }
        .unwrap()
    };
    for with_samples in [false, true] {
        let schedule = Schedule::new(impulses(), if with_samples { samples.clone() } else { vec![] }).unwrap();
        let whole = run(&schedule, 400, None);
        let first = run(&schedule, 200, None);
        let rest = run(&schedule, 200, Some(first.checkpoint.clone()));
        assert_eq!(end_state(&rest), end_state(&whole));
        let n = first.len() - usize::from(!with_samples);
        assert_eq!(&whole.t[..n], &first.t[..n]);
        assert_eq!(&whole.t[n..], &rest.t[..]);
        assert_eq!(&whole.q[n..], &rest.q[..]);
    }
}

#[test]
fn bad_schedules_are_refused_by_name() {
    let message = |e: Error| e.to_string();
    let nan = Schedule::new(vec![blow(f64::NAN, &[1.0])], vec![])
        .err()
        .map(message)
        .unwrap();
    assert!(nan.contains("impulses") && nan.contains("finite"), "{nan}");
    let unsorted = Schedule::new(vec![], vec![0.5, 0.2]).err().map(message).unwrap();
    assert!(unsorted.contains("t_eval") && unsorted.contains("sorted"), "{unsorted}");
    let schedule = Schedule::new(vec![blow(0.5, &[1.0, 2.0])], vec![]).unwrap();
    let failure = run_oscillator(Method::Verlet, &Options::new(0.1, 10), &schedule).unwrap_err();
    let refused = failure.error.to_string();
    assert!(
        refused.contains("impulses[0]") && refused.contains("2 components of impulse for 1"),
        "{refused}"
    );
}

#[test]
fn an_ensemble_member_with_impulses_samples_and_contacts_is_its_single_run_bit_for_bit() {
    let g = 9.81;
    let ball = BouncingBall::new(g).unwrap();
    let contacts = floor(1.0, Law::Reflect);
    let samples: Vec<f64> = (1..60).map(|k| 0.05 * k as f64 + 0.001).collect();
    let watched = MemberWatch {
        contacts: vec![NativeContact {
            surface: NativeSurface::Wall {
                coordinate: 0,
                value: 0.0,
            },
            restitution: 1.0,
            law: Law::Reflect,
            friction: None,
            name: "floor".into(),
        }],
        impulses: vec![(0.2345, Generalized(vec![2.0])), (1.5, Generalized(vec![-1.0]))],
        samples: samples.clone(),
        ..MemberWatch::default()
    };
    let (q0, p0) = ([1.0, 0.5, 2.0], [0.0, 1.0, -1.0]);
    let options = Options::new(0.01, 300);
    let ensemble = verlet_ensemble(&ball, (&q0, &p0), &options, &watched);
    for (i, outcome) in ensemble.members.iter().enumerate() {
        let schedule = Schedule::new(vec![blow(0.2345, &[2.0]), blow(1.5, &[-1.0])], samples.clone()).unwrap();
        let watch = both(&contacts, &schedule);
        let single = integrate_watching(
            &ball,
            Method::Verlet,
            &q0[i..=i],
            &p0[i..=i],
            &options,
            || Ok(()),
            watch,
        )
        .unwrap();
        assert_eq!(single.t, samples);
        assert_eq!(outcome.as_ref().unwrap(), &single, "member {i}");
    }
}
