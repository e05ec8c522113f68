//! Kick–drift splitting methods: the coefficients' facts, the force evaluations they cost, and
//! the bit-identical results of the methods that were there before `Splitting` built them.

use crate::common;

use varmech::integrators::{Increment, Integrator, Leading, Method, Splitting, StepStart};
use varmech::scenes::Kepler;

/// The final state of 1 000 steps of h = 2π/100 on Kepler e = 0.6, as bit patterns.
fn kepler_bits(method: Method) -> [u64; 4] {
    let problem = Kepler::problem(0.6).unwrap();
    let steps = 1000;
    let t_end = steps as f64 * 2.0 * std::f64::consts::PI / 100.0;
    let traj = common::run(&problem, method, t_end, steps, steps);
    let k = traj.len() - 1;
    let (q, p) = (traj.q_at(k), traj.p_at(k));
    [q[0].to_bits(), q[1].to_bits(), p[0].to_bits(), p[1].to_bits()]
}

#[test]
fn the_methods_built_before_splittings_keep_their_bits() {
    // Recorded on the tree before `Splitting` (commit 895ccd1), where `KickDrift` built its
    // kicks from the compositions itself.
    let recorded = [
        (
            Method::SymplecticEuler,
            [
                0x3fd71f910b3eb39c,
                0x3fca0e49f186f4a9,
                0xbfdd09a562c9ce47,
                0x3fff56619f2226ec,
            ],
        ),
        (
            Method::Verlet,
            [
                0xbffa0f67826f8163,
                0x3fc4bedf8753f7e6,
                0x3faea027ce35c33a,
                0xbfdfd0dd60f58e1e,
            ],
        ),
        (
            Method::Yoshida4,
            [
                0x3fd5d63dfa831c21,
                0x3fd034feac47dd5a,
                0xbfe98f9e543fa1fb,
                0x3ffc076d32ae1984,
            ],
        ),
        (
            Method::Suzuki4,
            [
                0x3fd99733e6d51189,
                0x3f8b86d02bd448f8,
                0xbfa5e761727618c0,
                0x3ffffd1b819c8bcb,
            ],
        ),
        (
            Method::McLachlan4,
            [
                0x3fd99760a6c5f042,
                0x3f89f3dee877afb0,
                0xbfa5202e7ce45b60,
                0x3ffffd6c4b0e59e3,
            ],
        ),
        (
            Method::Yoshida6,
            [
                0x3fd9997689771a30,
                0xbf69ab94437739a0,
                0x3f84fd8a02b16f80,
                0x3fffffd7a2d4381c,
            ],
        ),
        (
            Method::KahanLi6,
            [
                0x3fd99998da6ae415,
                0xbf3dee8c2cf29c00,
                0x3f58830c0a028b00,
                0x3fffffff246c998f,
            ],
        ),
        (
            Method::SuzukiUmeno8,
            [
                0x3fd9999999991a86,
                0xbeb8c1fa0bc70000,
                0x3ed3f47d93560000,
                0x3fffffffffff6a17,
            ],
        ),
        (
            Method::KahanLi8,
            [
                0x3fd9999999999606,
                0xbe9037e3ffcc0000,
                0x3eaadce5d1280000,
                0x3ffffffffffffbf8,
            ],
        ),
    ];
    for (method, bits) in recorded {
        assert_eq!(kepler_bits(method), bits, "{method:?}");
    }
}

#[test]
fn every_kick_drift_method_is_a_consistent_splitting_with_its_documented_facts() {
    let mut count = 0;
    for method in Method::ALL {
        let info = method.info();
        let Some(s) = Splitting::of(method) else {
            assert!(
                info.implicit || !info.symplectic,
                "{}: symplectic and explicit",
                info.name
            );
            continue;
        };
        count += 1;
        assert_eq!(s.method(), method);
        assert_eq!(s.order(), info.order);
        assert_eq!(s.kicks().len(), s.drifts().len() + 1, "{}", info.name);
        for (what, x) in [("kicks", s.kicks()), ("drifts", s.drifts())] {
            let sum: f64 = x.iter().sum();
            assert!((sum - 1.0).abs() <= 4e-16, "{}: Σ {what} = {sum}", info.name);
        }
        assert_eq!(s.symmetric(), info.symmetric, "{}", info.name);
        assert_eq!(
            (s.stages(), s.stages()),
            (info.stages, info.force_evaluations),
            "{}",
            info.name
        );
        let aba = matches!(method, Method::Aba864 | Method::Aba1064 | Method::McLachlan8Dkd);
        assert_eq!(
            s.leading(),
            if aba { Leading::Drift } else { Leading::Kick },
            "{}",
            info.name
        );
        let bab = !aba && method != Method::SymplecticEuler;
        assert_eq!(s.first_same_as_last(), bab, "{}", info.name);
    }
    assert_eq!(count, 16);
}

