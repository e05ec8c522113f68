//! Contacts that hold: a ball with e < 1 bouncing to rest at the limit of its Zeno series and
//! then resting with λ = mg; a particle sliding from rest near the top of a smooth sphere, held on
//! it until it leaves where cos θ = (2/3)cos θ₀, located at the method's order; a run resumed from
//! a held state bit for bit; a method that cannot hold a contact still ending an accumulation
//! of impacts with `Error::Contact`; and Byerly's billiard ball, sliding on a rough table until
//! it rolls at 5v₀/7 from t = 2v₀/(7μg), exactly, its run resumed bit for bit; and a wheel whose
//! slip rows turn with its heading, rolling on its circle at the method's order while friction
//! holds it, and skidding where that needs more than μ_s mg; a held step past the surface's
//! curvature ending the run with `Error::Contact`, which advises the smaller step that runs; and
//! a particle in a trap pressed on a floor above its equilibrium, brought to rest at the Zeno
//! limit of its harmonic flights and held there at every step.

use nalgebra::DMatrix;
use varmech::integrators::{
    integrate_watching, Composition, Contact, Contacts, Dynamics, Feature, Friction, Law, Method, NativeSurface,
    Options, Slip, SlipRows, Switch, Trajectory,
};
use varmech::model::{Mass, MechanicalSystem, Reaction};
use varmech::scenes::BouncingBall;
use varmech::{Error, ModelError};

use crate::common::contacts::{circle, floor, wall};
use crate::common::Potential;
use crate::impacts::{drop_ball, split_run, watching, with_contacts};

const G: f64 = 9.81;

/// A body of unit mass under gravity, V = g y (y = q[1]), its coordinates' masses given: a
/// particle in the plane, a ball (x, y, θ).
struct Weighed(Mass, usize);

impl MechanicalSystem for Weighed {
    fn dim(&self) -> usize {
        self.1
    }

    fn mass(&self) -> &Mass {
        &self.0
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(G * q[1])
    }

    fn gradient(&self, _q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        grad[1] = G;
        Ok(())
    }
}

/// A unit mass in the plane under gravity.
fn particle() -> Weighed {
    Weighed(Mass::scalar(1.0).unwrap(), 2)
}

/// The outside of the unit circle, |q| ≥ 1 (a native ellipsoid, outside).
fn sphere() -> Contacts<'static> {
    circle(1.0, false, 0.0, Law::Reflect, "sphere")
}

/// λ of the contact φ at a saved state of `traj` on `model`, ∇φ given.
fn multiplier<S: Dynamics>(model: &S, traj: &Trajectory, k: usize, gradient: fn(&[f64]) -> Vec<f64>) -> f64 {
    let n = traj.dim;
    let rows = |q: &[f64], c: &mut DMatrix<f64>, b: &mut [f64]| -> Result<(), ModelError> {
        b.fill(0.0);
        for (i, g) in gradient(q).into_iter().enumerate() {
            c[(0, i)] = g;
        }
        Ok(())
    };
    let mut reaction = Reaction::new(n, 1);
    reaction
        .solve(model.as_lagrangian(), &rows, (traj.q_at(k), traj.p_at(k), traj.t[k]))
        .unwrap();
    reaction.multipliers[0]
}

#[test]
fn a_ball_with_e_below_1_comes_to_rest_at_the_zeno_limit_and_rests_with_lambda_mg() {
    // Dropped from rest at h₀ = 1: the first impact at t₁ = √(2h₀/g), the rebounds' flights
    // 2eᵏt₁ summing to t∞ = t₁(1 + e)/(1 − e).
    let ball = BouncingBall::new(G).unwrap();
    let e = 0.5;
    let t_rest = (2.0 / G).sqrt() * (1.0 + e) / (1.0 - e);
    for dt in [1e-3, 1e-2, 0.1] {
        let contacts = floor(e, Law::Reflect);
        let options = Options::new(dt, (3.0 / dt) as usize);
        let traj = drop_ball(&options, with_contacts(&contacts)).unwrap();
        let switches = &traj.impacts.switches;
        assert_eq!(switches.len(), 1, "dt = {dt}: {:?}", switches.t);
        assert_eq!(switches.kind[0], Switch::Closed);
        // Verlet is exact on the parabolas and the impacts are located to round-off.
        assert!(
            (switches.t[0] - t_rest).abs() <= 1e-12,
            "dt = {dt}: {} against {t_rest}",
            switches.t[0]
        );
        // The contact closes at the impact whose rebounds last less than a step.
        let last = *traj.impacts.t.last().unwrap();
        assert!(t_rest - last <= dt, "dt = {dt}: closed at {last}");
        assert_eq!(traj.impacts.p_after.last(), Some(&0.0));
        // Resting from there: on the floor, at rest, pressed with λ = mg.
        let resting: Vec<usize> = (0..traj.len()).filter(|&k| traj.t[k] > last).collect();
        assert!(resting.len() >= 2, "dt = {dt}");
        for &k in &resting {
            assert!(traj.q_at(k)[0].abs() <= 1e-15, "dt = {dt}: q = {:?}", traj.q_at(k));
            assert!(traj.p_at(k)[0].abs() <= 1e-15, "dt = {dt}: p = {:?}", traj.p_at(k));
            let lambda = multiplier(&ball, &traj, k, |_| vec![1.0]);
            assert!((lambda - G).abs() <= 1e-9 * G, "dt = {dt}: λ = {lambda}");
        }
        assert_eq!(traj.steps, options.steps);
    }
}

