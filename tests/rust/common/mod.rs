//! Helpers shared by the integration tests.

use varmech::diagnostics::{self, Statistics, Verdict};
use varmech::integrators::{
    integrate, integrate_ensemble, Dynamics, Ensemble, General, MemberWatch, Method, Options, Parallel, Shared,
    Trajectory,
};
use varmech::model::{Constrained, Hessians, Lagrangian, Mass, MechanicalSystem};
use varmech::scenes::{Problem, RigidBody, State};
use varmech::{Error, ModelError};

pub mod contacts;
pub mod skate;
pub mod tapes;

/// ∂L/∂q or ∂L/∂q̇ as a function of (q, q̇).
pub type Gradient<'a> = &'a dyn Fn(&[f64], &[f64], &mut [f64]);

/// Column j of L_qq (∂/∂qⱼ of ∂L/∂q), of L_qq̇ (∂/∂q̇ⱼ of ∂L/∂q) and of L_q̇q̇, by central
/// differences (step 1e-6) of the gradients `lq` and `lv` at (q, q̇): what a model's Hessians
/// are checked against.
pub fn hessian_columns(lq: Gradient, lv: Gradient, q: &[f64], v: &[f64], j: usize) -> [Vec<f64>; 3] {
    let e = 1e-6;
    let column = |f: Gradient, wrt_q: bool| {
        let (mut qp, mut qm, mut vp, mut vm) = (q.to_vec(), q.to_vec(), v.to_vec(), v.to_vec());
        let (plus, minus) = if wrt_q { (&mut qp, &mut qm) } else { (&mut vp, &mut vm) };
        plus[j] += e;
        minus[j] -= e;
        let (mut a, mut b) = (vec![0.0; q.len()], vec![0.0; q.len()]);
        f(&qp, &vp, &mut a);
        f(&qm, &vm, &mut b);
        a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * e)).collect()
    };
    [column(lq, true), column(lq, false), column(lv, false)]
}

/// One method of each family: explicit splitting, composition, baseline, implicit, Galerkin.
pub const FAMILIES: [Method; 5] = [
    Method::Verlet,
    Method::KahanLi8,
    Method::Rk4,
    Method::Midpoint,
    Method::Galerkin4,
];

/// A model of constant mass in a potential given by its two functions, V(q) and ∇V(q).
#[derive(Clone)]
pub struct Potential<V = fn(&[f64]) -> f64, G = fn(&[f64], &mut [f64])> {
    pub dim: usize,
    pub mass: Mass,
    pub potential: V,
    pub gradient: G,
}

impl Potential {
    /// A unit mass (each coordinate's) in V, of gradient ∇V.
    pub fn unit(dim: usize, potential: fn(&[f64]) -> f64, gradient: fn(&[f64], &mut [f64])) -> Self {
        let mass = Mass::scalar(1.0).unwrap();
        Potential {
            dim,
            mass,
            potential,
            gradient,
        }
    }
}

impl<V: Fn(&[f64]) -> f64, G: Fn(&[f64], &mut [f64])> MechanicalSystem for Potential<V, G> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok((self.potential)(q))
    }
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        (self.gradient)(q, grad);
        Ok(())
    }
}

/// The implicit methods, the variational integrators of general Lagrangians: every method of
/// [`Method::ALL`] that [`MethodInfo::implicit`](varmech::integrators::MethodInfo) marks.
pub const IMPLICIT: [Method; 4] = [
    Method::Midpoint,
    Method::Trapezoid,
    Method::Galerkin4,
    Method::Galerkin6,
];

/// splitmix64: reproducible points without a dependency.
pub struct Points(pub u64);

impl Points {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [−scale, scale).
    pub fn uniform(&mut self, scale: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        scale * (2.0 * unit - 1.0)
    }
}

