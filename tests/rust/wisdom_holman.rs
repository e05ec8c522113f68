//! The Wisdom–Holman methods: the Kepler drift against Kepler's equation, Jacobi coordinates,
//! the kernel's order and ε-scaling, the correctors, reversibility and symplecticity, resuming,
//! and the outer solar system against HLW's reference state.

use crate::common::{self, final_error, run};
use varmech::diagnostics::symplecticity_defect;
use varmech::integrators::wisdom_holman::{kepler_drift, Jacobi};
use varmech::integrators::{Kernel, Method, Options, Stepper, WisdomHolman};
use varmech::model::hamiltonian;
use varmech::scenes::{Kepler, NBody, Problem};

/// x += δ with Kahan's carry, as the methods add their drifts.
fn add(x: &mut [f64; 3], e: &mut [f64; 3], d: [f64; 3]) {
    for k in 0..3 {
        let s = e[k] + d[k];
        let next = x[k] + s;
        e[k] = s + (x[k] - next);
        x[k] = next;
    }
}

/// The position on the orbit a = 1, μ = 1 of eccentricity `e` at time t from pericentre (y
/// ahead), by Kepler's equation E − e sin E = t, solved by Newton's method to round-off.
fn keplers_equation(e: f64, t: f64) -> [f64; 3] {
    let m = t.rem_euclid(2.0 * std::f64::consts::PI);
    let mut big_e = if e > 0.8 { std::f64::consts::PI } else { m };
    for _ in 0..100 {
        let next = big_e - (big_e - e * big_e.sin() - m) / (1.0 - e * big_e.cos());
        if next == big_e {
            break;
        }
        big_e = next;
    }
    [big_e.cos() - e, (1.0 - e * e).sqrt() * big_e.sin(), 0.0]
}

/// 10⁶ drifts of P/100 (10⁴ periods) land on the orbit of Kepler's equation. Each drift is
/// exact to a few ulps (the carries keep the sums exact), and the energy's round-off walk
/// shifts the phase: Brouwer's law, an along-track error growing like ε·n^{3/2}, bounds it by
/// ε·n^{3/2} = 2.2e-7 for n = 10⁶ (measured: 1.5e-10 for e = 0.1, 7.7e-9 for e = 0.6). At
/// e = 0.99 a step of P/100 crosses the pericentre (0.01) in one drift, whose round-off is
/// 1/(1 − e) times larger (measured 5e-14 against 3e-15 for one drift from pericentre, with an
/// mpmath reference): bound ε·n^{3/2}/(1 − e)². A single drift over the whole time is exact to
/// the period's round-off times the periods, plus the reference's own: its mean anomaly t mod 2π
/// is off by an ulp of t = 2π·10⁴, and the rounded initial speed v_p = √((1 + e)/(1 − e)) moves
/// the period by 3v_p²ε relatively, which after 10⁴ periods puts the orbit 2π·10⁴·3v_p³ε off at
/// pericentre: bound 4·2π·10⁴·ε·(v_p³ + 1/(1 − e)) (measured 1.8e-11, 3.0e-12, 3.8e-8).
#[test]
fn a_million_kepler_drifts_follow_keplers_equation() {
    for e in [0.1_f64, 0.6, 0.99] {
        let brouwer = f64::EPSILON * 1e9;
        let bound = if e > 0.9 { brouwer / (1.0 - e).powi(2) } else { brouwer };
        let v_p = ((1.0 + e) / (1.0 - e)).sqrt();
        let once_bound = 4.0 * 2.0 * std::f64::consts::PI * 1e4 * f64::EPSILON * (v_p.powi(3) + 1.0 / (1.0 - e));
        let mut x = [1.0 - e, 0.0, 0.0];
        let mut v = [0.0, v_p, 0.0];
        let (mut ex, mut ev) = ([0.0; 3], [0.0; 3]);
        let h = 2.0 * std::f64::consts::PI / 100.0;
        let steps = 1_000_000;
        for _ in 0..steps {
            let (dx, dv) = kepler_drift(x, v, 1.0, h);
            add(&mut x, &mut ex, dx);
            add(&mut v, &mut ev, dv);
        }
        let exact = keplers_equation(e, steps as f64 * h);
        let error = (0..3).map(|k| (x[k] - exact[k]).powi(2)).sum::<f64>().sqrt();
        println!("e = {e}: error {error:.3e}");
        assert!(error <= bound, "e = {e}: error {error:.3e} > {bound:.1e}");
        // One drift over the whole time lands there too (the flow drops whole periods).
        let (x0, v0) = ([1.0 - e, 0.0, 0.0], [0.0, v_p, 0.0]);
        let (dx, _) = kepler_drift(x0, v0, 1.0, steps as f64 * h);
        let once = (0..3).map(|k| (x0[k] + dx[k] - exact[k]).powi(2)).sum::<f64>().sqrt();
        println!("e = {e}: one drift, error {once:.3e}");
        assert!(
            once <= once_bound,
            "e = {e}, one drift: error {once:.3e} > {once_bound:.1e}"
        );
    }
}

