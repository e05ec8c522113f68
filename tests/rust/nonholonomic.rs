//! Velocity constraints A(q)q̇ = 0 and the reversible discrete Lagrange–d'Alembert integrator
//! (reference/impulses_and_rolling.md, "Rolling without slipping"): the vertical rolling disk,
//! Byerly's sphere on a rough incline, a particle held to a circle by x ẋ + y ẏ = 0 against
//! RATTLE, and the Chaplygin sleigh.

use crate::common::{self, Potential};
use crate::nonholonomic_scenes::{ball, build};

use nalgebra::DMatrix;
use varmech::integrators::{integrate, Dynamics, General, Method, Options, Trajectory};
use varmech::model::{Anchor, Constrained, Distances, Hessians, Lagrangian, Link, Nonholonomic, VelocityConstraints};
use varmech::scenes::{Blade, FreeBody, NonholonomicScene, SceneModel};
use varmech::{Error, ModelError};

/// L = ½q̇ᵀ diag(m) q̇, a free body, with its exact second derivatives unless `differenced`.
struct Free {
    mass: Vec<f64>,
    differenced: bool,
}

impl Lagrangian for Free {
    fn dim(&self) -> usize {
        self.mass.len()
    }

    fn lagrangian(&self, _q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(0.5 * v.iter().zip(&self.mass).map(|(v, m)| m * v * v).sum::<f64>())
    }

    fn dl_dq(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.fill(0.0);
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.iter_mut().zip(v).zip(&self.mass).for_each(|((o, v), m)| *o = m * v);
        Ok(())
    }

    fn velocity(&self, _q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        v.iter_mut().zip(p).zip(&self.mass).for_each(|((v, p), m)| *v = p / m);
        Ok(())
    }

    fn hessians(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        out.qq.fill(0.0);
        out.qv.fill(0.0);
        out.vv = DMatrix::from_diagonal(&self.mass.clone().into());
        Ok(!self.differenced)
    }
}

/// The vertical disk of radius R rolling without slipping, q = (x, y, θ, φ): ẋ = Rφ̇cosθ,
/// ẏ = Rφ̇sinθ, with ∂A/∂θ exact.
struct Rolling {
    radius: f64,
}

impl VelocityConstraints for Rolling {
    fn count(&self) -> usize {
        2
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (s, c) = q[2].sin_cos();
        a.fill(0.0);
        (a[(0, 0)], a[(0, 3)]) = (1.0, -self.radius * c);
        (a[(1, 1)], a[(1, 3)]) = (1.0, -self.radius * s);
        Ok(())
    }

    fn derivative(&self, q: &[f64], i: usize, out: &mut DMatrix<f64>) -> Result<(), ModelError> {
        out.fill(0.0);
        if i == 2 {
            let (s, c) = q[2].sin_cos();
            (out[(0, 3)], out[(1, 3)]) = (self.radius * s, -self.radius * c);
        }
        Ok(())
    }
}

fn options(h: f64, steps: usize, save_every: usize) -> Options {
    Options {
        save_every,
        ..Options::new(h, steps)
    }
}

fn run<L: Lagrangian, C: VelocityConstraints>(
    model: &Nonholonomic<L, C>,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
) -> Trajectory {
    integrate(model, Method::Midpoint, q0, p0, options, || Ok(())).unwrap_or_else(|f| panic!("{}", f.error))
}

/// max over the saved states of |A(q)q̇|∞ relative to ‖A‖∞‖q̇‖∞.
fn residual<L: Lagrangian, C: VelocityConstraints>(model: &Nonholonomic<L, C>, traj: &Trajectory) -> f64 {
    (0..traj.len())
        .map(|k| model.constraint_residuals(traj.q_at(k), traj.p_at(k)).unwrap().unwrap())
        .fold(0.0, |a, r| a.max(r.velocity / r.velocity_size))
}

/// The energies at the saved states.
fn energies<L: Lagrangian, C>(model: &Nonholonomic<L, C>, traj: &Trajectory) -> Vec<f64> {
    common::along(traj, |q, p| model.system.energy(q, p, 0.0).unwrap())
}

