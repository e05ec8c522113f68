//! Kepler's problem in polar coordinates (r, θ), a general Lagrangian with θ cyclic, over HLW's
//! 200 periods (e = 0.6): its exact reference, its conserved angular momentum, and the
//! Cartesian scene it is in other coordinates.

use crate::common;

use common::InvariantStatistics;
use std::f64::consts::PI;

use varmech::integrators::{Method, NewtonOptions, Options, Trajectory};
use varmech::model::Lagrangian;
use varmech::scenes::{Kepler, KeplerPolar, State};

const E: f64 = 0.6;

fn run_polar(method: Method, steps_per_period: usize, save_every: usize) -> Trajectory {
    run_polar_with(method, 200, steps_per_period, save_every, NewtonOptions::default())
}

fn run_polar_with(
    method: Method,
    periods: usize,
    steps_per_period: usize,
    save_every: usize,
    newton: NewtonOptions,
) -> Trajectory {
    let problem = KeplerPolar::problem(E).unwrap();
    let steps = periods * steps_per_period;
    let options = Options {
        save_every,
        newton,
        ..Options::new(2.0 * PI / steps_per_period as f64, steps)
    };
    common::run_general_with(&problem.system, &problem.initial, method, &options)
        .unwrap_or_else(|e| panic!("{method:?}: {e}"))
}

/// (x, y, p_x, p_y) of a polar state (m = 1): p_x = p_r cos θ − (p_θ/r) sin θ, and so on.
fn cartesian(q: &[f64], p: &[f64]) -> [f64; 4] {
    let (r, (s, c)) = (q[0], q[1].sin_cos());
    [r * c, r * s, p[0] * c - p[1] / r * s, p[0] * s + p[1] / r * c]
}

#[test]
fn the_derivatives_hessians_and_velocity_are_exact() {
    let sys = KeplerPolar::new(1.7, 0.9).unwrap();
    let (q, v) = ([0.8, 2.3], [-0.4, 1.1]);
    common::assert_hessians(&sys, &q, &v, 1e-7);
    // dl_dq and dl_dv are the derivatives of L.
    let (mut lq, mut lv) = ([0.0; 2], [0.0; 2]);
    sys.dl_dq(&q, &v, 0.0, &mut lq).unwrap();
    sys.dl_dv(&q, &v, 0.0, &mut lv).unwrap();
    let e = 1e-6;
    for i in 0..2 {
        let d = |dq: f64, dv: f64| {
            let (mut qp, mut vp) = (q, v);
            qp[i] += dq;
            vp[i] += dv;
            sys.lagrangian(&qp, &vp, 0.0).unwrap()
        };
        assert!((lq[i] - (d(e, 0.0) - d(-e, 0.0)) / (2.0 * e)).abs() < 1e-8);
        assert!((lv[i] - (d(0.0, e) - d(0.0, -e)) / (2.0 * e)).abs() < 1e-8);
    }
    let mut back = [0.0; 2];
    sys.velocity(&q, &lv, 0.0, &mut back).unwrap();
    assert!(
        back.iter().zip(&v).all(|(a, b)| (a - b).abs() <= 2e-16 * b.abs()),
        "{back:?}"
    );
    assert!(KeplerPolar::new(0.0, 1.0).is_err() && KeplerPolar::new(1.0, f64::NAN).is_err());
    assert!(KeplerPolar::problem(1.0).is_err());
}

#[test]
fn the_initial_state_is_the_cartesian_one_with_energy_minus_one_half() {
    let polar = KeplerPolar::problem(E).unwrap();
    let cart = Kepler::problem(E).unwrap();
    let x = cartesian(&polar.initial.q, &polar.initial.p);
    let y = [cart.initial.q.clone(), cart.initial.p.clone()].concat();
    assert!(x.iter().zip(&y).all(|(a, b)| (a - b).abs() <= 1e-15), "{x:?} vs {y:?}");
    let energy = polar.system.energy(&polar.initial.q, &polar.initial.p, 0.0).unwrap();
    assert!((energy + 0.5).abs() < 1e-15, "{energy}");
}

#[test]
fn midpoint_and_galerkin4_converge_at_their_orders_to_the_exact_reference() {
    let problem = KeplerPolar::problem(E).unwrap();
    let (reference, _) = problem.reference.as_ref().unwrap();
    for (method, n0, order) in [(Method::Midpoint, 1000, 2.0), (Method::Galerkin4, 200, 4.0)] {
        let errors: Vec<f64> = (0..4)
            .map(|k| {
                let n = n0 << k;
                common::final_error(&run_polar(method, n, 200 * n), &reference.q, &reference.p)
            })
            .collect();
        common::assert_order(
            &format!("{method:?}, {n0} to {} steps a period", n0 << 3),
            &errors,
            order,
            0.2,
        );
    }
}

