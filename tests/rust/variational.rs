//! The explicit methods are the variational integrators they claim to be, and they are
//! symplectic where they say so.

use varmech::diagnostics::symplecticity_defect;
use varmech::discrete::{increment, DiscreteLagrangian, Midpoint, Rectangle, Segment, Trapezoidal, Workspace};
use varmech::integrators::{integrate, Composition, Method, Options};
use varmech::model::{Lagrangian, MechanicalSystem};
use varmech::scenes::{DoublePendulum, FermiPastaUlam, HenonHeiles, Kepler, NBody};
use varmech::solve::difference::central_gradient;

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// One step of `method` from (q0, p0) satisfies p₀ = −D₁L_d(q₀, q₁) and p₁ = D₂L_d(q₀, q₁).
fn check_legendre<S: MechanicalSystem, D: DiscreteLagrangian>(
    sys: &S,
    method: Method,
    ld: D,
    q0: &[f64],
    p0: &[f64],
    h: f64,
) {
    let options = Options {
        compensated: false,
        ..Options::new(h, 1)
    };
    let traj = integrate(sys, method, q0, p0, &options, || Ok(())).unwrap();
    let (q1, p1) = (traj.q_at(1).to_vec(), traj.p_at(1).to_vec());
    let minus = ld.momentum_minus(sys, q0, &q1, 0.0, h).unwrap();
    let plus = ld.momentum_plus(sys, q0, &q1, 0.0, h).unwrap();
    let scale = p0.iter().chain(&p1).fold(1.0_f64, |m, x| m.max(x.abs()));
    assert!(
        max_diff(&minus, p0) < 1e-14 * scale,
        "{method:?}: p0 = -D1 Ld fails: {minus:?} vs {p0:?}"
    );
    assert!(
        max_diff(&plus, &p1) < 1e-14 * scale,
        "{method:?}: p1 = D2 Ld fails: {plus:?} vs {p1:?}"
    );
}

#[test]
fn verlet_is_the_variational_integrator_of_the_trapezoidal_rule() {
    let kepler = Kepler::problem(0.6).unwrap();
    check_legendre(
        &kepler.system,
        Method::Verlet,
        Trapezoidal,
        &kepler.initial.q,
        &kepler.initial.p,
        0.05,
    );
    let sun = NBody::outer_solar_system();
    check_legendre(
        &sun.system,
        Method::Verlet,
        Trapezoidal,
        &sun.initial.q,
        &sun.initial.p,
        100.0,
    );
}

#[test]
fn symplectic_euler_is_the_variational_integrator_of_the_rectangle_rule() {
    let hh = HenonHeiles::problem();
    check_legendre(
        &hh.system,
        Method::SymplecticEuler,
        Rectangle,
        &hh.initial.q,
        &hh.initial.p,
        0.1,
    );
}

/// Checks p₀ = −D₁L_d, p₁ = D₂L_d and p₁ − p₀ = D₁L_d + D₂L_d of `ld` against central
/// differences of L_d itself, on a non-separable Lagrangian (the double pendulum) and a
/// separable one (Hénon–Heiles).
fn check_slot_derivatives<D: DiscreteLagrangian, S: Lagrangian>(ld: &D, sys: &S, q0: [f64; 2], q1: [f64; 2], h: f64) {
    let value = |a: &[f64], b: &[f64]| {
        let at = Segment {
            q0: a,
            dq: &increment(a, b),
            t: 0.3,
            h,
        };
        ld.value(sys, at).unwrap()
    };
    let d = |slot: usize, i: usize| {
        let e = 1e-6;
        let (mut a, mut b) = ((q0.to_vec(), q1.to_vec()), (q0.to_vec(), q1.to_vec()));
        let (x, y) = if slot == 0 {
            (&mut a.0, &mut b.0)
        } else {
            (&mut a.1, &mut b.1)
        };
        x[i] += e;
        y[i] -= e;
        (value(&a.0, &a.1) - value(&b.0, &b.1)) / (2.0 * e)
    };
    let minus = ld.momentum_minus(sys, &q0, &q1, 0.3, h).unwrap();
    let plus = ld.momentum_plus(sys, &q0, &q1, 0.3, h).unwrap();
    let mut change = [0.0; 2];
    let at = Segment {
        q0: &q0,
        dq: &increment(&q0, &q1),
        t: 0.3,
        h,
    };
    ld.momentum_change(sys, at, &mut change, &mut Workspace::new(2))
        .unwrap();
    for i in 0..2 {
        let scale = minus[i].abs().max(1.0);
        assert!(
            (d(0, i) + minus[i]).abs() < 1e-7 * scale,
            "D1[{i}]: {} vs {}",
            d(0, i),
            -minus[i]
        );
        assert!(
            (d(1, i) - plus[i]).abs() < 1e-7 * scale,
            "D2[{i}]: {} vs {}",
            d(1, i),
            plus[i]
        );
        assert!(
            (change[i] - (plus[i] - minus[i])).abs() < 1e-12 * scale,
            "D1 + D2 [{i}]"
        );
    }
}

