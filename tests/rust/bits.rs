//! The step loops' results, bit for bit: a fingerprint of every saved state and of the work
//! counts of short runs, one per method family and model kind, recorded before the step loops
//! were specialised (issue 15). Any change to the arithmetic of a step, its order included,
//! changes a fingerprint.

use varmech::integrators::{integrate, Dynamics, General, Method, Options, Trajectory};
use varmech::scenes::{planar_chain, DampedDrivenPendulum, DoublePendulum, Kepler};

/// FNV-1a over the bits of every saved (t, q, p), the Newton counts and work per saved state,
/// and the run's step, evaluation and iteration counts.
fn fingerprint(traj: &Trajectory) -> u64 {
    let (work, newton) = (traj.work_at_saves(), traj.newton_at_saves());
    let words = traj
        .t
        .iter()
        .chain(&traj.q)
        .chain(&traj.p)
        .chain(work.iter())
        .map(|x| x.to_bits())
        .chain(newton.iter().copied())
        .chain([traj.steps as u64, traj.force_evaluations, traj.newton_iterations]);
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    for word in words {
        for byte in word.to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

fn run<S: Dynamics + ?Sized>(sys: &S, method: Method, q0: &[f64], p0: &[f64], options: &Options) -> u64 {
    let traj = integrate(sys, method, q0, p0, options, || Ok(())).unwrap_or_else(|f| panic!("{method:?}: {}", f.error));
    fingerprint(&traj)
}

/// (case, fingerprint) of every run, for one comparison that names each mismatch.
fn check(actual: Vec<(String, u64)>, expected: &[(&str, u64)]) {
    let mismatches: Vec<_> = actual
        .iter()
        .zip(expected)
        .filter(|((_, a), (_, e))| a != e)
        .map(|((case, a), (_, e))| format!("{case}: {a:#018x}, recorded {e:#018x}"))
        .collect();
    let cases: Vec<_> = actual.iter().map(|(c, _)| c.as_str()).collect();
    let recorded: Vec<_> = expected.iter().map(|(c, _)| *c).collect();
    assert_eq!(cases, recorded);
    assert!(mismatches.is_empty(), "changed bits:\n{}", mismatches.join("\n"));
}

#[test]
fn every_method_on_kepler_keeps_its_bits() {
    let p = Kepler::problem(0.6).unwrap();
    let (q0, p0) = (&p.initial.q, &p.initial.p);
    let options = Options {
        save_every: 37,
        max_energy_error: None,
        ..Options::new(2.0 * std::f64::consts::PI / 100.0, 500)
    };
    let plain = Options {
        compensated: false,
        ..options.clone()
    };
    // Today's methods, named: methods added later fingerprint themselves elsewhere.
    let methods = [
        "explicit_euler",
        "symplectic_euler",
        "verlet",
        "yoshida4",
        "suzuki4",
        "mclachlan4",
        "yoshida6",
        "kahan_li6",
        "suzuki_umeno8",
        "kahan_li8",
        "rk4",
        "midpoint",
        "trapezoid",
        "galerkin4",
        "galerkin6",
    ];
    let mut actual: Vec<_> = methods
        .into_iter()
        .map(|name| Method::from_name(name).unwrap())
        .map(|m| (m.info().name.to_string(), run(&p.system, m, q0, p0, &options)))
        .collect();
    for m in [Method::Verlet, Method::KahanLi8, Method::Midpoint] {
        actual.push((format!("{} plain", m.info().name), run(&p.system, m, q0, p0, &plain)));
    }
    check(actual, KEPLER);
}

#[test]
fn the_implicit_and_constrained_methods_keep_their_bits() {
    let options = |dt, steps| Options {
        save_every: 17,
        ..Options::new(dt, steps)
    };
    let mut actual = Vec::new();
    let dp = DoublePendulum::problem();
    for m in crate::common::IMPLICIT {
        let f = run(
            &General(&dp.system),
            m,
            &dp.initial.q,
            &dp.initial.p,
            &options(0.01, 300),
        );
        actual.push((format!("double pendulum {}", m.info().name), f));
    }
    let forced = DampedDrivenPendulum::problem(0.5, 1.5, 2.0 / 3.0).unwrap();
    let f = run(
        &General(&forced.system),
        Method::Midpoint,
        &forced.initial.q,
        &forced.initial.p,
        &options(0.05, 300),
    );
    actual.push(("damped driven pendulum midpoint".into(), f));
    let chain = planar_chain(2).unwrap();
    for m in Method::CONSTRAINED {
        let f = run(
            &chain.system,
            m,
            &chain.initial.q,
            &chain.initial.p,
            &options(0.01, 300),
        );
        actual.push((format!("planar chain {}", m.info().name), f));
    }
    crate::common::with_rigid_body(|sys, s| {
        for m in [Method::Midpoint, Method::Trapezoid] {
            let f = run(sys, m, &s.q, &s.p, &options(0.01, 300));
            actual.push((format!("rigid body {}", m.info().name), f));
        }
    });
    check(actual, IMPLICIT);
}

const KEPLER: &[(&str, u64)] = &[
    ("explicit_euler", 0xcb46c19b834aaaf1),
    ("symplectic_euler", 0x1a3d4b634570fba7),
    ("verlet", 0x2851361787ddba3b),
    ("yoshida4", 0x9e72c6a8e5129d23),
    ("suzuki4", 0x05bae11cbcd9f68b),
    ("mclachlan4", 0xc3e602f0e2d230bb),
    ("yoshida6", 0xd3f7528550e7b5bd),
    ("kahan_li6", 0xc16802457b5756cf),
    ("suzuki_umeno8", 0xa4004acce03d6531),
    ("kahan_li8", 0x99987c0d100b7f66),
    ("rk4", 0xd89e3f15f201b20f),
    ("midpoint", 0xe2ff2725e4d8bc48),
    ("trapezoid", 0x854981b8b6aa7b79),
    ("galerkin4", 0x822b619b689bca77),
    ("galerkin6", 0x532f5ab23b515140),
    ("verlet plain", 0xa23bb8ddd3c1ee73),
    ("kahan_li8 plain", 0x8457c30cfbc237f5),
    ("midpoint plain", 0xb68c9607c912711f),
];
const IMPLICIT: &[(&str, u64)] = &[
    ("double pendulum midpoint", 0xcf52ca6383de90fb),
    ("double pendulum trapezoid", 0xf018fad1ba1ed67d),
    ("double pendulum galerkin4", 0x1ad3a7e42167e45c),
    ("double pendulum galerkin6", 0x1eec7480aa8b498e),
    ("damped driven pendulum midpoint", 0x4fa80d95fb163757),
    ("planar chain rattle", 0x6f3391556c980c2e),
    ("planar chain rattle4", 0x02b0255961d09d59),
    ("planar chain shake", 0x79b457cc82171f1f),
    ("rigid body midpoint", 0xedc10a92a2d4d250),
    ("rigid body trapezoid", 0x71deaafb24640780),
];

#[path = "../../benches/reference/mod.rs"]
mod reference;

/// The benches' hand-written Verlet loop does varmech's arithmetic: its final state is
/// `integrate`'s, bit for bit, so that timing one against the other measures overhead alone.
#[test]
fn the_reference_verlet_loop_is_varmechs_to_the_bit() {
    let p = Kepler::problem(0.6).unwrap();
    let (h, steps) = (2.0 * std::f64::consts::PI / 200.0, 2000);
    let options = Options {
        save_every: steps,
        ..Options::new(h, steps)
    };
    let traj = integrate(&p.system, Method::Verlet, &p.initial.q, &p.initial.p, &options, || {
        Ok(())
    })
    .unwrap();
    let q0 = [p.initial.q[0], p.initial.q[1]];
    let p0 = [p.initial.p[0], p.initial.p[1]];
    let (q, pp) = reference::kepler_verlet(q0, p0, h, steps);
    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&q), bits(traj.q_at(1)));
    assert_eq!(bits(&pp), bits(traj.p_at(1)));
}

