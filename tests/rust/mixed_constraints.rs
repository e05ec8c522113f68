//! Holonomic and velocity constraints together ([`Mixed`]): a knife edge (a skate) on an
//! inclined plane, its heading written redundantly as a unit vector (c, s) held to the circle
//! c² + s² = 1, q = (x, y, c, s): L = ½(ẋ² + ẏ²) + ½J(ċ² + ṡ²) + a x (a = g sin α, x down the
//! slope), g(q) = ½(c² + s² − 1), and no sideways slip, s ẋ − c ẏ = 0. Turned at ω from rest
//! at the origin heading down the slope, it moves on Neimark & Fufaev's closed form (Bloch,
//! *Nonholonomic Mechanics and Control*, §1.6): φ = ωt,
//! x = (a/2ω²) sin²ωt,   y = (a/2ω²)(ωt − ½ sin 2ωt).

use crate::common;
use crate::common::skate::{skate, Heading, Holding, KnifeEdge, Pushed, INERTIA, OMEGA, SLOPE};

use varmech::integrators::{integrate, Dynamics, Method, Options, Trajectory};
use varmech::model::{Lagrangian, Mixed, Nonholonomic};

/// The closed form (x, y, cos ωt, sin ωt) at t.
fn exact(t: f64) -> [f64; 4] {
    let (s, c) = (OMEGA * t).sin_cos();
    let k = SLOPE / (2.0 * OMEGA * OMEGA);
    [k * s * s, k * (OMEGA * t - s * c), c, s]
}

fn run<D: Dynamics>(
    model: &D,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    h: f64,
    steps: usize,
    every: usize,
) -> Trajectory {
    let options = Options {
        save_every: every,
        ..Options::new(h, steps)
    };
    integrate(model, method, q0, p0, &options, || Ok(())).unwrap_or_else(|f| panic!("{}", f.error))
}