#[test]
fn the_published_stage_counts() {
    let stages = |m| Splitting::of(m).unwrap().stages();
    assert_eq!(stages(Method::BlanesMoan4), 6); // SRKN₆ᵇ
    assert_eq!(stages(Method::BlanesMoan6), 11); // SRKN₁₁ᵇ
    assert_eq!(stages(Method::Aba864), 7);
    assert_eq!(stages(Method::Aba1064), 8);
    assert_eq!(stages(Method::McLachlan6), 9);
    assert_eq!(stages(Method::McLachlan8), 17);
    assert_eq!(stages(Method::McLachlan8Dkd), 17);
}

/// Runs `steps` steps of `method` on Kepler e = 0.6 and counts the force evaluations.
fn evaluations(method: Method, steps: u64) -> u64 {
    let problem = Kepler::problem(0.6).unwrap();
    let mut integrator = Integrator::new(method, 2);
    let (mut q, mut p) = (problem.initial.q.clone(), problem.initial.p.clone());
    let (mut dq, mut dp) = (vec![0.0; 2], vec![0.0; 2]);
    for _ in 0..steps {
        let start = StepStart {
            t: 0.0,
            h: 0.05,
            q: &q,
            p: &p,
        };
        let mut increment = Increment {
            dq: &mut dq,
            dp: &mut dp,
        };
        integrator.increment(&problem.system, &start, &mut increment).unwrap();
        for i in 0..2 {
            q[i] += dq[i];
            p[i] += dp[i];
        }
    }
    integrator.force_evaluations()
}

#[test]
fn aba_methods_evaluate_no_force_they_do_not_use_and_bab_methods_reuse_the_last() {
    for method in [
        Method::McLachlan8Dkd,
        Method::Aba864,
        Method::Aba1064,
        Method::BlanesMoan4,
        Method::BlanesMoan6,
        Method::Verlet,
    ] {
        let s = Splitting::of(method).unwrap();
        let per_step = s.stages() as u64;
        // A BAB method evaluates the force at the start once, then s a step; ABA exactly s.
        let first = u64::from(s.leading() == Leading::Kick);
        assert_eq!(evaluations(method, 10), 10 * per_step + first, "{method:?}");
    }
}

#[test]
fn the_position_form_composition_has_the_kicks_of_the_velocity_forms_drifts() {
    let (v, x) = (
        Splitting::of(Method::McLachlan8).unwrap(),
        Splitting::of(Method::McLachlan8Dkd).unwrap(),
    );
    assert_eq!(&x.kicks()[1..x.kicks().len() - 1], v.drifts());
    assert_eq!(x.drifts(), v.kicks());
}

#[test]
fn a_drift_first_step_applies_its_drifts_and_kicks_in_order() {
    // ABA(8,6,4) on the linear oscillator: one step from (1, 0) by hand, a drift first.
    let s = Splitting::of(Method::Aba864).unwrap();
    let sys = varmech::scenes::HarmonicOscillator::new(1.0).unwrap();
    let h = 0.3;
    let (mut q, mut p) = (1.0_f64, 0.0_f64);
    for (i, b) in s.drifts().iter().enumerate() {
        q += b * h * p;
        p -= s.kicks()[i + 1] * h * q;
    }
    let mut integrator = Integrator::new(Method::Aba864, 1);
    let (mut dq, mut dp) = ([0.0], [0.0]);
    let start = StepStart {
        t: 0.0,
        h,
        q: &[1.0],
        p: &[0.0],
    };
    integrator
        .increment(
            &sys,
            &start,
            &mut Increment {
                dq: &mut dq,
                dp: &mut dp,
            },
        )
        .unwrap();
    assert!(
        (1.0 + dq[0] - q).abs() < 1e-15 && (dp[0] - p).abs() < 1e-15,
        "{dq:?} {dp:?} vs {q} {p}"
    );
}
