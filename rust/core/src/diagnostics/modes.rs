//! Small oscillations: an equilibrium (Newton on the generalized force at rest), the linearized
//! equations there,
//!
//! M δq̈ + (G + D) δq̇ + K δq = 0,   M = ∂²L/∂q̇²,  K = −∂²L/∂q² − ∂Q/∂q,
//! G = ∂²L/∂q̇∂q − ∂²L/∂q∂q̇ (antisymmetric: magnetic fields, rotating frames),  D = −∂Q/∂q̇,
//!
//! all at (q, q̇ = 0, t), Q the model's own forces; their normal modes; and the largest step a
//! method takes on them, stably (hω_max below the method's limit) or to a phase accuracy.
//!
//! A Routh-reduced model's Lagrangian is its Routhian, whose potential is the amended one: its
//! equilibria are the full model's relative equilibria (steady motions), its G their Coriolis
//! coupling.

use nalgebra::{DMatrix, Schur, SymmetricEigen};

use crate::error::StepError;
use crate::integrators::{integrate, Method, Options};
use crate::model::{Hessians, Lagrangian};
use crate::scenes::HarmonicOscillator;
use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::solve::newton::{Correction, Newton, NewtonProblem, Reasons, Rules};
use crate::solve::NewtonOptions;
use crate::{Error, ModelError};

/// The linearized equations at a point: n × n each.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// M = ∂²L/∂q̇².
    pub mass: DMatrix<f64>,
    /// K = −∂²L/∂q² − ∂Q/∂q (symmetric but for circulatory forces).
    pub stiffness: DMatrix<f64>,
    /// G = ∂²L/∂q̇∂q − ∂²L/∂q∂q̇, antisymmetric.
    pub gyroscopic: DMatrix<f64>,
    /// D = −∂Q/∂q̇ (zero for a model without forces).
    pub damping: DMatrix<f64>,
}

/// ∂f/∂x at x by central differences ([`central_jacobian`]), into `out`.
fn differenced(
    f: impl FnMut(&[f64], &mut [f64]) -> Result<(), ModelError>,
    x: &[f64],
    out: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let n = out.nrows();
    let (mut plus, mut minus, mut x) = (vec![0.0; n], vec![0.0; n], x.to_vec());
    let at = Evaluations {
        plus: &mut plus,
        minus: &mut minus,
    };
    central_jacobian(f, &mut x, unit, at, out)
}

/// ∂²L/∂q² at (q, 0, t) and, with `velocities`, ∂²L/∂q∂q̇ and ∂²L/∂q̇²: the model's own where it
/// supplies them, else central differences of its first derivatives (only those asked for: a
/// Newton iteration on the balance of forces needs ∂²L/∂q² alone).
fn hessians(model: &dyn Lagrangian, q: &[f64], t: f64, velocities: bool) -> Result<Hessians, ModelError> {
    let n = q.len();
    let mut out = Hessians::zeros(n);
    let zeros = vec![0.0; n];
    if model.hessians(q, &zeros, t, &mut out)? {
        return Ok(out);
    }
    differenced(|x, out| model.dl_dq(x, &zeros, t, out), q, &mut out.qq)?;
    if velocities {
        // Entry (i, j) of qv is ∂²L/∂qᵢ∂q̇ⱼ: row i of ∂(∂L/∂q)/∂q̇.
        differenced(|v, out| model.dl_dq(q, v, t, out), &zeros, &mut out.qv)?;
        differenced(|v, out| model.dl_dv(q, v, t, out), &zeros, &mut out.vv)?;
    }
    Ok(out)
}

/// K = −∂²L/∂q² − ∂Q/∂q at (q, 0, t), ∂²L/∂q² from `h`, ∂Q/∂q by central differences.
fn stiffness(model: &dyn Lagrangian, q: &[f64], t: f64, h: &Hessians) -> Result<DMatrix<f64>, ModelError> {
    let mut k = -&h.qq;
    if model.is_forced() {
        let (n, zeros) = (q.len(), vec![0.0; q.len()]);
        let mut dq = DMatrix::zeros(n, n);
        differenced(|x, out| model.force(x, &zeros, t, out), q, &mut dq)?;
        k -= dq;
    }
    Ok(k)
}

/// The linearized equations of `model` at (q, q̇ = 0, t) ([`Linearization`]).
///
/// # Errors
/// The model's own.
pub fn linearize(model: &dyn Lagrangian, q: &[f64], t: f64) -> Result<Linearization, ModelError> {
    let n = q.len();
    let h = hessians(model, q, t, true)?;
    let mut damping = DMatrix::zeros(n, n);
    if model.is_forced() {
        let zeros = vec![0.0; n];
        differenced(|v, out| model.force(q, v, t, out), &zeros, &mut damping)?;
        damping.neg_mut();
    }
    Ok(Linearization {
        stiffness: stiffness(model, q, t, &h)?,
        gyroscopic: h.qv.transpose() - &h.qv,
        mass: h.vv,
        damping,
    })
}