/// The largest distance of the final positions from the closed form at T = `steps`·h.
fn error_at_end(method: Method, h: f64, steps: usize) -> f64 {
    let (model, q0, p0) = skate();
    let traj = run(&model, method, &q0, &p0, h, steps, steps);
    let q = traj.q_at(traj.len() - 1);
    let x = exact(h * steps as f64);
    q.iter().zip(&x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
}

#[test]
fn the_skate_holds_both_constraints_to_round_off_and_its_energy_without_drift() {
    // 10⁵ steps of h = 0.05 (T = 5000, 1000 turns): |g(q)| and |[G; A]q̇| at round-off at
    // every saved state, and the energy error bounded (the reversible step on a reversible
    // system): as large over the run's last tenth as over its first.
    let (model, q0, p0) = skate();
    let traj = run(&model, Method::Midpoint, &q0, &p0, 0.05, 100_000, 10);
    let (mut position, mut velocity) = (0.0_f64, 0.0_f64);
    let mut energy = Vec::with_capacity(traj.len());
    for k in 0..traj.len() {
        let r = model.constraint_residuals(traj.q_at(k), traj.p_at(k)).unwrap().unwrap();
        position = position.max(r.position);
        velocity = velocity.max(r.velocity / r.velocity_size);
        energy.push(Lagrangian::energy(&model.system, traj.q_at(k), traj.p_at(k), 0.0).unwrap());
    }
    let tenth = energy.len() / 10;
    let spread = |e: &[f64]| e.iter().fold(0.0_f64, |a, x| a.max((x - energy[0]).abs()));
    let (first, last) = (spread(&energy[..tenth]), spread(&energy[energy.len() - tenth..]));
    println!("skate: |g| ≤ {position:.1e}, |[G; A]q̇| ≤ {velocity:.1e} of its size, |ΔE| ≤ {first:.2e} first tenth, {last:.2e} last");
    assert!(position <= 1e-14, "{position:e}");
    assert!(velocity <= 1e-13, "{velocity:e}");
    assert!(first <= 2e-3 && first > 0.0, "{first:e}");
    assert!(last <= 1.5 * first, "the energy drifts: {first:e} then {last:e}");
}

#[test]
fn the_skate_follows_the_closed_form_to_order_2_and_composed_to_order_4() {
    let errors = |method, h0: f64| -> Vec<f64> {
        (0..3)
            .map(|k| {
                let h = h0 / 2f64.powi(k);
                error_at_end(method, h, (4.0 / h).round() as usize)
            })
            .collect()
    };
    common::assert_order("skate, midpoint", &errors(Method::Midpoint, 0.1), 2.0, 0.1);
    common::assert_order("skate, dla4", &errors(Method::Dla4, 0.2), 4.0, 0.25);
}

#[test]
fn cortes_martinez_takes_the_mixed_constraints_too() {
    // Its discrete constraint at the step's start: of order 1, on both constraints.
    let (model, q0, p0) = skate();
    let traj = run(&model, Method::CortesMartinez, &q0, &p0, 0.01, 400, 400);
    let r = model.constraint_residuals(traj.q_at(1), traj.p_at(1)).unwrap().unwrap();
    assert!(
        r.position <= 1e-14 && r.velocity <= 1e-14 * r.velocity_size.max(1.0),
        "{r:?}"
    );
    let errors: Vec<f64> = [0.02, 0.01, 0.005]
        .iter()
        .map(|&h| error_at_end(Method::CortesMartinez, h, (4.0 / h).round() as usize))
        .collect();
    common::assert_order("skate, cortes_martinez", &errors, 1.0, 0.15);
}

#[test]
fn a_height_held_at_zero_changes_nothing_in_the_plane() {
    // The skate with its heading an angle, q = (x, y, φ), against the same skate with a height
    // z pulled down by gravity and held at z = 0, q = (x, y, φ, z): the same discrete
    // Lagrange–d'Alembert steps, so the same states to round-off.
    let (h, steps) = (0.05, 2_000);
    let plane = Nonholonomic {
        system: Pushed::new(vec![1.0, 1.0, INERTIA], vec![SLOPE, 0.0, 0.0]),
        constraints: KnifeEdge(Heading::Angle(2)),
    };
    let lifted = Mixed {
        system: Pushed::new(vec![1.0, 1.0, INERTIA, 2.0], vec![SLOPE, 0.0, 0.0, -9.81 * 2.0]),
        holonomic: Holding::Plane(3),
        velocity: KnifeEdge(Heading::Angle(2)),
    };
    let p0 = [0.0, 0.0, INERTIA * OMEGA];
    let a = run(&plane, Method::Midpoint, &[0.0; 3], &p0, h, steps, 1);
    let b = run(
        &lifted,
        Method::Midpoint,
        &[0.0; 4],
        &[0.0, 0.0, INERTIA * OMEGA, 0.0],
        h,
        steps,
        1,
    );
    let (mut gap, mut height) = (0.0_f64, 0.0_f64);
    for k in 0..a.len() {
        let (qa, qb, pa, pb) = (a.q_at(k), b.q_at(k), a.p_at(k), b.p_at(k));
        let scale = qa.iter().chain(pa).fold(1.0_f64, |m, x| m.max(x.abs()));
        let d = (0..3)
            .map(|i| (qa[i] - qb[i]).abs().max((pa[i] - pb[i]).abs()))
            .fold(0.0, f64::max);
        gap = gap.max(d / scale);
        height = height.max(qb[3].abs()).max(pb[3].abs());
    }
    println!("eliminated against held: relative gap {gap:.1e}, |z|, |p_z| ≤ {height:.1e}");
    assert!(gap <= 1e-13, "{gap:e}");
    assert!(height <= 1e-15, "{height:e}");
}

#[test]
fn initial_states_off_either_constraint_are_refused_by_name() {
    let (model, q0, p0) = skate();
    let off = |q: &[f64], p: &[f64]| match run_result(&model, q, p) {
        Err(varmech::Error::InvalidArgument { argument, .. }) => argument,
        other => panic!("not refused by name: {other:?}"),
    };
    assert_eq!(off(&[0.0, 0.0, 1.1, 0.0], &p0), "q0");
    assert_eq!(off(&q0, &[0.0, 0.3, 0.0, INERTIA * OMEGA]), "p0");
    assert_eq!(off(&q0, &[0.0, 0.0, 0.2, INERTIA * OMEGA]), "p0");
    // The projection puts them back, on both.
    let (q, p) = Dynamics::project(&model, &[0.1, 0.2, 1.1, 0.1], &[0.4, 0.3, 0.2, 0.6])
        .unwrap()
        .unwrap();
    let r = model.constraint_residuals(&q, &p).unwrap().unwrap();
    assert!(r.position <= 1e-15 && r.velocity <= 1e-15, "{r:?}");
    assert!(run_result(&model, &q, &p).is_ok());
}

fn run_result<D: Dynamics>(model: &D, q0: &[f64], p0: &[f64]) -> Result<Trajectory, varmech::Error> {
    integrate(model, Method::Midpoint, q0, p0, &Options::new(0.05, 10), || Ok(())).map_err(|f| f.error)
}