#[test]
fn the_methods_with_a_held_step_are_verlet_and_its_compositions() {
    // The held step is RATTLE composed as the method composes Verlet: the table's
    // `Feature::HeldStep` must be that structure's, for every method.
    for method in Method::every() {
        assert_eq!(
            method.supports(Feature::HeldStep),
            Composition::of(method).is_some(),
            "{method:?}"
        );
    }
}

#[test]
fn a_method_that_cannot_hold_a_contact_ends_an_accumulation_of_impacts_with_a_contact_error() {
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(0.5, Law::Reflect);
    let options = Options::new(0.01, 300);
    let failure = integrate_watching(
        &ball,
        Method::Rk4,
        &[1.0],
        &[0.0],
        &options,
        || Ok(()),
        with_contacts(&contacts),
    )
    .unwrap_err();
    let Error::Contact { time, ref reason, .. } = failure.error else {
        panic!("{}", failure.error)
    };
    assert!(reason.contains("verlet and its compositions"), "{reason}");
    assert!((time - 1.35).abs() < 0.05, "{}", failure.error);
    assert!(failure.partial.impacts.switches.is_empty());
}

/// cos θ where the particle, from rest at θ₀ from the top of the unit sphere, leaves it with
/// `method` and step h: the lift-off's state, its radius checked at 1.
fn leaving(method: Method, theta0: f64, h: f64) -> f64 {
    let model = particle();
    let contacts = sphere();
    let (mut q0, p0) = ([theta0.sin(), theta0.cos()], [0.0, 0.0]);
    // On the surface to round-off, not inside it.
    while q0[0] * q0[0] + q0[1] * q0[1] < 1.0 {
        q0 = q0.map(|x| x * (1.0 + f64::EPSILON));
    }
    let options = Options::new(h, (1.5 / h) as usize);
    let traj = integrate_watching(&model, method, &q0, &p0, &options, || Ok(()), with_contacts(&contacts)).unwrap();
    let switches = &traj.impacts.switches;
    assert!(
        !switches.is_empty() && switches.kind[0] == Switch::Released,
        "{method:?}, h = {h}: {:?}",
        switches.t
    );
    let q = &switches.q[..2];
    let radius = q[0].hypot(q[1]);
    assert!((radius - 1.0).abs() <= 1e-13, "{method:?}, h = {h}: |q| = {radius}");
    // Held on the sphere up to there.
    for k in (0..traj.len()).filter(|&k| traj.t[k] <= switches.t[0]) {
        let (x, y) = (traj.q_at(k)[0], traj.q_at(k)[1]);
        assert!(
            (x.hypot(y) - 1.0).abs() <= 1e-13,
            "{method:?}, h = {h}: |q| = {}",
            x.hypot(y)
        );
    }
    q[1] / radius
}

#[test]
fn a_particle_sliding_on_a_smooth_sphere_leaves_it_where_cos_theta_is_two_thirds_of_cos_theta0_at_the_methods_order() {
    let theta0 = 0.3_f64;
    let exact = 2.0 / 3.0 * theta0.cos();
    for (method, order, h) in [(Method::Verlet, 2.0, 0.01), (Method::Yoshida4, 4.0, 0.04)] {
        let errors: Vec<f64> = [h, h / 2.0, h / 4.0]
            .iter()
            .map(|&h| (leaving(method, theta0, h) - exact).abs())
            .collect();
        let measured: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        for m in &measured {
            assert!(
                (m - order).abs() <= 0.25,
                "{method:?}: orders {measured:?}, errors {errors:?}"
            );
        }
    }
}

