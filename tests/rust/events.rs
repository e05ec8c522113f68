//! Events: the Illinois and bracketed Newton root finders, and crossings of the harmonic oscillator located by the
//! method's partial step, at the method's order, with directions and terminal counts; a
//! billiard's ellipse located at the exact time.

use std::f64::consts::PI;

use varmech::integrators::{
    integrate, integrate_watching, Detector, Dynamics, EventSpec, Method, NativeEvent, Options, Trajectory, Watch,
};
use varmech::scenes::{EllipticBilliard, HarmonicOscillator};
use varmech::solve::bracket::{illinois, newton};

#[test]
fn illinois_finds_a_root_to_round_off_in_few_evaluations() {
    let mut calls = 0;
    let f = |x: f64| {
        calls += 1;
        Ok::<_, ()>(x.cos())
    };
    // cos falls through 0 at π/2 on [0, 2]: f(a) > 0 ≥ f(b) is a bracket too.
    let (x, fx) = illinois(f, (0.0, 1.0), (2.0, 2.0_f64.cos()), 0.0).unwrap();
    assert!((x - PI / 2.0).abs() <= 2.0 * f64::EPSILON, "{x}");
    assert!(fx.abs() <= 2e-16);
    assert!(calls <= 8, "{calls} evaluations");
    // A failing function's error comes back.
    let failing = illinois(|_| Err("model failed"), (0.0, -1.0), (1.0, 1.0), 0.0);
    assert_eq!(failing, Err("model failed"));
}

#[test]
fn newton_in_the_bracket_finds_a_root_to_round_off_in_fewer_evaluations() {
    // cos on [0, 2], a tolerance of 4 ulps of the bracket (as contacts locate): with the exact
    // derivative, quadratic convergence (Illinois takes 6 here); with one 0.1% off, as an
    // impact's ∇φ·q̇ is off the partial step's rate, nearly so; with one 30% off, linear at rate
    // 1 − 1/1.3 = 0.23; with a useless one (of the wrong sign), the bracket's bisection (2⁻⁵⁰);
    // each to round-off of π/2.
    let tolerance = 4.0 * f64::EPSILON * 2.0;
    for (scale, most) in [(1.0, 5), (1.001, 7), (1.3, 27), (-1.0, 52)] {
        let mut calls = 0;
        let f = |x: f64| {
            calls += 1;
            Ok::<_, ()>((x.cos(), -scale * x.sin()))
        };
        let (x, fx) = newton(f, (0.0, 1.0), (2.0, 2.0_f64.cos()), None, tolerance).unwrap();
        assert!((x - PI / 2.0).abs() <= tolerance, "{x}, derivative × {scale}");
        assert!(fx.abs() <= 1e-15, "{fx}");
        assert!(calls <= most, "{calls} evaluations, derivative × {scale}");
    }
    // A root at an end of the bracket, and tolerance 0 (4 ulps of the root).
    let (x, fx) = newton(|x: f64| Ok::<_, ()>((x - 1.0, 1.0)), (1.0, 0.0), (3.0, 2.0), None, 0.0).unwrap();
    assert_eq!((x, fx), (1.0, 0.0));
    // √2, from no guess; from a guess at the root (an interpolant's, as an impact's): that point
    // and the probe past it. A guess outside the bracket is not taken: the secant point's
    // evaluations.
    for (guess, most) in [
        (None, 7),
        (Some(2.0_f64.sqrt()), 2),
        (Some(-1.0), 7),
        (Some(f64::NAN), 7),
    ] {
        let mut calls = 0;
        let f = |x: f64| {
            calls += 1;
            Ok::<_, ()>((x * x - 2.0, 2.0 * x))
        };
        let (x, _) = newton(f, (0.0, -2.0), (2.0, 2.0), guess, 0.0).unwrap();
        assert!((x - 2.0_f64.sqrt()).abs() <= 4.0 * f64::EPSILON * 2.0, "{x}");
        assert!(calls <= most, "{calls} evaluations from {guess:?}");
    }
    // A failing function's error comes back.
    let failing = newton(|_| Err("model failed"), (0.0, -1.0), (1.0, 1.0), None, 0.0);
    assert_eq!(failing, Err("model failed"));
}

/// The detector of q₀ = 0 crossed in `direction`, terminal after `terminal` crossings (0: never).
fn crossing(direction: i8, terminal: usize) -> Detector<'static> {
    let crossing = vec![NativeEvent::Crossing {
        coordinate: 0,
        value: 0.0,
    }];
    let spec = EventSpec {
        name: "q0 = 0".into(),
        direction,
        terminal,
    };
    Detector::new(Box::new(crossing), vec![spec]).unwrap()
}

