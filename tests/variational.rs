//! The explicit methods are the variational integrators they claim to be, and they are
//! symplectic where they say so.

use varmech::diagnostics::symplecticity_defect;
use varmech::discrete::{DiscreteLagrangian, Rectangle, Trapezoidal};
use varmech::integrators::{Composition, Integrator, Method};
use varmech::model::{finite_difference, MechanicalSystem};
use varmech::scenes::{FermiPastaUlam, HenonHeiles, Kepler, NBody};

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
    let (mut q1, mut p1) = (q0.to_vec(), p0.to_vec());
    Integrator::new(method, sys.dim())
        .step(sys, &mut q1, &mut p1, h)
        .unwrap();
    let minus = ld.momentum_minus(sys, q0, &q1, h).unwrap();
    let plus = ld.momentum_plus(sys, q0, &q1, h).unwrap();
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

#[test]
fn discrete_legendre_transforms_are_the_slot_derivatives_of_the_discrete_lagrangian() {
    // p₁ = D₂L_d and p₀ = −D₁L_d, checked against differences of L_d itself.
    let hh = HenonHeiles::problem();
    let (q0, q1, h) = ([0.1, -0.2], [0.15, -0.1], 0.1);
    let d = |ld: &dyn Fn(&[f64], &[f64]) -> f64, slot: usize, i: usize| {
        let e = 1e-6;
        let (mut a, mut b) = ((q0.to_vec(), q1.to_vec()), (q0.to_vec(), q1.to_vec()));
        if slot == 0 {
            a.0[i] += e;
            b.0[i] -= e;
        } else {
            a.1[i] += e;
            b.1[i] -= e;
        }
        (ld(&a.0, &a.1) - ld(&b.0, &b.1)) / (2.0 * e)
    };
    let trap = |a: &[f64], b: &[f64]| Trapezoidal.value(&hh.system, a, b, h).unwrap();
    let rect = |a: &[f64], b: &[f64]| Rectangle.value(&hh.system, a, b, h).unwrap();
    for i in 0..2 {
        assert!((d(&trap, 0, i) + Trapezoidal.momentum_minus(&hh.system, &q0, &q1, h).unwrap()[i]).abs() < 1e-8);
        assert!((d(&trap, 1, i) - Trapezoidal.momentum_plus(&hh.system, &q0, &q1, h).unwrap()[i]).abs() < 1e-8);
        assert!((d(&rect, 0, i) + Rectangle.momentum_minus(&hh.system, &q0, &q1, h).unwrap()[i]).abs() < 1e-8);
        assert!((d(&rect, 1, i) - Rectangle.momentum_plus(&hh.system, &q0, &q1, h).unwrap()[i]).abs() < 1e-8);
    }
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
    finite_difference::central_gradient(|x| fpu.system.potential(x), &q, &mut work, &mut approx).unwrap();
    let scale = exact.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    assert!(max_diff(&exact, &approx) < 1e-8 * scale, "{exact:?} vs {approx:?}");
}

#[test]
fn scene_data_match_the_published_invariants() {
    let fpu = FermiPastaUlam::problem();
    let h = varmech::diagnostics::hamiltonian(&fpu.system, &fpu.initial.q, &fpu.initial.p).unwrap();
    assert!((h - 2.00120008).abs() < 1e-8, "FPU H0 = {h}");
    let i: f64 = (1..=3)
        .map(|j| fpu.system.oscillatory_energy(&fpu.initial.q, &fpu.initial.p, j))
        .sum();
    assert!((i - 1.0).abs() < 1e-8, "FPU I0 = {i}");
    let hh = HenonHeiles::problem();
    let h = varmech::diagnostics::hamiltonian(&hh.system, &hh.initial.q, &hh.initial.p).unwrap();
    assert!((h - 0.13).abs() < 1e-15, "Hénon–Heiles H0 = {h}");
}