#[test]
fn a_run_resumed_from_a_held_state_is_the_whole_run_bit_for_bit() {
    let model = particle();
    let contacts = sphere();
    let [all, part, rest] = split_run(&model, &contacts, (&[0.0, 1.0], &[0.3, 0.0]), (0.01, 150, 40, 1));
    // Held at the join, released after it.
    assert!(part.impacts.switches.is_empty());
    assert_eq!(all.impacts.switches.kind, vec![Switch::Released]);
    assert_eq!(rest.impacts.switches, all.impacts.switches);
    assert_eq!(&all.q[all.q.len() - rest.q.len()..], &rest.q[..]);
    assert_eq!(&all.p[all.p.len() - rest.p.len()..], &rest.p[..]);
}

#[test]
fn a_held_step_past_the_surfaces_curvature_ends_the_run_with_a_contact_error_advising_a_smaller_step() {
    // At the bottom of the inside of the unit circle at speed 1, pressed by v² + g: a step of 2
    // moves it twice the radius, and no point of q₀ + s(q̇ + c∇φ) lies on the circle.
    let model = particle();
    let contacts = circle(1.0, true, 0.0, Law::Reflect, "bowl");
    let run = |h: f64| {
        let options = Options::new(h, 10);
        watching(&model, Method::Verlet, (&[0.0, -1.0], &[1.0, 0.0]), &options, &contacts)
    };
    let failure = run(2.0).unwrap_err();
    let Error::Contact { step, time, ref reason } = failure.error else {
        panic!("{}", failure.error)
    };
    assert_eq!((step, time), (1, 0.0));
    assert!(
        reason.contains("position constraint") && reason.contains("a smaller step helps"),
        "{reason}"
    );
    assert_eq!(failure.partial.q, vec![0.0, -1.0]);
    // As it advises: held on the circle at a step short against its radius.
    let traj = run(0.1).unwrap();
    for k in 0..traj.len() {
        let (x, y) = (traj.q_at(k)[0], traj.q_at(k)[1]);
        assert!((x.hypot(y) - 1.0).abs() <= 1e-15, "|q| = {}", x.hypot(y));
    }
}

const R: f64 = 0.1;
const INERTIA: f64 = 0.4 * R * R;

/// The floor y ≥ R with friction μ, the contact point slipping at ẋ − Rθ̇.
fn rough_floor(mu: f64) -> Contacts<'static> {
    let contact = Contact {
        surface: Box::new(NativeSurface::Wall {
            coordinate: 1,
            value: R,
        }),
        restitution: 0.0,
        law: Law::Reflect,
        friction: Some(Friction {
            static_coefficient: mu,
            kinetic: mu,
            slip: Slip::Rows {
                rows: 1,
                jacobian: vec![1.0, 0.0, -R],
            },
        }),
        name: "table".into(),
    };
    Contacts::new(vec![contact]).unwrap()
}

#[test]
fn byerlys_billiard_ball_slides_and_then_rolls_at_five_sevenths_of_its_speed_from_2v0_over_7_mu_g() {
    let (v0, mu) = (2.0, 0.2);
    // A uniform ball (x, y, θ) of unit mass and radius R.
    let ball = Weighed(Mass::diagonal(vec![1.0, 1.0, INERTIA]).unwrap(), 3);
    let contacts = rough_floor(mu);
    let rolls = 2.0 * v0 / (7.0 * mu * G);
    let (q0, p0) = ([0.0, R, 0.0], [v0, 0.0, 0.0]);
    for method in [Method::Verlet, Method::Yoshida4] {
        let options = Options::new(0.01, 200);
        let watch = with_contacts(&contacts);
        let traj = integrate_watching(&ball, method, &q0, &p0, &options, || Ok(()), watch).unwrap();
        let switches = &traj.impacts.switches;
        assert_eq!(switches.kind, vec![Switch::Stuck], "{method:?}");
        assert!(
            (switches.t[0] - rolls).abs() < 1e-13,
            "{method:?}: {} against {rolls}",
            switches.t[0]
        );
        // Constant forces: the held step is exact, sliding and rolling.
        for k in 0..traj.len() {
            let (t, p) = (traj.t[k], traj.p_at(k));
            let v = if t < rolls { v0 - mu * G * t } else { 5.0 * v0 / 7.0 };
            assert!((p[0] - v).abs() < 1e-13, "{method:?} at t = {t}: {} against {v}", p[0]);
        }
        let lost = -(2.0 / 7.0) * v0 * v0 / 2.0;
        let work = traj.work[traj.len() - 1];
        assert!(
            (work - lost).abs() < 1e-13,
            "{method:?}: the work {work} against {lost}"
        );
    }
    // Resumed while it slides, it rolls from the same time, its work counted on.
    let [all, part, rest] = split_run(&ball, &contacts, (&q0, &p0), (0.01, 100, 20, 1));
    assert!(part.impacts.switches.is_empty());
    assert_eq!(rest.impacts.switches, all.impacts.switches);
    assert_eq!(&all.q[all.q.len() - rest.q.len()..], &rest.q[..]);
    assert_eq!(&all.p[all.p.len() - rest.p.len()..], &rest.p[..]);
    assert_eq!(&all.work[all.work.len() - rest.work.len()..], &rest.work[..]);
}