/// The run of `sys` watching the `detector`'s events.
fn watching<S: Dynamics>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    detector: &mut Detector<'_>,
) -> Trajectory {
    integrate_watching(sys, method, q0, p0, options, || Ok(()), Watch::events(detector)).unwrap()
}

/// The crossings of q = 0 of q = cos t (ω = 1 from q = 1, p = 0) with `method` at step h over
/// t ∈ [0, 20]: the largest error of the located times against (k + ½)π.
fn crossing_error(method: Method, h: f64, direction: i8) -> (usize, f64) {
    let sys = HarmonicOscillator::new(1.0).unwrap();
    let options = Options::new(h, (20.0 / h).round() as usize);
    let mut detector = crossing(direction, 0);
    let traj = watching(&sys, method, &[1.0], &[0.0], &options, &mut detector);
    let worst = traj.events.iter().fold(0.0_f64, |m, e| {
        // Downward crossings at (2j + ½)π, upward at (2j + 3/2)π.
        let exact = ((e.t / PI - 0.5).round() + 0.5) * PI;
        assert!(e.q[0].abs() <= 1e-15, "q = {} at the crossing", e.q[0]);
        m.max((e.t - exact).abs())
    });
    (traj.events.len(), worst)
}

#[test]
fn crossings_are_located_at_the_methods_order() {
    for (method, order, h) in [
        (Method::Verlet, 2, 0.1),
        (Method::Yoshida4, 4, 0.1),
        (Method::KahanLi6, 6, 0.2),
    ] {
        let (count, coarse) = crossing_error(method, h, 0);
        let (_, fine) = crossing_error(method, h / 2.0, 0);
        // q = cos t crosses 0 six times in [0, 20] (at π/2 … 11π/2).
        assert_eq!(count, 6, "{method:?}");
        let slope = (coarse / fine).log2();
        assert!((slope - order as f64).abs() <= 0.3, "{method:?}: slope {slope}");
    }
}

#[test]
fn directions_keep_their_crossings_and_a_count_terminal_stops_after_its_step() {
    // Downward at π/2, 5π/2, 9π/2; upward at 3π/2, 7π/2, 11π/2.
    assert_eq!(crossing_error(Method::Verlet, 0.01, -1).0, 3);
    assert_eq!(crossing_error(Method::Verlet, 0.01, 1).0, 3);

    let sys = HarmonicOscillator::new(1.0).unwrap();
    let options = Options::new(0.01, 2000);
    let mut detector = crossing(0, 3);
    let traj = watching(&sys, Method::Verlet, &[1.0], &[0.0], &options, &mut detector);
    assert_eq!(traj.events.len(), 3);
    assert_eq!(traj.terminated_by, Some(0));
    // The run stops at the end of the step of the third crossing (5π/2), a state of the grid
    // equal bit for bit to the same step of a run without events.
    let third = &traj.events[2];
    assert_eq!(traj.steps, third.step);
    assert_eq!(*traj.t.last().unwrap(), 0.01 * third.step as f64);
    assert!(traj.t[traj.len() - 2] < third.t && third.t <= *traj.t.last().unwrap());
    let plain = integrate(
        &sys,
        Method::Verlet,
        &[1.0],
        &[0.0],
        &Options::new(0.01, third.step),
        || Ok(()),
    )
    .unwrap();
    assert_eq!(plain.q, traj.q);
    assert_eq!(plain.p, traj.p);
}

#[test]
fn each_crossing_carries_the_state_at_the_start_of_its_step() {
    // The start of the partial step located, for the implicit midpoint rule too: the saved state
    // of the step before, bit for bit (every step saved).
    let sys = HarmonicOscillator::new(1.0).unwrap();
    for method in [Method::Verlet, Method::Midpoint] {
        let options = Options::new(0.1, 200);
        let mut detector = crossing(0, 0);
        let traj = watching(&sys, method, &[1.0], &[0.0], &options, &mut detector);
        assert_eq!(traj.events.len(), 6, "{method:?}");
        for e in &traj.events {
            let k = e.step - 1;
            assert_eq!(e.q_start, traj.q[k..k + 1], "{method:?} step {}", e.step);
            assert_eq!(e.p_start, traj.p[k..k + 1], "{method:?} step {}", e.step);
            assert!(traj.t[k] < e.t && e.t <= traj.t[k + 1]);
        }
    }
}