/// Integrates `problem` from its initial state with `steps` steps to `t_end`, keeping every
/// `save_every`-th state.
pub fn run<S: MechanicalSystem>(
    problem: &Problem<S>,
    method: Method,
    t_end: f64,
    steps: usize,
    save_every: usize,
) -> Trajectory {
    let options = Options {
        save_every,
        ..Options::new(t_end / steps as f64, steps)
    };
    integrate(
        &problem.system,
        method,
        &problem.initial.q,
        &problem.initial.p,
        &options,
        || Ok(()),
    )
    .unwrap_or_else(|f| panic!("{:?} failed: {}", method, f.error))
}

/// `f` of each saved state (q, p) of `traj`.
pub fn along<T>(traj: &Trajectory, f: impl Fn(&[f64], &[f64]) -> T) -> Vec<T> {
    (0..traj.len()).map(|k| f(traj.q_at(k), traj.p_at(k))).collect()
}

/// ‖(q, p) − (q_ref, p_ref)‖₂ at the last saved state.
pub fn final_error(traj: &Trajectory, q_ref: &[f64], p_ref: &[f64]) -> f64 {
    let k = traj.len() - 1;
    let dq = traj.q_at(k).iter().zip(q_ref).map(|(a, b)| (a - b).powi(2));
    let dp = traj.p_at(k).iter().zip(p_ref).map(|(a, b)| (a - b).powi(2));
    dq.chain(dp).sum::<f64>().sqrt()
}

/// Asserts `measured` is within a factor `factor` of `published`.
pub fn assert_within_factor(what: &str, measured: f64, published: f64, factor: f64) {
    assert!(
        measured <= factor * published && measured >= published / factor,
        "{what}: measured {measured:.3e}, published {published:.3e} (allowed factor {factor})"
    );
}

/// Asserts that errors at successively halved steps fall at `order` ± `tolerance`: each
/// observed order log₂(eₖ/eₖ₊₁) is in that band. Prints and returns the observed orders.
pub fn assert_order(what: &str, errors: &[f64], order: f64, tolerance: f64) -> Vec<f64> {
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("{what}: errors {errors:?}, orders {orders:.3?}");
    assert!(
        orders.iter().all(|p| (p - order).abs() <= tolerance),
        "{what}: orders {orders:.3?} (errors {errors:?}), expected {order} ± {tolerance}"
    );
    orders
}

/// Asserts that `method` converges at its order ± 0.3 over `halvings` halvings of the step from
/// `n0` steps ([`assert_order`]), `error(steps)` being the error of a run of so many steps.
pub fn assert_method_order(method: Method, n0: usize, halvings: usize, error: impl FnMut(usize) -> f64) {
    let errors: Vec<f64> = (0..=halvings).map(|k| n0 << k).map(error).collect();
    assert_order(&format!("{method:?}"), &errors, method.info().order as f64, 0.3);
}

/// Integrates the general Lagrangian `sys` from `initial` with `steps` steps of size h, keeping
/// every `save_every`-th state.
pub fn run_general<L: Lagrangian>(
    sys: &L,
    initial: &State,
    method: Method,
    h: f64,
    steps: usize,
    save_every: usize,
) -> Result<Trajectory, Error> {
    let options = Options {
        save_every,
        ..Options::new(h, steps)
    };
    run_general_with(sys, initial, method, &options)
}

/// Integrates the general Lagrangian `sys` from `initial` with `options`.
pub fn run_general_with<L: Lagrangian>(
    sys: &L,
    initial: &State,
    method: Method,
    options: &Options,
) -> Result<Trajectory, Error> {
    integrate(&General(sys), method, &initial.q, &initial.p, options, || Ok(())).map_err(|f| f.error)
}