/// The rows of a wheel of radius r held upright, on (x, z, y, φ, θ) (its height z second, where
/// [`Weighed`] puts gravity): its contact point slips at (ẋ − rθ̇ cos φ, ẏ − rθ̇ sin φ).
struct Rolling(f64);

impl SlipRows for Rolling {
    fn count(&self) -> usize {
        2
    }

    fn jacobian(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let (r, c, s) = (self.0, q[3].cos(), q[3].sin());
        out.copy_from_slice(&[1.0, 0.0, 0.0, 0.0, -r * c, 0.0, 0.0, 1.0, 0.0, -r * s]);
        Ok(())
    }
}

#[test]
fn a_wheel_whose_slip_rows_turn_with_it_rolls_on_its_circle_at_the_methods_order_and_skids_past_mu_s() {
    // Unit mass, radius 0.3, spin w = 10, turning at Ω = 2: a circle of radius rw/Ω while the
    // sideways force rwΩ is within μ_s g.
    let (r, w, turn) = (0.3, 10.0, 2.0);
    let wheel = Weighed(
        Mass::diagonal(vec![1.0, 1.0, 1.0, 0.25 * r * r, 0.5 * r * r]).unwrap(),
        5,
    );
    let ground = |mu: f64| {
        let friction = Friction {
            static_coefficient: mu,
            kinetic: mu / 2.0,
            slip: Slip::Field(std::sync::Arc::new(Rolling(r))),
        };
        let surface = Box::new(NativeSurface::Wall {
            coordinate: 1,
            value: 0.0,
        });
        let contact = Contact {
            surface,
            restitution: 0.0,
            law: Law::Reflect,
            friction: Some(friction),
            name: "ground".into(),
        };
        Contacts::new(vec![contact]).unwrap()
    };
    let (q0, p0) = ([0.0; 5], [r * w, 0.0, 0.0, 0.25 * r * r * turn, 0.5 * r * r * w]);
    let needs = r * w * turn / G;
    let radius = r * w / turn;
    for (method, order) in [(Method::Verlet, 2.0), (Method::Yoshida4, 4.0)] {
        let contacts = ground(needs * (1.0 + 1e-9));
        let errors: Vec<f64> = [0.02, 0.01]
            .iter()
            .map(|&dt| {
                let options = Options::new(dt, (2.0 / dt).round() as usize);
                let traj = integrate_watching(&wheel, method, &q0, &p0, &options, || Ok(()), with_contacts(&contacts))
                    .unwrap();
                assert!(traj.impacts.switches.is_empty() && traj.work.iter().all(|&x| x == 0.0));
                (0..traj.len())
                    .map(|k| {
                        let (q, phi) = (traj.q_at(k), turn * traj.t[k]);
                        let exact = [radius * phi.sin(), 0.0, radius * (1.0 - phi.cos()), phi, w * traj.t[k]];
                        q.iter().zip(exact).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let measured = (errors[0] / errors[1]).log2();
        assert!(
            (measured - order).abs() < 0.05,
            "{method:?}: order {measured} ({errors:?})"
        );
    }
    let contacts = ground(needs * (1.0 - 1e-9));
    let traj = integrate_watching(
        &wheel,
        Method::Verlet,
        &q0,
        &p0,
        &Options::new(0.01, 50),
        || Ok(()),
        with_contacts(&contacts),
    )
    .unwrap();
    assert!(traj.work[traj.len() - 1] < 0.0, "it skids: friction does work");
}

/// When the trapped particle (k, m, g) from (x₀, v₀) comes to rest on the floor x = −a with
/// restitution e: its first impact, then flights harmonic about the equilibrium, each from
/// the floor (at d = gm/k − a above it) at the speed v back to it after (2/ω)·atan(v/(ωd)),
/// v falling by e at each.
fn trapped_rest((k, m, g, a): (f64, f64, f64, f64), e: f64, (x0, v0): (f64, f64)) -> f64 {
    let (w, below) = ((k / m).sqrt(), g * m / k);
    let (y0, d) = (x0 + below, below - a);
    let amplitude = y0.hypot(v0 / w);
    let first = (v0.atan2(w * y0) + (d / amplitude).acos()) / w;
    let (mut t, mut v) = (first, e * w * (amplitude * amplitude - d * d).sqrt());
    while v > 1e-300 {
        t += 2.0 / w * (v / (w * d)).atan();
        v *= e;
    }
    t
}

#[test]
fn a_trapped_particle_pressed_on_a_floor_above_its_equilibrium_bounces_to_rest_there_held_at_every_step() {
    // Issue 64's cases (k, m, g, a, e, x₀, v₀, h) and a sweep of e and a. A closing leaves
    // the round-off of the normal velocity it takes away, ε|q̇⁻|; where positive, it released
    // the body, which crossed the floor again at once, and the run ended "a smaller step
    // helps", at every step.
    let mut cases = vec![
        (
            3.3575621915367484,
            1.6898067384630384,
            6.283483229136442,
            0.5889668115537644,
            0.5458215677524878,
            0.0,
            0.0,
            0.8356555558181492,
        ),
        (
            0.3653746425055403,
            0.8756114838428447,
            0.99999,
            1.3264414980520427,
            0.3413037757262099,
            1.7857279646163263e-190,
            1.8163818877974123,
            0.04871056203162395,
        ),
    ];
    for i in 0..6 {
        for j in 0..4 {
            let (e, a) = (0.1 + 0.15 * i as f64, 0.2 + 0.25 * j as f64);
            cases.push((2.0, 1.3, 9.81, a, e, 0.5, 0.7, 0.1));
        }
    }
    for (k, m, g, a, e, x0, v0, h) in cases {
        // A particle of mass m in the trap ½kx² under gravity g, V = ½kx² + gmx, its equilibrium
        // x = −gm/k below the floor x ≥ −a.
        let trap = Potential {
            dim: 1,
            mass: Mass::diagonal(vec![m]).unwrap(),
            potential: |q: &[f64]| 0.5 * k * q[0] * q[0] + g * m * q[0],
            gradient: |q: &[f64], grad: &mut [f64]| grad[0] = k * q[0] + g * m,
        };
        let contact = wall(0, -a, e, Law::Reflect, "floor");
        let contacts = Contacts::new(vec![contact]).unwrap();
        let t_rest = trapped_rest((k, m, g, a), e, (x0, v0));
        for (method, order) in [(Method::Verlet, 2), (Method::Yoshida4, 4)] {
            for div in [1, 2, 4, 16] {
                let dt = h / div as f64;
                // To a step past the rest.
                let options = Options::new(dt, ((t_rest + h) / dt).ceil() as usize);
                let traj = integrate_watching(
                    &trap,
                    method,
                    &[x0],
                    &[m * v0],
                    &options,
                    || Ok(()),
                    with_contacts(&contacts),
                )
                .unwrap_or_else(|f| panic!("{method:?}, e = {e}, a = {a}, h/{div}: {}", f.error));
                let switches = &traj.impacts.switches;
                let case = format!("{method:?}, e = {e}, a = {a}, h/{div}");
                assert_eq!(switches.kind, vec![Switch::Closed], "{case}: {:?}", switches.t);
                // At the Zeno limit, within the method's error over the run (hω ≤ 1.2 here) and
                // the rest of the series taken as parabolas' from the closing impact, O(h³).
                let error = (switches.t[0] - t_rest).abs();
                assert!(
                    error <= 0.5 * dt.powi(order.min(3)) * t_rest,
                    "{case}: closed {error} from {t_rest}"
                );
                // Resting from there: on the floor, at rest, pressed with λ = gm − ka.
                let last = traj.len() - 1;
                assert!(
                    (traj.q_at(last)[0] + a).abs() <= 4.0 * f64::EPSILON * a,
                    "{case}: {:?}",
                    traj.q_at(last)
                );
                assert!(traj.p_at(last)[0].abs() <= 1e-15 * m, "{case}: {:?}", traj.p_at(last));
                let lambda = multiplier(&trap, &traj, last, |_| vec![1.0]);
                assert!(
                    (lambda - (g * m - k * a)).abs() <= 1e-12 * g * m,
                    "{case}: λ = {lambda}"
                );
            }
        }
    }
}