/// The balance of forces at rest, ∂L/∂q(q, 0, t) + Q(q, 0, t) = 0, in q.
struct Balance<'a> {
    model: &'a dyn Lagrangian,
    q: Vec<f64>,
    zeros: Vec<f64>,
    force: Vec<f64>,
    t: f64,
}

impl NewtonProblem for Balance<'_> {
    const REASONS: Reasons = Reasons {
        singular: "the stiffness K is singular: the equilibrium is not isolated (a symmetry's direction?)",
        non_finite_start: "the generalized force is non-finite at the guess",
        non_finite: "the generalized force became non-finite",
        not_converged: "Newton on the generalized force did not converge: no equilibrium near the guess",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        self.model.dl_dq(&self.q, &self.zeros, self.t, r)?;
        if self.model.is_forced() {
            self.model.force(&self.q, &self.zeros, self.t, &mut self.force)?;
            r.iter_mut().zip(&self.force).for_each(|(r, f)| *r += f);
        }
        Ok(())
    }

    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        let h = hessians(self.model, &self.q, self.t, false)?;
        jac.copy_from(&(-stiffness(self.model, &self.q, self.t, &h)?));
        Ok(())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        Correction::relative(&mut self.q, delta)
    }
}

/// An equilibrium found from a guess.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    pub q: Vec<f64>,
    /// ‖∂L/∂q + Q‖∞ there.
    pub residual: f64,
    pub iterations: usize,
}

/// The equilibrium of `model` at time t nearest `guess`: Newton on the generalized force at
/// rest, with the Jacobian −K (exact where the model supplies its Hessians).
///
/// # Errors
/// [`Error::Convergence`] (step 0, time t) with the residual where Newton fails: no equilibrium
/// near the guess, or a K singular there; the model's own.
pub fn equilibrium(
    model: &dyn Lagrangian,
    guess: &[f64],
    t: f64,
    options: &NewtonOptions,
) -> Result<Equilibrium, Error> {
    options.check()?;
    let n = guess.len();
    let mut balance = Balance {
        model,
        q: guess.to_vec(),
        zeros: vec![0.0; n],
        force: vec![0.0; n],
        t,
    };
    let rules = Rules {
        simplified: false,
        noise_floor: true,
    };
    let solution = Newton::new(n)
        .solve(&mut balance, options, rules)
        .map_err(|e| e.at(0, t))?;
    Ok(Equilibrium {
        q: balance.q,
        residual: solution.residual,
        iterations: solution.iterations,
    })
}

/// The normal modes of a linearization.
#[derive(Clone, Debug)]
pub struct Modes {
    /// ω of each mode, ascending: 0 for a zero mode and for a mode that grows without
    /// oscillating.
    pub frequencies: Vec<f64>,
    /// σ, the largest real part of each mode's eigenvalues λ = σ ± iω: 0 for a stable
    /// undamped mode, negative for a damped one, positive for one that grows.
    pub growth: Vec<f64>,
    /// The eigenvalues κ of K̄x = κMx, K̄ = (K + Kᵀ)/2, ascending: ω² of the modes where
    /// G = D = 0 and K is symmetric; their signs are K's inertia (a minimum of the potential
    /// where every κ > 0, whether or not G stabilizes a maximum).
    pub curvatures: Vec<f64>,
    /// How many κ are positive, zero (to `ZERO` relative) and negative.
    pub inertia: [usize; 3],
    /// The mode shapes, M-orthonormal columns in the order of `frequencies`, where G = D = 0
    /// and K is symmetric; else None (the modes of the quadratic eigenproblem are complex).
    pub shapes: Option<DMatrix<f64>>,
}

/// Relative size below which an entry of a linearization counts as zero: central differences
/// are accurate to about ε^{2/3} ≈ 4e-11.
const ZERO: f64 = 1e-8;