/// The benches' hand-written midpoint loop solves the same equations by the same Newton rule:
/// the same iterations to within a few over 1 000 steps (3 744 both, measured), and the same
/// state to 1e-10 (its 2×2 LU rounds differently from the general one, and the chaotic double
/// pendulum amplifies those last bits to about 5e-12 by t = 10).
#[test]
fn the_reference_midpoint_loop_takes_varmechs_newton_steps() {
    let dp = DoublePendulum::problem();
    let (h, steps) = (0.01, 1000);
    let options = Options {
        save_every: steps,
        ..Options::new(h, steps)
    };
    let traj = crate::common::run_general_with(&dp.system, &dp.initial, Method::Midpoint, &options).unwrap();
    let (q0, p0) = ([dp.initial.q[0], dp.initial.q[1]], [dp.initial.p[0], dp.initial.p[1]]);
    let (q, p, iterations) = reference::midpoint(&dp.system, q0, p0, h, steps);
    println!(
        "Newton iterations: varmech {}, reference {iterations}",
        traj.newton_iterations
    );
    assert!(traj.newton_iterations.abs_diff(iterations) <= 5);
    let gap = q
        .iter()
        .chain(&p)
        .zip(traj.q_at(1).iter().chain(traj.p_at(1)))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-10, "{gap:e}");
}