#[test]
fn discrete_legendre_transforms_are_the_slot_derivatives_of_the_discrete_lagrangian() {
    let hh = HenonHeiles::problem().system;
    let dp = DoublePendulum::problem().system;
    let (q0, q1, h) = ([0.1, -0.2], [0.15, -0.1], 0.1);
    check_slot_derivatives(&Trapezoidal, &hh, q0, q1, h);
    check_slot_derivatives(&Rectangle, &hh, q0, q1, h);
    check_slot_derivatives(&Midpoint, &hh, q0, q1, h);
    check_slot_derivatives(&Trapezoidal, &dp, q0, q1, h);
    check_slot_derivatives(&Rectangle, &dp, q0, q1, h);
    check_slot_derivatives(&Midpoint, &dp, q0, q1, h);
}

#[test]
fn compositions_are_symmetric_and_consistent() {
    for method in Method::ALL {
        let Some(c) = Composition::of(method) else { continue };
        let g = c.gamma();
        assert_eq!(g.len(), method.info().stages);
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-15, "{method:?}: Σγ ≠ 1");
        assert!(
            g.iter().zip(g.iter().rev()).all(|(a, b)| a == b),
            "{method:?}: not symmetric"
        );
        if method.info().order >= 4 {
            assert!(
                g.iter().map(|x| x.powi(3)).sum::<f64>().abs() < 1e-14,
                "{method:?}: Σγ³ ≠ 0"
            );
        }
        if method.info().order >= 6 {
            assert!(
                g.iter().map(|x| x.powi(5)).sum::<f64>().abs() < 1e-14,
                "{method:?}: Σγ⁵ ≠ 0"
            );
        }
    }
}

#[test]
fn symplectic_methods_have_no_symplecticity_defect_and_the_baselines_do() {
    let fpu = FermiPastaUlam::problem();
    let kepler = Kepler::problem(0.6).unwrap();
    for method in Method::ALL {
        let info = method.info();
        let d_fpu = symplecticity_defect(&fpu.system, method, &fpu.initial.q, &fpu.initial.p, 0.01).unwrap();
        let d_kep = symplecticity_defect(&kepler.system, method, &kepler.initial.q, &kepler.initial.p, 0.05).unwrap();
        if info.symplectic {
            assert!(
                d_fpu <= 1e-9 && d_kep <= 1e-9,
                "{}: defects {d_fpu:.2e}, {d_kep:.2e}",
                info.name
            );
        } else {
            assert!(
                d_fpu >= 1e-6 && d_kep >= 1e-6,
                "{}: defects {d_fpu:.2e}, {d_kep:.2e}",
                info.name
            );
        }
    }
}

#[test]
fn central_differences_reproduce_the_gradient() {
    let fpu = FermiPastaUlam::problem();
    let q: Vec<f64> = fpu
        .initial
        .q
        .iter()
        .enumerate()
        .map(|(i, x)| x + 0.1 * i as f64)
        .collect();
    let mut exact = vec![0.0; 6];
    fpu.system.gradient(&q, &mut exact).unwrap();
    let (mut work, mut approx) = (vec![0.0; 6], vec![0.0; 6]);
    central_gradient(|x| fpu.system.potential(x), &q, &mut work, &mut approx).unwrap();
    let scale = exact.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    assert!(max_diff(&exact, &approx) < 1e-8 * scale, "{exact:?} vs {approx:?}");
}

#[test]
fn scene_data_match_the_published_invariants() {
    let fpu = FermiPastaUlam::problem();
    let h = varmech::model::hamiltonian(&fpu.system, &fpu.initial.q, &fpu.initial.p).unwrap();
    assert!((h - 2.00120008).abs() < 1e-8, "FPU H0 = {h}");
    let i: f64 = (1..=3)
        .map(|j| fpu.system.oscillatory_energy(&fpu.initial.q, &fpu.initial.p, j))
        .sum();
    assert!((i - 1.0).abs() < 1e-8, "FPU I0 = {i}");
    let hh = HenonHeiles::problem();
    let h = varmech::model::hamiltonian(&hh.system, &hh.initial.q, &hh.initial.p).unwrap();
    assert!((h - 0.13).abs() < 1e-15, "Hénon–Heiles H0 = {h}");
}