/// The normal modes of `linear`: the generalized symmetric eigenproblem K x = ω² M x where
/// G = D = 0 and K is symmetric (zero modes, κ = 0 to `ZERO` relative, have ω = σ = 0), else
/// the eigenvalues of the first-order system (δq, δq̇)' = [0 I; −M⁻¹K −M⁻¹(G + D)](δq, δq̇),
/// paired into modes: a complex pair σ ± iω is one mode, two real eigenvalues one mode (the
/// larger its σ).
///
/// # Errors
/// M not symmetric positive definite; a non-finite entry.
pub fn modes(linear: &Linearization) -> Result<Modes, ModelError> {
    let Linearization {
        mass,
        stiffness,
        gyroscopic,
        damping,
    } = linear;
    let n = mass.nrows();
    let finite = |m: &DMatrix<f64>| m.iter().all(|x| x.is_finite());
    if ![mass, stiffness, gyroscopic, damping].into_iter().all(finite) {
        return Err(
            "the linearization has non-finite entries: the model's second derivatives are not finite at q".into(),
        );
    }
    let size = |m: &DMatrix<f64>| m.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let cholesky = mass
        .clone()
        .cholesky()
        .ok_or("the mass matrix M = ∂²L/∂q̇² is not positive definite at q")?;
    let scale = size(stiffness);
    let symmetric = (stiffness - stiffness.transpose())
        .iter()
        .all(|x| x.abs() <= ZERO * scale);
    let first_order = size(gyroscopic).max(size(damping));
    // L⁻¹K̄L⁻ᵀ y = κ y, x = L⁻ᵀy: M-orthonormal shapes.
    let l = cholesky.l();
    let inverse = l.clone().try_inverse().ok_or("the mass matrix M is singular")?;
    let reduced = &inverse * ((stiffness + stiffness.transpose()) * 0.5) * inverse.transpose();
    let eigen = SymmetricEigen::new(reduced);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let largest = eigen.eigenvalues.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let curvatures: Vec<f64> = order.iter().map(|&k| eigen.eigenvalues[k]).collect();
    let zero = |k: f64| k.abs() <= ZERO * largest;
    let inertia = [
        curvatures.iter().filter(|&&k| k > 0.0 && !zero(k)).count(),
        curvatures.iter().filter(|&&k| zero(k)).count(),
        curvatures.iter().filter(|&&k| k < 0.0 && !zero(k)).count(),
    ];
    if symmetric && first_order <= ZERO * scale.max(size(mass)) {
        let unsorted = inverse.transpose() * &eigen.eigenvectors;
        let shapes = DMatrix::from_fn(n, n, |i, j| unsorted[(i, order[j])]);
        return Ok(Modes {
            frequencies: curvatures
                .iter()
                .map(|&k| if zero(k) { 0.0 } else { k.max(0.0).sqrt() })
                .collect(),
            growth: curvatures
                .iter()
                .map(|&k| if zero(k) { 0.0 } else { (-k).max(0.0).sqrt() })
                .collect(),
            curvatures,
            inertia,
            shapes: Some(shapes),
        });
    }
    let mut system = DMatrix::zeros(2 * n, 2 * n);
    let solve = |b: &DMatrix<f64>| cholesky.solve(b);
    system.view_mut((0, n), (n, n)).fill_with_identity();
    system.view_mut((n, 0), (n, n)).copy_from(&(-solve(stiffness)));
    system
        .view_mut((n, n), (n, n))
        .copy_from(&(-solve(&(gyroscopic + damping))));
    let eigenvalues =
        eigenvalues(system).ok_or("the eigenvalues of the linearized first-order system did not converge")?;
    let rate = eigenvalues.iter().fold(0.0_f64, |a, z| a.max(z.norm()));
    let tiny = ZERO * rate;
    let mut pairs: Vec<(f64, f64)> = eigenvalues
        .iter()
        .filter(|z| z.im > tiny)
        .map(|z| (z.im, if z.re.abs() <= tiny { 0.0 } else { z.re }))
        .collect();
    let mut real: Vec<f64> = eigenvalues
        .iter()
        .filter(|z| z.im.abs() <= tiny)
        .map(|z| if z.re.abs() <= tiny { 0.0 } else { z.re })
        .collect();
    real.sort_by(|a, b| b.total_cmp(a));
    pairs.extend(real.chunks(2).map(|pair| (0.0, pair[0])));
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    Ok(Modes {
        frequencies: pairs.iter().map(|p| p.0).collect(),
        growth: pairs.iter().map(|p| p.1).collect(),
        curvatures,
        inertia,
        shapes: None,
    })
}

/// The eigenvalues of a real square matrix by the shifted QR (Schur) iteration, capped: its
/// symmetric structure can stall the iteration (a gyroscopic system's ±σ ± iω), which a
/// similarity by a fixed shear breaks without moving the eigenvalues.
fn eigenvalues(a: DMatrix<f64>) -> Option<Vec<nalgebra::Complex<f64>>> {
    let cap = 1000;
    if let Some(schur) = Schur::try_new(a.clone(), f64::EPSILON, cap) {
        return Some(schur.complex_eigenvalues().iter().copied().collect());
    }
    let n = a.nrows();
    let shear = DMatrix::from_fn(n, n, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Equal => 1.0,
        std::cmp::Ordering::Less => 0.5_f64.powi((j - i) as i32),
        std::cmp::Ordering::Greater => 0.0,
    });
    let inverse = shear.clone().try_inverse()?;
    Schur::try_new(shear * a * inverse, f64::EPSILON, cap).map(|s| s.complex_eigenvalues().iter().copied().collect())
}