/// Hyperbolic and parabolic-like orbits, forwards and backwards: 10⁴ drifts equal one drift of
/// the total time, and a drift undone by the drift back returns to round-off.
#[test]
fn kepler_drifts_compose_on_unbound_orbits_and_reverse() {
    for (v_peri, bound) in [(1.5, 1e-12), (2.0f64.sqrt(), 1e-12), (3.0, 1e-12)] {
        let (x0, v0) = ([1.0, 0.0, 0.0], [0.0, v_peri, 0.0]);
        for h in [0.01, -0.01] {
            let (mut x, mut v) = (x0, v0);
            let (mut ex, mut ev) = ([0.0; 3], [0.0; 3]);
            for _ in 0..10_000 {
                let (dx, dv) = kepler_drift(x, v, 1.0, h);
                add(&mut x, &mut ex, dx);
                add(&mut v, &mut ev, dv);
            }
            let (dx, dv) = kepler_drift(x0, v0, 1.0, 10_000.0 * h);
            let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
            let error = (0..3).map(|k| (x[k] - x0[k] - dx[k]).abs()).fold(0.0, f64::max) / r;
            println!("v_peri = {v_peri}, h = {h}: relative error {error:.3e}");
            assert!(error <= bound, "v_peri = {v_peri}, h = {h}: {error:.3e}");
            let (x1, v1) = (
                std::array::from_fn(|k| x0[k] + dx[k]),
                std::array::from_fn(|k| v0[k] + dv[k]),
            );
            let (bx, _) = kepler_drift(x1, v1, 1.0, -10_000.0 * h);
            let back = (0..3).map(|k| (x1[k] + bx[k] - x0[k]).abs()).fold(0.0, f64::max);
            assert!(back <= 1e-12 * r, "v_peri = {v_peri}: back by {back:.3e}");
        }
    }
}