/// The midpoint rule's θ equation says p_θ,k = mr²θ̇ at the midpoint = p_θ,k+1: p_θ changes only
/// by what Newton's iteration leaves unsolved. Its stopping test is relative to the step's
/// increment, not to θ, which grows to 400π here; measured relative errors of p_θ
/// (h = 2π/200, 200 periods): 3.3e-14 (midpoint) and 8.5e-14 (Galerkin-4) at the default
/// tolerance, 2.4e-14 and 6.6e-14 at 1e-16, and 4.4e-15, 2.4e-15 over the first period. (With
/// the test scaled by 1 + ‖q‖∞, as before, they were 3.3e-11 and 2.6e-10.)
#[test]
fn the_angular_momentum_is_conserved_to_round_off_as_the_angle_grows() {
    let problem = KeplerPolar::problem(E).unwrap();
    let cyclic = problem.system.symmetries()[0];
    let to_round_off = NewtonOptions {
        tolerance: 1e-16,
        ..NewtonOptions::default()
    };
    for method in [Method::Midpoint, Method::Galerkin4] {
        for (periods, newton, bound) in [
            (200, NewtonOptions::default(), 2e-13),
            (200, to_round_off, 2e-13),
            (1, NewtonOptions::default(), 1e-14),
        ] {
            let traj = run_polar_with(method, periods, 200, 10, newton);
            let l: Vec<f64> = common::along(&traj, |q, p| cyclic.momentum(q, p));
            let stats = InvariantStatistics::new(&l);
            let e: Vec<f64> = common::along(&traj, |q, p| problem.system.energy(q, p, 0.0).unwrap());
            let e_err = e.iter().fold(0.0_f64, |m, x| m.max((x - e[0]).abs() / 0.5));
            println!(
                "{method:?}, {periods} periods of 200 steps, Newton tolerance {:e}: p_θ = {}, max relative error {:.2e}; \
                 max |ΔE/E| = {e_err:.2e}",
                newton.tolerance, stats.initial, stats.max_rel_error
            );
            assert!((stats.initial - 0.8).abs() < 1e-15);
            assert!(stats.max_rel_error <= bound, "{method:?}, {periods} periods: {stats:?}");
        }
    }
}

/// Both runs approximate one orbit, each to its method's error: the gap between the polar run
/// (converted to Cartesian coordinates) and the Cartesian scene's run with the same method and
/// step, over 20 periods saved once a period, falls at the method's order.
#[test]
fn the_polar_run_follows_the_cartesian_scene_to_the_method_error() {
    let cart = Kepler::problem(E).unwrap();
    let periods = 20;
    for (method, n0, order) in [(Method::Midpoint, 1000, 2.0), (Method::Galerkin4, 100, 4.0)] {
        let mut gaps = Vec::new();
        for k in 0..3 {
            let n = n0 << k;
            // Saved once a period, where the exact state is the initial one.
            let polar = run_polar_with(method, periods, n, n, NewtonOptions::default());
            let t = periods as f64 * 2.0 * PI;
            let cartesian_run = common::run(&cart, method, t, periods * n, n);
            assert_eq!(polar.len(), cartesian_run.len());
            let exact: Vec<f64> = [cart.initial.q.clone(), cart.initial.p.clone()].concat();
            let (mut gap, mut polar_error, mut cartesian_error) = (0.0_f64, 0.0_f64, 0.0_f64);
            for i in 0..polar.len() {
                let x = cartesian(polar.q_at(i), polar.p_at(i));
                let y = [cartesian_run.q_at(i), cartesian_run.p_at(i)].concat();
                let dist = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
                gap = gap.max(dist(&x, &y));
                polar_error = polar_error.max(dist(&x, &exact));
                cartesian_error = cartesian_error.max(dist(&y, &exact));
            }
            println!(
                "{method:?}, {n} steps a period: max over {periods} periods of |polar − Cartesian| = {gap:.2e}; \
                 errors against the exact orbit: polar {polar_error:.2e}, Cartesian {cartesian_error:.2e}"
            );
            gaps.push(gap);
        }
        common::assert_order(&format!("{method:?}: polar − Cartesian gap"), &gaps, order, 0.3);
    }
}

#[test]
fn the_scene_states_match_state_conventions() {
    // The reference is the exact state after 200 periods: θ is not reduced modulo 2π.
    let problem = KeplerPolar::problem(0.0).unwrap();
    let (reference, source) = problem.reference.unwrap();
    assert_eq!(
        reference,
        State {
            t: 400.0 * std::f64::consts::PI,
            q: vec![1.0, 400.0 * std::f64::consts::PI],
            p: vec![0.0, 1.0],
        }
    );
    assert!(source.starts_with("exact"));
}
