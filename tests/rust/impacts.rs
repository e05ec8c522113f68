//! Impacts on unilateral contacts φ(q) ≥ 0, resolved in the core's step loop: the bouncing ball
//! (a native wall) and the circular billiard (a native ellipsoid) against their exact motion,
//! and the bits: a step
//! without an impact, a resumed run and an ensemble member are those of the plain run.

use varmech::integrators::{
    integrate, integrate_watching, resume_watching, Checkpoint, Contacts, Detector, DiscreteEnergy, Dynamics,
    EventSpec, Failure, General, Impacts, Law, MemberWatch, Method, NativeContact, NativeEvent, NativeSurface, Options,
    Stepper, Trajectory, Watch, Watcher,
};
use varmech::model::Lagrangian;
use varmech::scenes::{planar_chain, BouncingBall, EllipticBilliard, NBody};
use varmech::{Error, ModelError};

use crate::common::contacts::{floor, table, wall};
use crate::common::verlet_ensemble;

const G: f64 = 9.81;

/// The ball (g = 9.81) dropped from rest at height 1 with verlet, watching `watch`.
pub(crate) fn drop_ball(options: &Options, watch: Watch<'_, '_, '_>) -> Result<Trajectory, Box<Failure>> {
    let ball = BouncingBall::new(G).unwrap();
    integrate_watching(&ball, Method::Verlet, &[1.0], &[0.0], options, || Ok(()), watch)
}

pub(crate) fn with_contacts<'w>(contacts: &'w Contacts<'static>) -> Watch<'w, 'static, 'static> {
    Watch {
        events: None,
        contacts: Some(contacts),
        ..Watch::default()
    }
}

/// The run of `model` by `method` from (q0, p0), resolving the impacts on `contacts`.
pub(crate) fn watching<S: Dynamics + ?Sized>(
    model: &S,
    method: Method,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    contacts: &Contacts<'static>,
) -> Result<Trajectory, Box<Failure>> {
    integrate_watching(model, method, q0, p0, options, || Ok(()), with_contacts(contacts))
}

#[test]
fn the_ball_first_hits_the_floor_at_the_exact_time_and_keeps_its_energy() {
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(1.0, Law::Reflect);
    let (h0, dt) = (1.0, 1e-3);
    let period = 2.0 * (2.0 * h0 / G).sqrt();
    let options = Options::new(dt, (20.0 * period / dt) as usize);
    let traj = watching(&ball, Method::Verlet, (&[h0], &[0.0]), &options, &contacts).unwrap();
    let impacts = &traj.impacts;
    assert_eq!(impacts.len(), 20, "{:?}", impacts.t);
    // Verlet is exact on the parabola, and the contact is located to round-off.
    assert!(
        (impacts.t[0] - (2.0 * h0 / G).sqrt()).abs() <= 1e-12,
        "{}",
        impacts.t[0]
    );
    for k in 0..impacts.len() {
        let exact = (k as f64 + 0.5) * period;
        assert!(
            (impacts.t[k] - exact).abs() <= 1e-11,
            "impact {k}: {} against {exact}",
            impacts.t[k]
        );
        assert!(impacts.q_at(k)[0].abs() <= 1e-15);
        // The reflection reverses the momentum.
        assert_eq!(impacts.p_after_at(k)[0], -impacts.p_before_at(k)[0]);
    }
    // H at round-off at every saved state, impacts included.
    let h = |k: usize| ball.energy_terms(traj.q_at(k), traj.p_at(k), 0.0).unwrap().energy;
    let worst = (0..traj.len()).map(|k| (h(k) - G * h0).abs()).fold(0.0, f64::max);
    assert!(worst <= 1e-12, "energy error {worst}");
    // Every height stays above the floor, and the apex keeps h₀.
    assert!((0..traj.len()).all(|k| traj.q_at(k)[0] >= -1e-15));
    let apex = (0..traj.len()).map(|k| traj.q_at(k)[0]).fold(0.0, f64::max);
    assert!((apex - h0).abs() <= 1e-12);
    // One time, two rows at each impact.
    let k = traj.t.iter().position(|&t| t == impacts.t[0]).unwrap();
    assert_eq!(traj.t[k + 1], impacts.t[0]);
    assert_eq!(traj.p_at(k + 1), impacts.p_after_at(0));
}

