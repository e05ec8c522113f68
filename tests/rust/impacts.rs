//! Impacts on unilateral contacts φ(q) ≥ 0, resolved in the core's step loop: the bouncing ball
//! (a native wall) and the circular billiard (a native ellipsoid) against their exact motion,
//! an accumulation of impacts ending the run with `Error::Contact`, and the bits: a step
//! without an impact, a resumed run and an ensemble member are those of the plain run.

use varmech::integrators::{integrate_watching, Contact, Contacts, Law, Method, NativeSurface, Options, Watch};
use varmech::model::Lagrangian;
use varmech::scenes::BouncingBall;
use varmech::Error;

const G: f64 = 9.81;

fn floor(restitution: f64, law: Law) -> Contacts<'static> {
    let contact = Contact {
        surface: Box::new(NativeSurface::Wall {
            coordinate: 0,
            value: 0.0,
        }),
        restitution,
        law,
        name: "floor".into(),
    };
    Contacts::new(vec![contact]).unwrap()
}

fn with_contacts<'w>(contacts: &'w Contacts<'static>) -> Watch<'w, 'static, 'static> {
    Watch {
        events: None,
        contacts: Some(contacts),
    }
}

#[test]
fn the_ball_first_hits_the_floor_at_the_exact_time_and_keeps_its_energy() {
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(1.0, Law::Reflect);
    let (h0, dt) = (1.0, 1e-3);
    let period = 2.0 * (2.0 * h0 / G).sqrt();
    let options = Options::new(dt, (20.0 * period / dt) as usize);
    let traj = integrate_watching(
        &ball,
        Method::Verlet,
        &[h0],
        &[0.0],
        &options,
        || Ok(()),
        with_contacts(&contacts),
    )
    .unwrap();
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

#[test]
fn an_accumulation_of_impacts_ends_the_run_with_a_contact_error_at_the_steps_start() {
    // e = 0.5: the ball comes to rest at t = (1 + 2e/(1 − e))√(2h₀/g) ≈ 1.35.
    let ball = BouncingBall::new(G).unwrap();
    let contacts = floor(0.5, Law::Reflect);
    let options = Options::new(0.01, 200);
    let failure = integrate_watching(
        &ball,
        Method::Verlet,
        &[1.0],
        &[0.0],
        &options,
        || Ok(()),
        with_contacts(&contacts),
    )
    .unwrap_err();
    let Error::Contact { step, time, .. } = failure.error else {
        panic!("{}", failure.error)
    };
    assert_eq!((step, (time * 100.0).round() / 100.0), (136, 1.35), "{}", failure.error);
    let partial = &failure.partial;
    assert_eq!(partial.impacts.len(), 8);
    assert_eq!(partial.steps, 135);
    assert_eq!(*partial.t.last().unwrap(), time);
}