/// The largest stable step of `method` on frequencies up to `omega_max`: hω_max < c, c the
/// method's limit on q̈ = −ω²q ([`crate::integrators::MethodInfo::h_omega_max`]); infinite
/// for an unconditionally stable method or ω_max = 0.
///
/// # Errors
/// A method that does not integrate the oscillator (the Wisdom–Holman methods), or never is
/// stable on it (explicit Euler); ω_max not finite and ≥ 0.
pub fn stable_step(method: Method, omega_max: f64) -> Result<f64, Error> {
    if !(omega_max.is_finite() && omega_max >= 0.0) {
        return Err(Error::invalid(
            "omega_max",
            format!("must be finite and ≥ 0, got {omega_max}"),
        ));
    }
    let info = method.info();
    if info.h_omega_max.is_nan() || info.h_omega_max <= 0.0 {
        return Err(Error::invalid(
            "method",
            format!(
                "{} has no stable step on an oscillator (its linear stability limit hω < {})",
                info.name, info.h_omega_max
            ),
        ));
    }
    Ok(if omega_max == 0.0 {
        f64::INFINITY
    } else {
        info.h_omega_max / omega_max
    })
}

/// The phase error per period of `method` on q̈ = −q at the step x (= hω): 2π|θ/x − 1|, θ the
/// angle its one-step map turns the oscillator's state by (the argument of its eigenvalues);
/// infinite where the map has real eigenvalues (unstable).
///
/// # Errors
/// The method's own on the oscillator.
pub fn phase_error(method: Method, x: f64) -> Result<f64, Error> {
    let oscillator = HarmonicOscillator::new(1.0)?;
    let options = Options {
        max_energy_error: None,
        ..Options::new(x, 1)
    };
    let mut map = [[0.0; 2]; 2];
    for (k, (q0, p0)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
        let traj = integrate(&oscillator, method, &[q0], &[p0], &options, || Ok(())).map_err(|f| f.error)?;
        let last = traj.len() - 1;
        map[0][k] = traj.q_at(last)[0];
        map[1][k] = traj.p_at(last)[0];
    }
    let half_trace = 0.5 * (map[0][0] + map[1][1]);
    let det = map[0][0] * map[1][1] - map[0][1] * map[1][0];
    let discriminant = det - half_trace * half_trace;
    if discriminant <= 0.0 {
        return Ok(f64::INFINITY);
    }
    let theta = discriminant.sqrt().atan2(half_trace);
    Ok(std::f64::consts::TAU * (theta / x - 1.0).abs())
}

/// The largest step of `method` whose phase error per period ([`phase_error`]) on frequencies
/// up to `omega_max` is at most `accuracy` (radians a period), within its stable step: the
/// error grows as x^p, p the method's order, so the step is bracketed downward from the limit
/// and bisected to 1e-6 relative.
///
/// # Errors
/// As [`stable_step`]; `accuracy` not finite and positive.
pub fn accurate_step(method: Method, omega_max: f64, accuracy: f64) -> Result<f64, Error> {
    if !(accuracy.is_finite() && accuracy > 0.0) {
        return Err(Error::invalid(
            "accuracy",
            format!("must be finite and positive, got {accuracy}"),
        ));
    }
    let stable = stable_step(method, omega_max)?;
    if omega_max == 0.0 {
        return Ok(f64::INFINITY);
    }
    // x below the first resonance hω = π, where the angle's branch is ambiguous.
    let limit = (stable * omega_max).min(std::f64::consts::PI) * (1.0 - 1e-9);
    let within = |x: f64| phase_error(method, x).map(|e| e <= accuracy);
    if within(limit)? {
        return Ok(limit / omega_max);
    }
    let mut high = limit;
    let mut low = 0.5 * high;
    while !within(low)? {
        high = low;
        low *= 0.5;
        if low < 1e-12 {
            return Err(Error::invalid(
                "accuracy",
                format!("{accuracy:e} a period is below {}'s round-off", method.info().name),
            ));
        }
    }
    while high - low > 1e-6 * low {
        let mid = 0.5 * (low + high);
        if within(mid)? {
            low = mid;
        } else {
            high = mid;
        }
    }
    Ok(low / omega_max)
}