/// The circular billiard: the free particle, its unit table (reflect law) and its start (q0, p0).
fn billiard() -> (EllipticBilliard, Contacts<'static>, ([f64; 2], [f64; 2])) {
    let free = EllipticBilliard::new(1.0, 1.0).unwrap();
    (free, table(1.0, Law::Reflect), ([0.3, -0.2], [0.6, 0.8]))
}

#[test]
fn the_circular_billiard_stays_on_the_table_with_its_speed_and_angular_momentum() {
    // A free particle: Verlet is exact between impacts, and the reflection at the circle, along
    // its radius, keeps |p| and the angular momentum L = x p_y − y p_x about the centre.
    let (free, contacts, (q0, p0)) = billiard();
    let options = Options::new(0.01, 100_000);
    let traj = watching(&free, Method::Verlet, (&q0, &p0), &options, &contacts).unwrap();
    // Chords of length 2√(1 − d²), d = |L|/|p| the distance of the path from the centre.
    let angular = |q: &[f64], p: &[f64]| q[0] * p[1] - q[1] * p[0];
    let l0 = angular(&q0, &p0);
    let chord = 2.0 * (1.0 - l0 * l0).sqrt();
    let expected = (1000.0 / chord) as usize;
    assert!(
        traj.impacts.len().abs_diff(expected) <= 1,
        "{} impacts",
        traj.impacts.len()
    );
    for k in 0..traj.len() {
        let (q, p) = (traj.q_at(k), traj.p_at(k));
        assert!(
            q[0] * q[0] + q[1] * q[1] <= 1.0 + 4e-15,
            "row {k}: |q|² = {}",
            q[0] * q[0] + q[1] * q[1]
        );
        assert!(
            (p[0].hypot(p[1]) - 1.0).abs() <= 1e-13,
            "row {k}: |p| = {}",
            p[0].hypot(p[1])
        );
        assert!(
            (angular(q, p) - l0).abs() <= 1e-13,
            "row {k}: L = {} against {l0}",
            angular(q, p)
        );
    }
    // Every contact on the circle, to round-off.
    for k in 0..traj.impacts.len() {
        let q = traj.impacts.q_at(k);
        assert!((q[0].hypot(q[1]) - 1.0).abs() <= 1e-15);
    }
}

#[test]
fn a_step_without_an_impact_is_bit_for_bit_the_step_without_contacts() {
    // A floor the ball never reaches, with and without an event beside it.
    let ball = BouncingBall::new(G).unwrap();
    let far = wall(0, -1e3, 1.0, Law::Reflect, "far");
    let contacts = Contacts::new(vec![far]).unwrap();
    let options = Options {
        save_every: 7,
        ..Options::new(1e-3, 5000)
    };
    for method in [Method::Verlet, Method::Yoshida4, Method::Midpoint] {
        let plain = integrate(&ball, method, &[1.0], &[2.0], &options, || Ok(())).unwrap();
        let watched = watching(&ball, method, (&[1.0], &[2.0]), &options, &contacts).unwrap();
        assert!(watched.impacts.is_empty());
        assert_eq!(
            (&watched.t, &watched.q, &watched.p),
            (&plain.t, &plain.q, &plain.p),
            "{method:?}"
        );
        assert_eq!(watched.checkpoint, plain.checkpoint, "{method:?}");

        let mut events = height(0.5, -1);
        let alone = integrate_watching(
            &ball,
            method,
            &[1.0],
            &[2.0],
            &options,
            || Ok(()),
            Watch::events(&mut events),
        )
        .unwrap();
        let mut events = height(0.5, -1);
        let watch = Watch {
            events: Some(&mut events),
            contacts: Some(&contacts),
            ..Watch::default()
        };
        let both = integrate_watching(&ball, method, &[1.0], &[2.0], &options, || Ok(()), watch).unwrap();
        assert_eq!(both.events.len(), 1, "{method:?}");
        assert_eq!(
            (&both.t, &both.q, &both.p, &both.events),
            (&alone.t, &alone.q, &alone.p, &alone.events)
        );
    }
}