/// The free particle of the elliptic billiard x²/4 + y² ≤ 1 from (0.3, 0.1) with p = (0.6, 0.8)
/// reaches the wall at the root τ of |q₀ + τp|²_A = 1, a quadratic; Verlet is exact on the
/// straight line, so the native ellipsoid event locates it to round-off, and the same ellipse
/// moved to a centre and in other coordinates gives the same time.
#[test]
fn the_ellipsoid_event_finds_a_free_particle_at_the_wall_at_the_exact_time() {
    let sys = EllipticBilliard::new(2.0, 1.0).unwrap();
    let (q0, p0) = ([0.3, 0.1], [0.6, 0.8]);
    // (q₀ + τp)ᵀD(q₀ + τp) = 1, D = diag(1/4, 1): aτ² + bτ + c = 0, the positive root.
    let (a, b, c): (f64, f64, f64) = (
        0.09 + 0.64,
        2.0 * (0.3 * 0.6 / 4.0 + 0.1 * 0.8),
        0.09 / 4.0 + 0.01 - 1.0,
    );
    let exact = (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    let run = |wall: NativeEvent, q0: &[f64], p0: &[f64]| {
        wall.check("wall", q0.len()).unwrap();
        let spec = EventSpec {
            name: "wall".into(),
            direction: -1,
            terminal: 1,
        };
        let mut detector = Detector::new(Box::new(vec![wall]), vec![spec]).unwrap();
        let options = Options::new(0.01, 1000);
        let traj = watching(&sys, Method::Verlet, q0, p0, &options, &mut detector);
        assert_eq!((traj.events.len(), traj.terminated_by), (1, Some(0)));
        traj.events[0].clone()
    };
    let table = NativeEvent::Ellipsoid {
        coordinates: vec![0, 1],
        centre: vec![0.0, 0.0],
        semi_axes: vec![2.0, 1.0],
        inside: true,
    };
    let hit = run(table, &q0, &p0);
    assert!(
        (hit.t - exact).abs() <= 4.0 * f64::EPSILON * exact,
        "{} against {exact}",
        hit.t
    );
    assert!(sys.inside(&hit.q).abs() <= 4.0 * f64::EPSILON);
    // The ellipse about (1, −2) in the coordinates (1, 0), the particle moved with it.
    let moved = NativeEvent::Ellipsoid {
        coordinates: vec![1, 0],
        centre: vec![1.0, -2.0],
        semi_axes: vec![2.0, 1.0],
        inside: true,
    };
    let shifted = run(moved, &[q0[1] - 2.0, q0[0] + 1.0], &[p0[1], p0[0]]);
    assert!(
        (shifted.t - exact).abs() <= 16.0 * f64::EPSILON * exact,
        "{} against {exact}",
        shifted.t
    );
}

#[test]
fn the_ellipsoid_event_refuses_bad_shapes_by_name() {
    let shape = |coordinates: Vec<usize>, centre: Vec<f64>, semi_axes: Vec<f64>| NativeEvent::Ellipsoid {
        coordinates,
        centre,
        semi_axes,
        inside: false,
    };
    for (bad, says) in [
        (shape(vec![0, 2], vec![0.0, 0.0], vec![1.0, 1.0]), "coordinate 2"),
        (shape(vec![0, 1], vec![0.0], vec![1.0, 1.0]), "equal length"),
        (shape(vec![], vec![], vec![]), "non-empty"),
        (shape(vec![0, 1], vec![0.0, 0.0], vec![1.0, 0.0]), "semi-axis"),
        (shape(vec![0, 1], vec![f64::NAN, 0.0], vec![1.0, 1.0]), "centre"),
    ] {
        match bad.check("obstacle", 2) {
            Err(varmech::Error::InvalidArgument { argument, reason }) => {
                assert_eq!(argument, "events");
                assert!(reason.starts_with("obstacle: ") && reason.contains(says), "{reason}");
            }
            other => panic!("expected an invalid argument, got {other:?}"),
        }
    }
    // Outside an obstacle the sign is reversed: g = Σu² − 1.
    let sys = EllipticBilliard::new(2.0, 1.0).unwrap();
    let mut obstacle = shape(vec![0, 1], vec![0.0, 0.0], vec![2.0, 1.0]);
    assert_eq!(obstacle.value(&sys, 0.0, &[2.0, 1.0], &[0.0, 0.0]).unwrap(), 1.0);
}
