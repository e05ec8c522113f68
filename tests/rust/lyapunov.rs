//! The tangent map of a kick–drift step against differences of two nearby steps, its
//! symplecticity, and the Lyapunov spectra it gives: Hénon–Heiles chaotic (a positive exponent
//! and its mirror, a sum of 0 to round-off at every time) and regular (λ₁ falling as log T/T),
//! the harmonic oscillator's all falling to 0.

use varmech::diagnostics::{lyapunov, LyapunovOptions, Stretching};
use varmech::integrators::{Dynamics, General, Method, Options, Stepper, Tangent};
use varmech::model::MechanicalSystem;
use varmech::scenes::{DoublePendulum, FermiPastaUlam, HarmonicOscillator, HenonHeiles};
use varmech::Error;

/// One step of `method` from (q, p): the end (q, p) as one vector.
fn step<S: Dynamics>(sys: &S, method: Method, h: f64, x: &[f64]) -> Vec<f64> {
    let n = sys.dim();
    let mut stepper = Stepper::new(sys, method, &x[..n], &x[n..], &Options::new(h, 1)).unwrap();
    stepper.step().unwrap();
    stepper.q().iter().chain(stepper.p()).copied().collect()
}

/// The tangent map applied to the 2n unit vectors: the step's Jacobian Ψ, column-major.
fn jacobian<S: MechanicalSystem>(sys: &S, method: Method, h: f64, x: &[f64]) -> Vec<f64> {
    let dim = x.len();
    let mut psi = vec![0.0; dim * dim];
    (0..dim).for_each(|j| psi[j * dim + j] = 1.0);
    let mut tangent = Tangent::new(method, dim / 2).unwrap();
    let n = dim / 2;
    tangent.apply(sys, h, (&x[..n], &x[n..]), &mut psi).unwrap();
    psi
}

/// max |Ψ − central differences of the step| over max |Ψ|, and ‖ΨᵀJΨ − J‖_max.
fn check<S: MechanicalSystem + Dynamics>(sys: &S, method: Method, h: f64, x: &[f64]) -> (f64, f64) {
    let dim = x.len();
    let psi = jacobian(sys, method, h, x);
    let (mut error, mut size) = (0.0_f64, 0.0_f64);
    for j in 0..dim {
        let delta = 1e-5 * x[j].abs().max(1.0);
        let moved = |s: f64| {
            let mut y = x.to_vec();
            y[j] += s * delta;
            step(sys, method, h, &y)
        };
        let (plus, minus) = (moved(1.0), moved(-1.0));
        for i in 0..dim {
            let difference = (plus[i] - minus[i]) / (2.0 * delta);
            error = error.max((psi[j * dim + i] - difference).abs());
            size = size.max(psi[j * dim + i].abs());
        }
    }
    let n = dim / 2;
    // (ΨᵀJΨ)ᵢⱼ = Σ_k Ψ_{k,i}·(JΨ)_{k,j}, (JΨ)_{k,j} = Ψ_{k+n,j} for k < n, −Ψ_{k−n,j} after.
    let mut defect = 0.0_f64;
    for i in 0..dim {
        for j in 0..dim {
            let form: f64 = (0..n)
                .map(|k| psi[i * dim + k] * psi[j * dim + k + n] - psi[i * dim + k + n] * psi[j * dim + k])
                .sum();
            let exact = if j == i + n && i < n {
                1.0
            } else if i == j + n && j < n {
                -1.0
            } else {
                0.0
            };
            defect = defect.max((form - exact).abs());
        }
    }
    (error / size, defect)
}

#[test]
fn the_tangent_map_is_the_steps_jacobian_and_symplectic() {
    // Hénon–Heiles with its exact Hessian, and FPU's differenced one; BAB, ABA and first-order
    // splittings. Differences of 1e-5 of the step are right to about 1e-9.
    let hh = HenonHeiles::new();
    let fpu = FermiPastaUlam::new(3, 10.0).unwrap();
    let methods = [
        Method::Verlet,
        Method::Yoshida4,
        Method::Aba864,
        Method::SymplecticEuler,
    ];
    for method in methods {
        let (error, defect) = check(&hh, method, 0.1, &[0.1, -0.2, 0.3, 0.25]);
        assert!(error < 1e-8, "{method:?} on Hénon–Heiles: {error:e}");
        assert!(defect < 1e-14, "{method:?} on Hénon–Heiles: ΨᵀJΨ − J = {defect:e}");
        let x: Vec<f64> = (0..12).map(|i| 0.1 * ((i * 7 % 5) as f64 - 2.0)).collect();
        let (error, defect) = check(&fpu, method, 0.01, &x);
        assert!(error < 1e-7, "{method:?} on FPU: {error:e}");
        assert!(defect < 1e-11, "{method:?} on FPU: ΨᵀJΨ − J = {defect:e}");
    }
}