/// The event q₀ = `value`, crossed in `direction`.
fn height(value: f64, direction: i8) -> Detector<'static> {
    let crossing = vec![NativeEvent::Crossing { coordinate: 0, value }];
    let spec = EventSpec {
        name: "height".into(),
        direction,
        terminal: 0,
    };
    Detector::new(Box::new(crossing), vec![spec]).unwrap()
}

#[test]
fn events_are_located_on_the_pieces_of_a_step_with_an_impact() {
    // The ball from h₀ = 1 crosses y = 0.05 at √(2(1 − y)/g) after each apex, down, and as
    // long before the next, up: with dt = 0.1 both fall in the step of the impact between them,
    // on its pieces.
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(1.0, Law::Reflect);
    let (fall, y) = ((2.0 / G).sqrt(), 0.05);
    let down = (2.0 * (1.0 - y) / G).sqrt();
    let options = Options::new(0.1, 40);
    let mut events = height(y, 0);
    let watch = Watch {
        events: Some(&mut events),
        contacts: Some(&contacts),
        ..Watch::default()
    };
    let traj = integrate_watching(&ball, Method::Verlet, &[1.0], &[0.0], &options, || Ok(()), watch).unwrap();
    assert_eq!(traj.events.len(), 2 * traj.impacts.len());
    let mut on_pieces = 0;
    for (k, e) in traj.events.iter().enumerate() {
        let apex = 2.0 * (k / 2) as f64 * fall;
        let exact = if k % 2 == 0 {
            apex + down
        } else {
            apex + 2.0 * fall - down
        };
        assert!((e.t - exact).abs() <= 1e-12, "event {k}: {} against {exact}", e.t);
        assert!((e.q[0] - y).abs() <= 1e-14);
        on_pieces += usize::from(traj.impacts.step.contains(&e.step));
    }
    assert!(on_pieces >= 4, "{on_pieces} events in steps with an impact");
}

/// The run of `steps` steps of h with verlet from `start` watching `contacts` (saving every
/// `save_every`-th state), the run of its `first` steps, and that one resumed from its checkpoint
/// for the rest.
pub(crate) fn split_run<S: Dynamics>(
    model: &S,
    contacts: &Contacts<'static>,
    (q0, p0): (&[f64], &[f64]),
    (h, steps, first, save_every): (f64, usize, usize, usize),
) -> [Trajectory; 3] {
    let whole = Options {
        save_every,
        ..Options::new(h, steps)
    };
    let run = |steps: usize| {
        let options = Options { steps, ..whole.clone() };
        watching(model, Method::Verlet, (q0, p0), &options, contacts).unwrap()
    };
    let (all, part) = (run(steps), run(first));
    let checkpoint = Checkpoint::from_bytes(&part.checkpoint).unwrap();
    let rest = resume_watching(
        model,
        checkpoint,
        steps - first,
        save_every,
        || Ok(()),
        with_contacts(contacts),
    )
    .unwrap();
    [all, part, rest]
}

#[test]
fn a_resumed_run_with_its_contacts_is_the_whole_run_bit_for_bit() {
    let (free, contacts, start) = billiard();
    let [all, part, rest] = split_run(&free, &contacts, (&start.0, &start.1), (0.01, 3000, 1234, 10));
    assert!(part.impacts.len() >= 5 && rest.impacts.len() >= 5);
    assert_eq!(rest.steps, 3000);
    // The impacts of the two runs are the whole run's, and so are the states saved after the join.
    let joined =
        |column: fn(&Impacts) -> &Vec<f64>| [column(&part.impacts).clone(), column(&rest.impacts).clone()].concat();
    assert_eq!(joined(|i| &i.t), all.impacts.t);
    assert_eq!(joined(|i| &i.q), all.impacts.q);
    assert_eq!(joined(|i| &i.p_after), all.impacts.p_after);
    let tail = rest.len() - 1;
    assert_eq!(&all.q[all.q.len() - 2 * tail..], &rest.q[2..]);
    assert_eq!(&all.p[all.p.len() - 2 * tail..], &rest.p[2..]);
}