/// Asserts that the Hessians of `sys` at (q, q̇), t = 0, are the central differences of its
/// gradients ([`hessian_columns`]) to `tolerance` relative to max(1, |difference|); returns
/// them, and the largest such gap.
pub fn assert_hessians<L: Lagrangian + ?Sized>(sys: &L, q: &[f64], v: &[f64], tolerance: f64) -> (Hessians, f64) {
    let n = q.len();
    let mut h = Hessians::zeros(n);
    assert!(sys.hessians(q, v, 0.0, &mut h).unwrap());
    let lq = |q: &[f64], v: &[f64], out: &mut [f64]| sys.dl_dq(q, v, 0.0, out).unwrap();
    let lv = |q: &[f64], v: &[f64], out: &mut [f64]| sys.dl_dv(q, v, 0.0, out).unwrap();
    let mut worst = 0.0_f64;
    for j in 0..n {
        let [qq, qv, vv] = hessian_columns(&lq, &lv, q, v, j);
        for (name, matrix, column) in [("qq", &h.qq, qq), ("qv", &h.qv, qv), ("vv", &h.vv, vv)] {
            for i in 0..n {
                let gap = (matrix[(i, j)] - column[i]).abs() / column[i].abs().max(1.0);
                worst = worst.max(gap);
                assert!(
                    gap < tolerance,
                    "{name} ({i}, {j}) at q = {q:?}: {} vs {}",
                    matrix[(i, j)],
                    column[i]
                );
            }
        }
    }
    (h, worst)
}

/// Runs `body` on the rigid body, its Lagrangian on its constraints as a general one, and its
/// initial state.
pub fn with_rigid_body<R>(body: impl FnOnce(&dyn Dynamics, &State) -> R) -> R {
    let problem = RigidBody::problem();
    let sys = Constrained {
        system: General(&problem.system.system),
        constraints: problem.system.constraints.clone(),
    };
    body(&sys, &problem.initial)
}

/// The statistics and verdict of the energy of `sys` along `traj`.
pub fn energy_statistics<L: Lagrangian + ?Sized>(sys: &L, traj: &Trajectory) -> Statistics {
    let terms = diagnostics::energy_terms(sys, traj).unwrap();
    diagnostics::energy_statistics(&traj.t, &terms, &traj.work_at_saves(), traj.steps as u64).unwrap()
}

/// Whether a verdict says the quantity is conserved: to round-off, or in a bounded band.
pub fn conserved(verdict: Verdict) -> bool {
    matches!(verdict, Verdict::ConservedToRoundOff | Verdict::Bounded)
}

/// The relative energy error e = (H − H₀)/|H₀| of a series: its max |e|, and its max |e| over
/// the first and the last tenth of the series (the figures the literature publishes).
#[derive(Debug)]
pub struct RelativeEnergyError {
    pub initial: f64,
    pub max: f64,
    pub first_tenth: f64,
    pub last_tenth: f64,
}

pub fn relative_energy_error(h: &[f64]) -> RelativeEnergyError {
    let e: Vec<f64> = h.iter().map(|x| ((x - h[0]) / h[0]).abs()).collect();
    let max = |s: &[f64]| s.iter().fold(0.0_f64, |m, x| m.max(*x));
    let tenth = (e.len() / 10).max(1);
    RelativeEnergyError {
        initial: h[0],
        max: max(&e),
        first_tenth: max(&e[..tenth]),
        last_tenth: max(&e[e.len() - tenth..]),
    }
}

/// The error of a conserved quantity J along a run: max |J − J₀|, absolute and relative to |J₀|.
#[derive(Debug)]
pub struct InvariantStatistics {
    pub initial: f64,
    pub max_abs_error: f64,
    /// max |J − J₀| / |J₀| (the absolute error when J₀ = 0).
    pub max_rel_error: f64,
}

impl InvariantStatistics {
    pub fn new(values: &[f64]) -> Self {
        let initial = values.first().copied().unwrap_or(0.0);
        let max_abs_error = values.iter().fold(0.0_f64, |m, x| m.max((x - initial).abs()));
        let scale = if initial != 0.0 { initial.abs() } else { 1.0 };
        InvariantStatistics {
            initial,
            max_abs_error,
            max_rel_error: max_abs_error / scale,
        }
    }
}

/// The verlet ensemble of `sys` on two workers from the rows (q0, p0), every member watching
/// `watched`.
pub fn verlet_ensemble<S: Dynamics + Sync>(
    sys: &S,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    watched: &MemberWatch,
) -> Ensemble {
    let parallel = Parallel {
        workers: Some(2),
        chunk_size: None,
    };
    integrate_ensemble(&Shared(sys), Method::Verlet, q0, p0, options, parallel, watched, || {
        Ok(())
    })
    .unwrap()
}