fn spectrum<S: Dynamics>(sys: &S, q0: &[f64], p0: &[f64], (dt, steps): (f64, usize)) -> Stretching {
    let options = LyapunovOptions {
        t0: 0.0,
        dt,
        steps,
        k: 2 * q0.len(),
        every: 10,
    };
    lyapunov(sys, Method::Verlet, q0, p0, &options, || Ok(())).unwrap()
}

/// λⱼ at row r of the run.
fn exponents(s: &Stretching, r: usize) -> Vec<f64> {
    s.sums[r * s.k..(r + 1) * s.k].iter().map(|x| x / s.t[r]).collect()
}

#[test]
fn henon_heiles_chaotic_has_a_positive_exponent_its_mirror_and_a_sum_of_zero_at_every_time() {
    let sys = HenonHeiles::new();
    let s = spectrum(&sys, &[0.0, -0.25], &[0.42, 0.0], (0.05, 200_000));
    // The tangent map has determinant 1: Σ ln Rⱼⱼ is 0 to round-off at every
    // re-orthonormalization (20 000 of them here).
    let worst = s
        .sums
        .chunks_exact(4)
        .map(|r| r.iter().sum::<f64>().abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-11, "Σ ln R = {worst:e}");
    let last = exponents(&s, s.t.len() - 1);
    assert!(last[0] > 0.04, "λ₁ = {}", last[0]);
    assert!((last[0] + last[3]).abs() < 1e-3, "{last:?}");
    // The two along the flow and across the energy shell fall as 1/T.
    assert!(last[1].abs() < 2e-3 && last[2].abs() < 2e-3, "{last:?}");
    // The same run's states, bit for bit.
    let mut stepper = Stepper::new(
        &sys,
        Method::Verlet,
        &[0.0, -0.25],
        &[0.42, 0.0],
        &Options::new(0.05, 1),
    )
    .unwrap();
    stepper.advance(200_000, || Ok(())).unwrap();
    assert_eq!((stepper.q(), stepper.p()), (&s.q[..], &s.p[..]));
}

#[test]
fn a_regular_orbits_exponents_fall_as_log_t_over_t() {
    // Hénon–Heiles on a torus (H = 0.13, the SciML protocol's orbit), and the harmonic
    // oscillator (its Hessian differenced): λ₁(T) ≈ c·ln T/T, so from T = 10³ to 10⁴ it falls by
    // about 7.7 (at least 4 here), and Σλ stays 0.
    let hh = HenonHeiles::new();
    let ho = HarmonicOscillator::new(2.0).unwrap();
    let runs = [
        spectrum(&hh, &[0.1, 0.0], &[0.0, 0.5], (0.05, 200_000)),
        spectrum(&ho, &[1.0], &[0.0], (0.05, 200_000)),
    ];
    for s in runs {
        let at = |t: f64| exponents(&s, s.t.iter().position(|&x| x >= t).unwrap());
        let (early, late) = (at(1e3), at(1e4));
        assert!(
            late[0] > 0.0 && late[0] < early[0] / 4.0,
            "λ₁ {} → {}",
            early[0],
            late[0]
        );
        assert!(late[0] < 2e-3, "{late:?}");
        assert!(late.iter().sum::<f64>().abs() < 1e-14, "{late:?}");
    }
}

#[test]
fn bad_requests_are_refused_naming_the_argument() {
    let hh = HenonHeiles::new();
    let options = LyapunovOptions {
        t0: 0.0,
        dt: 0.05,
        steps: 100,
        k: 4,
        every: 10,
    };
    let refused = |sys: &dyn Dynamics, method, options: LyapunovOptions| match lyapunov(
        sys,
        method,
        &[0.1, 0.0],
        &[0.0, 0.5],
        &options,
        || Ok(()),
    ) {
        Err(Error::InvalidArgument { argument, .. }) => argument,
        other => panic!("not refused: {other:?}"),
    };
    assert_eq!(refused(&hh, Method::Verlet, LyapunovOptions { k: 5, ..options }), "k");
    assert_eq!(refused(&hh, Method::Verlet, LyapunovOptions { k: 0, ..options }), "k");
    assert_eq!(
        refused(&hh, Method::Verlet, LyapunovOptions { every: 0, ..options }),
        "every"
    );
    assert_eq!(refused(&hh, Method::Rk4, options), "method");
    let pendulum = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81).unwrap();
    assert_eq!(refused(&General(&pendulum), Method::Midpoint, options), "model");
}