#[test]
fn an_ensemble_member_is_its_single_run_bit_for_bit() {
    let free = EllipticBilliard::new(1.0, 1.0).unwrap();
    let table = NativeContact {
        surface: NativeSurface::Ellipsoid {
            coordinates: vec![0, 1],
            centre: vec![0.0, 0.0],
            semi_axes: vec![1.0, 1.0],
            inside: true,
        },
        restitution: 1.0,
        law: Law::Reflect,
        friction: None,
        name: "table".into(),
    };
    let members = 6;
    let q0: Vec<f64> = (0..members).flat_map(|i| [0.1 * i as f64, -0.2]).collect();
    let p0: Vec<f64> = (0..members).flat_map(|i| [0.6, 0.8 - 0.1 * i as f64]).collect();
    let options = Options::new(0.01, 2000);
    let watched = MemberWatch {
        contacts: vec![table.clone()],
        ..MemberWatch::default()
    };
    let ensemble = verlet_ensemble(&free, (&q0, &p0), &options, &watched);
    let contacts = Contacts::native(std::slice::from_ref(&table)).unwrap();
    for (i, outcome) in ensemble.members.iter().enumerate() {
        let member = outcome.as_ref().unwrap();
        let rows = 2 * i..2 * i + 2;
        let single = watching(
            &free,
            Method::Verlet,
            (&q0[rows.clone()], &p0[rows]),
            &options,
            &contacts,
        )
        .unwrap();
        assert!(single.impacts.len() >= 5);
        assert_eq!(member, &single, "member {i}");
    }
}

#[test]
fn the_variational_law_keeps_the_discrete_energy_across_each_impact() {
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(1.0, Law::Variational);
    let options = Options::new(0.01, 300);
    let traj = drop_ball(&options, with_contacts(&contacts)).unwrap();
    assert_eq!((traj.impacts.len(), traj.impacts.grazing), (3, 0));
    let mut energy = DiscreteEnergy::new(Method::Verlet, 1).unwrap();
    for k in 0..traj.impacts.len() {
        // The rows: the step's start, the impact's two, the step's end.
        let (t, q) = (traj.impacts.t[k], traj.impacts.q_at(k));
        let r = traj.t.iter().position(|&x| x == t).unwrap();
        let start = (traj.q_at(r - 1), traj.p_at(r - 1));
        let before = energy
            .energy(
                &ball,
                traj.t[r - 1],
                t - traj.t[r - 1],
                start,
                (q, traj.impacts.p_before_at(k)),
            )
            .unwrap();
        let end = (traj.q_at(r + 2), traj.p_at(r + 2));
        let after = energy
            .energy(&ball, t, traj.t[r + 2] - t, (q, traj.impacts.p_after_at(k)), end)
            .unwrap();
        assert!(
            (after - before).abs() <= 1e-13 * before.abs(),
            "impact {k}: E_d {before} then {after}"
        );
        // Not the reflection: λ differs from it by O(h²).
        let reflected = -traj.impacts.p_before_at(k)[0];
        let off = (traj.impacts.p_after_at(k)[0] - reflected).abs();
        assert!(off > 0.0 && off <= 1e-3, "impact {k}: {off}");
    }
}

#[test]
fn the_variational_law_moves_h_by_g2h2_times_1_minus_2alpha_over_8_at_the_methods_order() {
    // Verlet's discrete energy on an exact parabola of duration τ is E_d = H − g²τ²/8; the law
    // makes E_d(τ₁ = αh) = E_d(τ₂ = (1 − α)h) at the impact, so H jumps by g²h²(1 − 2α)/8 there
    // (the apex falls by that over g). With the first impact at the fraction α = 1/4 of a step,
    // the jump and the second impact's time error fall at exactly order 2.
    let contacts = floor(1.0, Law::Variational);
    let (t1, alpha) = ((2.0 / G).sqrt(), 0.25);
    let mut errors = Vec::new();
    for m in [100, 200, 400] {
        let dt = t1 / (m as f64 + alpha);
        let options = Options::new(dt, 3 * m + 10);
        let traj = drop_ball(&options, with_contacts(&contacts)).unwrap();
        let impacts = &traj.impacts;
        assert_eq!(impacts.len(), 2);
        assert!((impacts.t[0] - t1).abs() < 1e-14);
        let jump = 0.5 * impacts.p_before_at(1)[0].powi(2) - G;
        let exact = G * G * dt * dt * (1.0 - 2.0 * alpha) / 8.0;
        assert!(
            (jump - exact).abs() <= 1e-8 * exact,
            "m = {m}: H jumps by {jump}, not {exact}"
        );
        errors.push(impacts.t[1] - 3.0 * t1);
    }
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((order - 2.0).abs() < 0.02, "{errors:?}: order {order}");
    }
}