/// The disk: m = 1, I = 1/4 about a diameter, J = 1/2 about the axle, R = 1; θ̇ = 0.7, φ̇ = 2.
fn disk(differenced: bool) -> (Nonholonomic<Free, Rolling>, Vec<f64>, Vec<f64>) {
    let model = Nonholonomic {
        system: Free {
            mass: vec![1.0, 1.0, 0.25, 0.5],
            differenced,
        },
        constraints: Rolling { radius: 1.0 },
    };
    let (theta0, omega, spin) = (0.3_f64, 0.7, 2.0);
    let v0 = [spin * theta0.cos(), spin * theta0.sin(), omega, spin];
    let mut p0 = vec![0.0; 4];
    model.system.dl_dv(&[0.0; 4], &v0, 0.0, &mut p0).unwrap();
    (model, vec![0.0, 0.0, theta0, 0.0], p0)
}

/// The largest relative distance of the disk's contact point from the circle of radius Rφ̇/θ̇
/// about its centre, over a run of `steps` steps of h.
fn off_the_circle<L: Lagrangian, C: VelocityConstraints>(
    model: &Nonholonomic<L, C>,
    q0: &[f64],
    p0: &[f64],
    h: f64,
    steps: usize,
) -> f64 {
    let traj = run(model, q0, p0, &options(h, steps, 1));
    let radius = 2.0 / 0.7;
    let centre = (-radius * q0[2].sin(), radius * q0[2].cos());
    (0..traj.len())
        .map(|k| {
            let q = traj.q_at(k);
            (((q[0] - centre.0).powi(2) + (q[1] - centre.1).powi(2)).sqrt() - radius).abs() / radius
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_rolling_disk_turns_and_rolls_at_constant_rates_on_a_circle() {
    // θ̇ and φ̇ stay constant, the energy too, and A(q)q̇ = 0 holds, all to round-off over 10⁶
    // steps: the angles grow to θ = 3.5e4 and φ = 1e5 rad, whose rounding (ε|φ| ≈ 2e-11 a
    // step) random-walks φ̇ and E by 4e-8 over the run (1.7e-10 after 10⁵ steps, as √N; the
    // method's own error is O(h²) = 2.5e-3).
    let problem = build("rolling_disk", &[]);
    let SceneModel::Nonholonomic(NonholonomicScene::RollingDisk(model)) = problem.system else {
        panic!("not the disk")
    };
    let (q0, p0) = (problem.initial.q, problem.initial.p);
    let (h, steps) = (0.05, 1_000_000);
    let traj = run(&model, &q0, &p0, &options(h, steps, 100));
    let (omega, spin) = (0.7, 2.0);
    let rates = (0..traj.len()).map(|k| traj.p_at(k)).fold(0.0_f64, |a, p| {
        a.max((p[2] / 0.25 - omega).abs()).max((p[3] / 0.5 - spin).abs())
    });
    let e = energies(&model, &traj);
    let energy = e.iter().fold(0.0_f64, |a, x| a.max((x - e[0]).abs() / e[0]));
    let constraint = residual(&model, &traj);
    println!("disk: |Δθ̇|, |Δφ̇| ≤ {rates:.1e}, |ΔE|/E ≤ {energy:.1e}, |A q̇| ≤ {constraint:.1e} ‖A‖‖q̇‖");
    assert!(rates <= 1e-7, "{rates:e}");
    assert!(energy <= 1e-7, "{energy:e}");
    assert!(constraint <= 1e-11, "{constraint:e}");
    // The contact point stays on the circle of radius Rφ̇/θ̇ to order 2 (over T = 100).
    let circle: Vec<f64> = (0..3)
        .map(|k| {
            let h = 0.1 / 2f64.powi(k);
            off_the_circle(&model, &q0, &p0, h, (100.0 / h).round() as usize)
        })
        .collect();
    common::assert_order("disk: contact point off the circle", &circle, 2.0, 0.15);
}

#[test]
fn the_exact_jacobian_and_the_differenced_one_take_the_same_steps() {
    // The exact path (∂A/∂q supplied, the model's Hessians) and central differences of the
    // whole equations solve the same equations: the states agree to the Newton tolerance.
    let ((exact, q0, p0), (differenced, _, _)) = (disk(false), disk(true));
    let options = options(0.05, 2_000, 2_000);
    let (a, b) = (run(&exact, &q0, &p0, &options), run(&differenced, &q0, &p0, &options));
    let last = a.len() - 1;
    let gap = common::final_error(&a, b.q_at(last), b.p_at(last));
    println!(
        "exact against differenced Jacobian after 2000 steps: {gap:.1e}; Newton {} and {}",
        a.newton_iterations, b.newton_iterations
    );
    assert!(gap <= 1e-11, "{gap:e}");
}

/// The centre of the ball of the scene `rolling_sphere` at T = 1 with steps of h (from (0, 0)
/// with velocity (1, 0.3) and no spin about the normal, on the incline α = 0.5), and the
/// largest constraint residual.
fn sphere_centre(h: f64) -> ([f64; 2], f64) {
    let (model, q0, p0, _) = ball("rolling_sphere", &[]);
    let steps = (1.0 / h).round() as usize;
    let traj = run(&model, &q0, &p0, &options(h, steps, steps));
    let q = traj.q_at(traj.len() - 1);
    ([q[0], q[1]], residual(&model, &traj))
}

#[test]
fn the_sphere_on_a_rough_incline_runs_down_a_parabola_at_five_sevenths_of_g_sin_alpha() {
    // Byerly: the centre moves with constant acceleration (5/7)g sin α down the slope, and
    // uniformly across it. The DLA integrator reaches that parabola at order 2.
    let acceleration = 5.0 / 7.0 * 9.81 * 0.5_f64.sin();
    let exact = [1.0 + 0.5 * acceleration, 0.3];
    let mut errors = Vec::new();
    for k in 0..4 {
        let (centre, constraint) = sphere_centre(0.1 / 2f64.powi(k));
        assert!(constraint <= 1e-14, "{constraint:e}");
        errors.push(((centre[0] - exact[0]).powi(2) + (centre[1] - exact[1]).powi(2)).sqrt());
    }
    common::assert_order("sphere on the incline, centre at T = 1", &errors, 2.0, 0.15);
    assert!(errors[3] < 1e-4, "{errors:?}");
}

/// The particle held to the unit circle by x ẋ + y ẏ = 0: A(q) = (x, y), ∂A/∂x = (1, 0),
/// ∂A/∂y = (0, 1).
struct Radial;

impl VelocityConstraints for Radial {
    fn count(&self) -> usize {
        1
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        (a[(0, 0)], a[(0, 1)]) = (q[0], q[1]);
        Ok(())
    }

    fn derivative(&self, _q: &[f64], i: usize, out: &mut DMatrix<f64>) -> Result<(), ModelError> {
        (out[(0, 0)], out[(0, 1)]) = (f64::from(i == 0), f64::from(i == 1));
        Ok(())
    }
}

/// A unit mass in the plane under V = y + x² (gravity and a spring to the vertical axis,
/// so that the midpoint and trapezoidal L_d differ).
fn bowl() -> Potential {
    Potential::unit(
        2,
        |q| q[1] + q[0] * q[0],
        |q, grad| grad.copy_from_slice(&[2.0 * q[0], 1.0]),
    )
}

#[test]
fn a_particle_held_to_a_circle_by_a_velocity_constraint_is_the_pendulum() {
    // x ẋ + y ẏ = 0 is the derivative of x² + y² = 1, and its discrete constraint at the
    // midpoint, q̄·δq = ½(|q₁|² − |q₀|²) = 0, is the holonomic one: the DLA step is the
    // constrained DEL step of the midpoint rule to round-off, and matches RATTLE (the
    // trapezoidal L_d) to order 2.
    let bowl = bowl();
    let model = Nonholonomic {
        system: bowl.clone(),
        constraints: Radial,
    };
    let circle = Distances::new(
        2,
        vec![Link {
            body: 0,
            to: Anchor::Fixed(vec![0.0, 0.0]),
            length: 1.0,
        }],
    );
    let holonomic = Constrained {
        system: General(&bowl),
        constraints: circle.clone(),
    };
    let rattle = Constrained {
        system: bowl.clone(),
        constraints: circle,
    };
    let (q0, p0) = ([2f64.sin(), -2f64.cos()], [0.0, 0.0]);
    let end = |traj: &Trajectory| [traj.q_at(traj.len() - 1).to_vec(), traj.p_at(traj.len() - 1).to_vec()].concat();
    let distance = |a: &[f64], b: &[f64]| a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let step = |h: f64, method, model: &dyn Dynamics| {
        let steps = (10.0 / h).round() as usize;
        end(&integrate(model, method, &q0, &p0, &options(h, steps, steps), || Ok(())).unwrap())
    };
    let same = distance(
        &step(0.05, Method::Midpoint, &model),
        &step(0.05, Method::Midpoint, &holonomic),
    );
    println!("DLA against the constrained DEL step (midpoint) at T = 10: {same:.1e}");
    assert!(same <= 1e-11, "{same:e}");
    let gaps: Vec<f64> = (0..4)
        .map(|k| {
            let h = 0.1 / 2f64.powi(k);
            distance(&step(h, Method::Midpoint, &model), &step(h, Method::Rattle, &rattle))
        })
        .collect();
    common::assert_order("DLA against RATTLE at T = 10", &gaps, 2.0, 0.15);
}

/// The sleigh of the scene `chaplygin_sleigh` (m = I = 1, blade b = 1 behind the centre)
/// spinning in place, ω = 1 and u = 0 (its centre moving sideways at bω).
fn sleigh() -> (Nonholonomic<FreeBody, Blade>, Vec<f64>, Vec<f64>) {
    let problem = build("chaplygin_sleigh", &[]);
    match problem.system {
        SceneModel::Nonholonomic(NonholonomicScene::ChaplyginSleigh(s)) => (s, problem.initial.q, problem.initial.p),
        other => panic!("not the sleigh: {other:?}"),
    }
}

#[test]
fn the_chaplygin_sleigh_keeps_its_energy_and_relaxes_to_a_straight_line() {
    // From a spin with no forward speed, E = ½(u² + (I + mb²)ω²) = 1 with u = 0, ω = 1 (the
    // sideways speed is bω). It relaxes to ω = 0, |u| = √(2E/m) = √2; the energy error stays
    // bounded, with no drift, over 10⁶ steps, and A(q)q̇ = 0 to round-off.
    let (model, q0, p0) = sleigh();
    let steps = 1_000_000;
    let traj = run(&model, &q0, &p0, &options(0.01, steps, 100));
    let e = energies(&model, &traj);
    let stats = common::energy_statistics(&model.system, &traj);
    let last = traj.p_at(traj.len() - 1);
    let (speed, omega) = ((last[0] * last[0] + last[1] * last[1]).sqrt(), last[2]);
    let constraint = residual(&model, &traj);
    println!(
        "sleigh: E0 = {}, max |ΔE| = {:.1e}, drift {:.1e} ± {:.1e}/time, verdict {:?}; final |v| = {speed:.12}, ω = {omega:.1e}, |A q̇| ≤ {constraint:.1e}",
        e[0], stats.max_abs_error, stats.drift_rate, stats.drift_rate_stderr, stats.verdict
    );
    assert!(common::conserved(stats.verdict), "{:?}", stats.verdict);
    assert!(stats.max_abs_error <= 1e-4, "{}", stats.max_abs_error);
    assert!(omega.abs() <= 1e-10, "{omega:e}");
    assert!((speed - 2f64.sqrt()).abs() <= 2.0 * stats.max_abs_error, "{speed}");
    assert!(constraint <= 1e-14, "{constraint:e}");
}

#[test]
fn initial_data_off_the_velocity_constraints_is_refused_naming_p0() {
    let (model, q0, mut p0) = disk(false);
    p0[0] += 1e-3;
    let err = integrate(&model, Method::Midpoint, &q0, &p0, &options(0.1, 10, 1), || Ok(())).unwrap_err();
    assert!(
        matches!(&err.error, Error::InvalidArgument { argument: "p0", .. }),
        "{}",
        err.error
    );
    let err = integrate(&model, Method::Trapezoid, &q0, &p0, &options(0.1, 10, 1), || Ok(())).unwrap_err();
    assert!(err.error.to_string().starts_with("method:"), "{}", err.error);
    // The projection puts it back: M-orthogonally, q unchanged.
    let (q, p) = Dynamics::project(&model, &q0, &p0).unwrap().unwrap();
    assert_eq!(q, q0);
    assert!(model.constraint_residuals(&q, &p).unwrap().unwrap().velocity <= 1e-15);
}

#[test]
fn the_step_is_reversible_the_sleigh_retraces_its_path_when_its_momenta_are_reversed() {
    // The DLA step is symmetric and the sleigh is reversible under p ↦ −p (L even in q̇, A
    // linear in it): 40 steps on, through the turn, the momenta reversed, 40 steps more return
    // it to its start with reversed momenta, to round-off (a step that is not symmetric misses
    // by its error, O(h²)). Longer runs amplify round-off: the relaxed motion, reversed, is
    // unstable (blade first).
    let (model, q0, p0) = sleigh();
    let options = options(0.05, 40, 40);
    let there = run(&model, &q0, &p0, &options);
    let k = there.len() - 1;
    let back: Vec<f64> = there.p_at(k).iter().map(|p| -p).collect();
    let home = run(&model, there.q_at(k), &back, &options);
    let reversed: Vec<f64> = p0.iter().map(|p| -p).collect();
    let miss = common::final_error(&home, &q0, &reversed);
    println!("sleigh there and back (2 × 40 steps of 0.05): {miss:.1e}");
    assert!(miss <= 1e-13, "{miss:e}");
}