/// To Jacobi coordinates and back is the identity to a few ulps, and the kinetic energy
/// separates with the Jacobi masses m′ᵢ = mᵢηᵢ₋₁/ηᵢ.
#[test]
fn jacobi_coordinates_invert_and_separate_the_kinetic_energy() {
    let problem = NBody::outer_solar_system();
    let (q, p) = (&problem.initial.q, &problem.initial.p);
    let jacobi = Jacobi::new(&problem.system);
    let n = problem.system.masses().len();
    let (mut x, mut v) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    jacobi.from_cartesian(q, p, &mut x, &mut v);
    let (mut q1, mut p1) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
    jacobi.to_cartesian(&x, &v, &mut q1, &mut p1);
    let scale = |a: &[f64]| a.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    let dq = q.iter().zip(&q1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let dp = p.iter().zip(&p1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(dq <= 8.0 * f64::EPSILON * scale(q), "positions off by {dq:.3e}");
    assert!(dp <= 8.0 * f64::EPSILON * scale(p), "momenta off by {dp:.3e}");

    let m = problem.system.masses();
    let t: f64 = (0..n)
        .map(|i| (0..3).map(|k| p[3 * i + k].powi(2)).sum::<f64>() / (2.0 * m[i]))
        .sum();
    let (mut eta, mut t_jacobi) = (m[0], 0.0);
    for i in 1..n {
        let reduced = m[i] * eta / (eta + m[i]);
        eta += m[i];
        t_jacobi += 0.5 * reduced * (0..3).map(|k| v[i][k].powi(2)).sum::<f64>();
    }
    t_jacobi += 0.5 * eta * (0..3).map(|k| v[0][k].powi(2)).sum::<f64>();
    assert!((t_jacobi / t - 1.0).abs() < 1e-14, "T = {t:e}, Jacobi T = {t_jacobi:e}");
}

/// The system of `problem` with the planets' masses (and momenta) scaled by `factor`.
fn scaled(problem: &Problem<NBody>, factor: f64) -> Problem<NBody> {
    let sys = &problem.system;
    let masses: Vec<f64> = sys
        .masses()
        .iter()
        .enumerate()
        .map(|(i, m)| if i == 0 { *m } else { m * factor })
        .collect();
    let mut scaled = problem.clone();
    for (i, m) in masses.iter().enumerate() {
        for k in 0..3 {
            scaled.initial.p[3 * i + k] *= m / sys.masses()[i];
        }
    }
    scaled.system = NBody::new(sys.gravitational_constant(), masses).unwrap();
    scaled
}

/// max |E − E₀|/|E₀| over `steps` steps of `kernel` with the corrector of `order`, the state
/// read every 10 steps.
fn energy_error(problem: &Problem<NBody>, kernel: Kernel, order: u32, h: f64, steps: usize) -> f64 {
    let sys = &problem.system;
    let (mut q, mut p) = (problem.initial.q.clone(), problem.initial.p.clone());
    let e0 = hamiltonian(sys, &q, &p).unwrap();
    let mut wh = WisdomHolman::new(kernel, order, q.len()).unwrap();
    let mut worst = 0.0_f64;
    for k in 0..steps {
        wh.step(sys, &q, &p, h, true).unwrap();
        if k % 10 == 9 {
            wh.synchronise(&mut q, &mut p);
            worst = worst.max((hamiltonian(sys, &q, &p).unwrap() / e0 - 1.0).abs());
        }
    }
    worst
}

/// The Wisdom–Holman kernel is of order 2 with an error proportional to the mass ratio ε:
/// halving h divides the energy error by 4, dividing the planets' masses by 10 divides the
/// relative energy error by 10 (measured 4.0 and 10.0).
#[test]
fn the_kernel_is_of_order_two_with_an_error_proportional_to_the_mass_ratio() {
    let problem = NBody::outer_solar_system();
    let t = 20_000.0;
    let error = |p: &Problem<NBody>, h: f64| energy_error(p, Kernel::Standard, 0, h, (t / h) as usize);
    let (e100, e50) = (error(&problem, 100.0), error(&problem, 50.0));
    let light = scaled(&problem, 0.1);
    let e100_light = error(&light, 100.0);
    println!("errors {e100:.3e}, {e50:.3e}; masses / 10: {e100_light:.3e}");
    let order = (e100 / e50).log2();
    assert!((order - 2.0).abs() < 0.15, "order {order:.3}");
    let ratio = e100 / e100_light;
    assert!((ratio / 10.0 - 1.0).abs() < 0.15, "ε-ratio {ratio:.3}");
}

/// The correctors of Wisdom, Holman & Touma remove the O(εh²) energy error: at h = 100 days over
/// 20 000 days the kernel's 4.1e-7 drops by 124 with the corrector of order 3 and by 845 (about
/// 1/ε) from order 5 on, to the O(ε²h²) left; the lazy modified kick removes that too (2.1e-12
/// with the corrector of order 11, a further factor 220).
#[test]
fn the_correctors_remove_the_first_order_energy_error() {
    let problem = NBody::outer_solar_system();
    let (h, steps) = (100.0, 200);
    let plain = energy_error(&problem, Kernel::Standard, 0, h, steps);
    for order in [3, 5, 7, 11, 17] {
        let e = energy_error(&problem, Kernel::Standard, order, h, steps);
        let k = energy_error(&problem, Kernel::LazyModifiedKick, order, h, steps);
        println!(
            "order {order}: {plain:.3e} → {e:.3e} (factor {:.0}); lazy kernel {k:.3e}",
            plain / e
        );
    }
    let e = energy_error(&problem, Kernel::Standard, 11, h, steps);
    assert!(plain / e > 300.0, "corrector 11: {plain:.3e} → {e:.3e}");
    let lazy = energy_error(&problem, Kernel::LazyModifiedKick, 11, h, steps);
    assert!(e / lazy > 30.0, "lazy kernel: {e:.3e} → {lazy:.3e}");
}

/// The outer solar system at 500 000 days against HLW's reference state (‖Δq, Δp‖₂, positions
/// in AU): wh and whc converge at order 2, whc's error 60 times smaller (its O(ε²h²) against
/// O(εh²); measured 3.0e-4 and 5.0e-6 at h = 100 days), whckl at order 4.
#[test]
fn the_outer_solar_system_reaches_the_reference_state() {
    let problem = NBody::outer_solar_system();
    let (reference, _) = problem.reference.as_ref().unwrap();
    for method in [Method::WisdomHolman, Method::WisdomHolmanCorrected] {
        let errors: Vec<f64> = [100.0, 50.0]
            .iter()
            .map(|h| {
                let steps = (problem.t_end / h) as usize;
                let traj = run(&problem, method, problem.t_end, steps, steps / 10);
                final_error(&traj, &reference.q, &reference.p)
            })
            .collect();
        common::assert_order(&format!("{method:?}"), &errors, 2.0, 0.1);
    }
    // The modified kick removes the ε²h² term: order 4 (measured 2.0e-10 and 1.0e-11 at 50 and
    // 25 days), down to the reference's own accuracy (Kahan–Li 8 converges to it within 6e-12).
    let errors: Vec<f64> = [50.0, 25.0]
        .iter()
        .map(|h| {
            let steps = (problem.t_end / h) as usize;
            let traj = run(&problem, Method::WisdomHolmanLazyKernel, problem.t_end, steps, steps);
            final_error(&traj, &reference.q, &reference.p)
        })
        .collect();
    common::assert_order("WisdomHolmanLazyKernel", &errors, 4.0, 0.5);
    assert!(errors[1] < 3e-11, "whckl at h = 25 days: {:.3e}", errors[1]);
}

/// The kernel is time-reversible: 1000 steps, the momenta flipped, 1000 steps more return to
/// the start with the momenta flipped, to round-off.
#[test]
fn the_kernel_is_time_reversible() {
    let problem = NBody::outer_solar_system();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let options = Options::new(100.0, 1000);
    let mut stepper = Stepper::new(&problem.system, Method::WisdomHolman, q0, p0, &options).unwrap();
    stepper.advance(1000, || Ok(())).unwrap();
    let (q1, p1): (Vec<f64>, Vec<f64>) = (stepper.q().to_vec(), stepper.p().iter().map(|x| -x).collect());
    stepper.reset(0.0, &q1, &p1).unwrap();
    stepper.advance(1000, || Ok(())).unwrap();
    let dq = stepper
        .q()
        .iter()
        .zip(q0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let dp = stepper
        .p()
        .iter()
        .zip(p0)
        .map(|(a, b)| (a + b).abs())
        .fold(0.0, f64::max);
    println!("back by {dq:.3e} (q), {dp:.3e} (p)");
    assert!(dq < 1e-11 && dp < 1e-17, "back by {dq:.3e} (q), {dp:.3e} (p)");
}

/// One step of wh and whc is symplectic: ‖ΨᵀJΨ − J‖ at round-off of the differences, on three
/// bodies of comparable masses (so that the finite differences see every coordinate).
#[test]
fn the_methods_are_symplectic() {
    let sys = NBody::new(1.0, vec![1.0, 0.1, 0.05]).unwrap();
    let q = [0.0, 0.0, 0.0, 1.0, 0.0, 0.1, -0.5, 2.0, 0.0];
    let p = [-0.1 * 0.1, 0.0, 0.0, 0.0, 0.1, 0.0, 0.05 * 0.7, 0.0, 0.0];
    for method in [Method::WisdomHolman, Method::WisdomHolmanCorrected] {
        let defect = symplecticity_defect(&sys, method, &q, &p, 0.05).unwrap();
        println!("{method:?}: defect {defect:.3e}");
        assert!(defect < 1e-9, "{method:?}: defect {defect:.3e}");
    }
}

/// Taken apart and resumed, a stepper of whc continues bit for bit, and reading the state
/// after every step does not change the steps (the image is made from a copy).
#[test]
fn resuming_and_reading_do_not_change_the_steps() {
    let problem = NBody::outer_solar_system();
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let options = Options::new(50.0, 1000);
    let method = Method::WisdomHolmanCorrected;
    let mut straight = Stepper::new(&problem.system, method, q0, p0, &options).unwrap();
    straight.advance(1000, || Ok(())).unwrap();

    let mut first = Stepper::new(&problem.system, method, q0, p0, &options).unwrap();
    for _ in 0..500 {
        first.step().unwrap();
    }
    let state = first.into_state();
    let model = Box::new(problem.system.clone());
    let mut second = Stepper::resume(model, state).unwrap();
    second.advance(500, || Ok(())).unwrap();
    assert_eq!(straight.steps(), second.steps());
    assert_eq!(straight.q(), second.q());
    assert_eq!(straight.p(), second.p());
    // Each of the 500 single steps synchronised (20 kicks of the inverse corrector), the straight
    // run once.
    assert_eq!(straight.force_evaluations() + 500 * 20, second.force_evaluations());
}

/// The Wisdom–Holman methods integrate the N-body problem alone, and say so.
#[test]
fn the_wisdom_holman_methods_refuse_other_models() {
    let problem = Kepler::problem(0.6).unwrap();
    let options = Options::new(0.01, 10);
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let error = Stepper::new(&problem.system, Method::WisdomHolmanCorrected, q0, p0, &options).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("gravitational N-body"), "{message}");
    assert_eq!(Method::from_name("whc").unwrap(), Method::WisdomHolmanCorrected);
}