#[test]
fn contacts_that_do_not_fit_are_refused_by_name() {
    let ball = BouncingBall::new(G).unwrap();
    let options = Options::new(0.01, 10);
    let refusal = |contacts: &Contacts<'static>, method: Method, q0: f64| {
        let run = watching(&ball, method, (&[q0], &[0.0]), &options, contacts);
        match run.unwrap_err().error {
            Error::InvalidArgument { argument, reason } => (argument, reason),
            other => panic!("{other}"),
        }
    };
    let (argument, reason) = refusal(&floor(1.0, Law::Variational), Method::Rk4, 1.0);
    assert_eq!(argument, "contacts");
    assert!(
        reason.starts_with("\"floor\" (contacts[0]): the variational collision integrator needs"),
        "{reason}"
    );
    assert_eq!(refusal(&floor(1.0, Law::Reflect), Method::Verlet, -0.1).0, "q0");
    let wrong = wall(3, 0.0, 1.0, Law::Reflect, "wall");
    let (argument, reason) = refusal(&Contacts::new(vec![wrong]).unwrap(), Method::Verlet, 1.0);
    assert_eq!(
        (argument, reason.as_str()),
        ("contacts", "\"wall\" (contacts[0]): coordinate 3 is not in 0 … 0")
    );
    let elastic = wall(0, 0.0, 1.5, Law::Reflect, "wall");
    assert!(Contacts::new(vec![elastic]).is_err());
}

#[test]
fn a_stepper_stepped_through_a_watcher_is_the_run_bit_for_bit() {
    // Stepper-level stepping with contacts (the binding's Stepper): the run's own loop.
    let (free, contacts, (q0, p0)) = billiard();
    let options = Options::new(0.01, 2000);
    let run = watching(&free, Method::Verlet, (&q0, &p0), &options, &contacts).unwrap();
    let mut stepper = Stepper::new(&free, Method::Verlet, &q0, &p0, &options).unwrap();
    let mut watcher = Watcher::begin(&free, &mut stepper, with_contacts(&contacts), "q0").unwrap();
    let mut record = Trajectory::default();
    record.impacts.dim = 2;
    let mut poll = || -> Result<(), ModelError> { Ok(()) };
    for _ in 0..20 {
        assert_eq!(
            watcher.advance(&mut stepper, 100, &mut record, &mut poll).unwrap(),
            None
        );
    }
    assert!(run.impacts.len() >= 5);
    assert_eq!(record.impacts, run.impacts);
    let last = run.len() - 1;
    assert_eq!((stepper.q(), stepper.p()), (run.q_at(last), run.p_at(last)));
}

/// The stepper of `sys` from (q0, p0) stepped `steps` times, each step through a watcher of
/// `contacts` resumed for it (as the binding's `Stepper.step()` does), and the impacts.
fn stepped_one_call_at_a_time<S: varmech::integrators::Dynamics>(
    sys: &S,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    contacts: &Contacts<'static>,
) -> (Vec<f64>, Vec<f64>, Impacts) {
    let mut stepper = Stepper::new(sys, Method::Verlet, q0, p0, options).unwrap();
    drop(Watcher::begin(sys, &mut stepper, with_contacts(contacts), "q0").unwrap());
    let mut impacts = Impacts {
        dim: q0.len(),
        ..Impacts::default()
    };
    let mut poll = || -> Result<(), ModelError> { Ok(()) };
    for _ in 0..options.steps {
        let mut watcher = Watcher::resume(sys, &mut stepper, with_contacts(contacts)).unwrap();
        let mut record = Trajectory::default();
        record.impacts.dim = q0.len();
        assert_eq!(watcher.advance(&mut stepper, 1, &mut record, &mut poll).unwrap(), None);
        impacts.append(&mut record.impacts);
    }
    (stepper.q().to_vec(), stepper.p().to_vec(), impacts)
}

#[test]
fn a_stepper_stepped_through_a_watcher_resumed_for_each_step_is_the_run_bit_for_bit() {
    // The binding's Stepper with contacts begins a watcher for each call: φ recomputed at the
    // state is the run's carried φ, bit for bit, and the scratch restarts at every piece.
    let ball = BouncingBall::new(G).unwrap();
    let on_floor = floor(1.0, Law::Variational);
    let options = Options::new(1e-2, 600);
    let (q0, p0) = ([1.0], [0.0]);
    let run = watching(&ball, Method::Verlet, (&q0, &p0), &options, &on_floor);
    let ball_run = (
        run.unwrap(),
        stepped_one_call_at_a_time(&ball, (&q0, &p0), &options, &on_floor),
    );
    let (billiard, on_table, (q0, p0)) = billiard();
    let options = Options::new(1e-2, 1000);
    let run = watching(&billiard, Method::Verlet, (&q0, &p0), &options, &on_table);
    let billiard_run = (
        run.unwrap(),
        stepped_one_call_at_a_time(&billiard, (&q0, &p0), &options, &on_table),
    );
    for (run, (q, p, impacts)) in [ball_run, billiard_run] {
        assert!(run.impacts.len() >= 5, "{}", run.impacts.len());
        assert_eq!(impacts, run.impacts);
        let last = run.len() - 1;
        assert_eq!((&q[..], &p[..]), (run.q_at(last), run.p_at(last)));
    }
}

#[test]
fn a_state_a_round_off_past_a_surface_leaves_it_and_one_further_past_is_refused() {
    // φ = −1e-17, moving away: the state an impact located on the floor's far side leaves (or a
    // point put on a curved surface in floating point). A run starts there, and a resumed
    // watcher takes the step leaving the floor, with no impact, bit for bit the step without
    // contacts; φ = −1e-9 is outside, and a run's start refuses it naming the argument.
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(1.0, Law::Variational);
    let options = Options::new(1e-3, 1);
    let (q0, p0) = ([-1e-17], [1.0]);
    let mut outside = Stepper::new(&ball, Method::Verlet, &[-1e-9], &p0, &options).unwrap();
    match Watcher::begin(&ball, &mut outside, with_contacts(&contacts), "q0") {
        Err(Error::InvalidArgument { argument, reason }) => {
            assert_eq!(argument, "q0");
            assert!(reason.contains("floor"), "{reason}");
        }
        other => panic!("expected q0 refused, got {:?}", other.err()),
    }
    let mut free = Stepper::new(&ball, Method::Verlet, &q0, &p0, &options).unwrap();
    free.step().unwrap();
    for begun in [true, false] {
        let mut stepper = Stepper::new(&ball, Method::Verlet, &q0, &p0, &options).unwrap();
        let mut watcher = if begun {
            Watcher::begin(&ball, &mut stepper, with_contacts(&contacts), "q0").unwrap()
        } else {
            Watcher::resume(&ball, &mut stepper, with_contacts(&contacts)).unwrap()
        };
        let mut record = Trajectory::default();
        record.impacts.dim = 1;
        let mut poll = || -> Result<(), ModelError> { Ok(()) };
        watcher.advance(&mut stepper, 1, &mut record, &mut poll).unwrap();
        assert!(record.impacts.is_empty() && record.impacts.switches.is_empty());
        assert!(stepper.q()[0] > 0.0);
        assert_eq!((stepper.q(), stepper.p()), (free.q(), free.p()));
    }
}

/// A wall q_k ≥ `value` (e = 1 under `law`) alone, named "wall".
fn lone_wall(coordinate: usize, value: f64, law: Law) -> Contacts<'static> {
    Contacts::new(vec![wall(coordinate, value, 1.0, law, "wall")]).unwrap()
}

/// The run of `method` on `model` from (q0, p0) with `contacts` and no events, which takes its
/// steps in the method's own loop, against the same run plain (`contacts` never hit) or
/// watching an event that never occurs, which takes them one at a time: the same states, bit
/// for bit, and the same impacts.
fn same_bits<S: Dynamics>(
    model: &S,
    method: Method,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    contacts: &Contacts<'static>,
    plain: bool,
) -> usize {
    let fast = watching(model, method, (q0, p0), options, contacts).unwrap();
    let other = if plain {
        integrate(model, method, q0, p0, options, || Ok(())).unwrap()
    } else {
        let mut never = height(1e12, 0);
        let watch = Watch {
            events: Some(&mut never),
            contacts: Some(contacts),
            ..Watch::default()
        };
        integrate_watching(model, method, q0, p0, options, || Ok(()), watch).unwrap()
    };
    assert!(other.events.is_empty());
    assert_eq!(fast.len(), other.len(), "{method:?}");
    assert_eq!(
        (&fast.t, &fast.q, &fast.p),
        (&other.t, &other.q, &other.p),
        "{method:?}"
    );
    assert_eq!(fast.impacts, other.impacts, "{method:?}");
    // The checkpoint counts the work done: the events' partial steps, and the Wisdom–Holman
    // methods' synchronisation after each step, which a watched run needs.
    if plain && !Method::WISDOM_HOLMAN.contains(&method) {
        assert_eq!(fast.checkpoint, other.checkpoint, "{method:?}");
    }
    fast.impacts.len()
}

#[test]
fn a_contact_never_hit_leaves_every_step_loop_bit_for_bit_the_plain_one() {
    // Each loop the steps may take: the fixed-size kick–drift loop (the ball, with and without
    // compensated summation), the step-by-step one (18 coordinates; midpoint on a separable
    // model), the method's own variables (Wisdom–Holman), the fixed-size DEL loop (midpoint
    // and trapezoid on the ball as a general Lagrangian) and a constrained model's (RATTLE).
    let ball = BouncingBall::new(G).unwrap();
    let far = lone_wall(0, -1e3, Law::Reflect);
    for compensated in [true, false] {
        let options = Options {
            save_every: 7,
            compensated,
            ..Options::new(1e-3, 5000)
        };
        for method in [Method::Verlet, Method::Yoshida4, Method::Midpoint] {
            same_bits(&ball, method, (&[1.0], &[2.0]), &options, &far, true);
        }
        for method in [Method::Midpoint, Method::Trapezoid] {
            same_bits(&General(&ball), method, (&[1.0], &[2.0]), &options, &far, true);
        }
    }
    let solar = NBody::outer_solar_system();
    let initial = (&solar.initial.q[..], &solar.initial.p[..]);
    let options = Options {
        save_every: 3,
        ..Options::new(10.0, 500)
    };
    for method in [Method::Verlet, Method::WisdomHolmanCorrected] {
        same_bits(
            &solar.system,
            method,
            initial,
            &options,
            &lone_wall(4, -1e9, Law::Reflect),
            true,
        );
    }
    let chain = planar_chain(8).unwrap();
    let options = Options {
        save_every: 3,
        ..Options::new(0.01, 500)
    };
    let initial = (&chain.initial.q[..], &chain.initial.p[..]);
    same_bits(
        &chain.system,
        Method::Rattle,
        initial,
        &options,
        &lone_wall(1, -1e3, Law::Reflect),
        true,
    );
}

#[test]
fn steps_with_impacts_in_the_methods_loop_are_bit_for_bit_those_taken_one_at_a_time() {
    // A run with contacts alone takes its steps in the method's own loop and stops it at each
    // step that crosses a contact; watching an event too, it takes them one at a time.
    let ball = BouncingBall::new(G).unwrap();
    let options = Options {
        save_every: 5,
        ..Options::new(1e-2, 3000)
    };
    for law in [Law::Reflect, Law::Variational] {
        for method in [Method::Verlet, Method::Yoshida4, Method::Midpoint] {
            let impacts = same_bits(&ball, method, (&[1.0], &[0.0]), &options, &floor(1.0, law), false);
            assert!(impacts >= 30, "{method:?}, {law:?}: {impacts} impacts");
        }
    }
    let impacts = same_bits(
        &General(&ball),
        Method::Midpoint,
        (&[1.0], &[0.0]),
        &options,
        &floor(1.0, Law::Reflect),
        false,
    );
    assert!(impacts >= 30);
    let free = EllipticBilliard::new(1.0, 1.0).unwrap();
    for method in [Method::Verlet, Method::Midpoint] {
        let impacts = same_bits(
            &free,
            method,
            (&[0.3, -0.2], &[0.6, 0.8]),
            &options,
            &table(1.0, Law::Reflect),
            false,
        );
        assert!(impacts >= 10, "{method:?}: {impacts} impacts");
    }
}
