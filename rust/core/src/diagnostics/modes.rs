//! Small oscillations: an equilibrium (Newton on the generalized force at rest, with the
//! constraints' multipliers), the linearized equations there,
//!
//! M δq̈ + (G + D) δq̇ + K δq = 0,   M = ∂²L/∂q̇²,  K = −∂²L/∂q² − ∂Q/∂q − Σᵢλᵢ∇²gᵢ,
//! G = ∂²L/∂q̇∂q − ∂²L/∂q∂q̇ (antisymmetric: magnetic fields, rotating frames),  D = −∂Q/∂q̇,
//!
//! all at (q, q̇ = 0, t), Q the model's own forces, λ the multipliers that hold q at rest on
//! holonomic constraints g(q) = 0 ([`Rest`]), each matrix restricted to the tangent space ker G(q)
//! (δq = T y, T an orthonormal basis: the fewest coordinates); their normal modes, real or complex,
//! the zero modes along the model's symmetries named; and the largest step a method takes on
//! them, stably (hω_max below the method's limit) or to a phase accuracy.
//!
//! A Routh-reduced model's Lagrangian is its Routhian, whose potential is the amended one: its
//! equilibria are the full model's relative equilibria (steady motions), its G their Coriolis
//! coupling.

use nalgebra::{Complex, DMatrix, DVector, Schur, SymmetricEigen};

use crate::error::StepError;
use crate::integrators::{integrate, Dynamics, Method, Options};
use crate::model::{reaction_force, Fastest, ForceAtRest, Hessians, HolonomicConstraints, Lagrangian, Rest};
use crate::scenes::HarmonicOscillator;
use crate::solve::bracket::bisect;
use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::solve::newton::{Correction, Newton, NewtonProblem, Reasons, Rules};
use crate::solve::NewtonOptions;
use crate::{Error, ModelError};

/// A model at a point: its Lagrangian and, if it has them, its holonomic constraints.
#[derive(Clone, Copy)]
pub struct Model<'a> {
    pub system: &'a dyn Lagrangian,
    pub constraints: Option<&'a dyn HolonomicConstraints>,
}

impl<'a, L: Lagrangian + 'a> From<&'a L> for Model<'a> {
    fn from(system: &'a L) -> Self {
        Model {
            system,
            constraints: None,
        }
    }
}

impl<'a> Model<'a> {
    /// A run's model: its Lagrangian and holonomic constraints.
    ///
    /// # Errors
    /// Velocity constraints, whose small oscillations are not those of a Lagrangian on a
    /// manifold (named `model`).
    pub fn of(dynamics: &'a dyn Dynamics) -> Result<Self, Error> {
        if dynamics.velocity_constraints().is_some() {
            return Err(Error::invalid(
                "model",
                "velocity constraints A(q)q̇ = 0 restrict the velocities but not the positions: a \
                 nonholonomic model's equilibria come in families and its small oscillations are not a \
                 Lagrangian's on a manifold; linearize a model of its holonomic part",
            ));
        }
        Ok(Model {
            system: dynamics.as_lagrangian(),
            constraints: dynamics.holonomic(),
        })
    }

    /// The fastest frequency of the small oscillations at (q, t) ([`Rest::fastest`]): what bounds
    /// a method's step, from [`Rest::BEFORE_RUN`] force evaluations at most.
    ///
    /// # Errors
    /// The model's own.
    pub fn fastest(&self, q: &[f64], t: f64) -> Result<Fastest, ModelError> {
        Rest::new(self.system, self.constraints, q, t)?.fastest(Rest::BEFORE_RUN)
    }
}

/// The linearized equations at a point in the tangent coordinates y (δq = T y): r × r each,
/// r = n − rank G (n without constraints, T = I).
#[derive(Clone, Debug)]
pub struct Linearization {
    /// M = Tᵀ ∂²L/∂q̇² T.
    pub mass: DMatrix<f64>,
    /// K = Tᵀ(−∂²L/∂q² − ∂Q/∂q − Σλᵢ∇²gᵢ)T (symmetric but for circulatory forces).
    pub stiffness: DMatrix<f64>,
    /// G = Tᵀ(∂²L/∂q̇∂q − ∂²L/∂q∂q̇)T, antisymmetric.
    pub gyroscopic: DMatrix<f64>,
    /// D = −Tᵀ ∂Q/∂q̇ T (zero for a model without forces).
    pub damping: DMatrix<f64>,
    /// T, n × r: orthonormal columns spanning ker G(q).
    pub basis: DMatrix<f64>,
    /// λ at rest (Lagrange's sign: ṗ = ∂L/∂q + Q + Gᵀλ); empty without constraints.
    pub multipliers: Vec<f64>,
    /// The point, q.
    pub q: Vec<f64>,
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

/// K = −∂²L/∂q² − ∂Q/∂q − Σλᵢ∇²gᵢ at (q, 0, t) in q's coordinates, ∂²L/∂q² from `h`, the rest
/// by central differences (of Q, and of G(x)ᵀλ).
fn stiffness(model: Model<'_>, q: &[f64], t: f64, h: &Hessians, lambda: &[f64]) -> Result<DMatrix<f64>, ModelError> {
    let system = model.system;
    let (n, zeros) = (q.len(), vec![0.0; q.len()]);
    let mut k = -&h.qq;
    let mut dq = DMatrix::zeros(n, n);
    if system.is_forced() {
        differenced(|x, out| system.force(x, &zeros, t, out), q, &mut dq)?;
        k -= &dq;
    }
    if let Some(c) = model.constraints {
        let mut g = DMatrix::zeros(c.count(), n);
        differenced(|x, out| reaction_force(c, x, lambda, &mut g, out), q, &mut dq)?;
        k -= dq;
    }
    Ok(k)
}

/// The linearized equations of `model` at (q, q̇ = 0, t) ([`Linearization`]), on its constraints'
/// tangent space where it has constraints.
///
/// # Errors
/// The model's own; dependent constraints at q.
pub fn linearize(model: Model<'_>, q: &[f64], t: f64) -> Result<Linearization, ModelError> {
    let (system, n) = (model.system, q.len());
    let rest = Rest::new(system, model.constraints, q, t)?;
    let h = hessians(system, q, t, true)?;
    let mut damping = DMatrix::zeros(n, n);
    if system.is_forced() {
        let zeros = vec![0.0; n];
        differenced(|v, out| system.force(q, v, t, out), &zeros, &mut damping)?;
        damping.neg_mut();
    }
    let basis = rest.tangent();
    let restrict = |a: &DMatrix<f64>| basis.transpose() * a * &basis;
    Ok(Linearization {
        stiffness: restrict(&stiffness(model, q, t, &h, rest.multipliers())?),
        gyroscopic: restrict(&(h.qv.transpose() - &h.qv)),
        mass: restrict(&h.vv),
        damping: restrict(&damping),
        multipliers: rest.multipliers().to_vec(),
        basis,
        q: q.to_vec(),
    })
}

/// The balance of forces at rest on the constraints, in (q, λ):
/// ∂L/∂q(q, 0, t) + Q(q, 0, t) + G(q)ᵀλ = 0 and g(q) = 0.
struct Balance<'a> {
    model: Model<'a>,
    q: Vec<f64>,
    lambda: Vec<f64>,
    force: ForceAtRest,
    g: DMatrix<f64>,
    t: f64,
    /// (q, λ) where the iteration started.
    guess: (Vec<f64>, Vec<f64>),
}

impl NewtonProblem for Balance<'_> {
    const REASONS: Reasons = Reasons {
        singular: "the stiffness K is singular: the equilibrium is not isolated (a symmetry's direction?)",
        non_finite_start: "the generalized force is non-finite at the guess",
        non_finite: "the generalized force became non-finite",
        not_converged: "Newton on the generalized force did not converge: no equilibrium near the guess",
        outside: "the guess lies outside the region where Newton's iteration converges: start nearer the \
                  equilibrium",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        let Model { system, constraints } = self.model;
        let (balance, on) = r.split_at_mut(self.q.len());
        self.force
            .evaluate(system, constraints, (&self.q, self.t), &self.lambda, balance)?;
        if let Some(c) = constraints {
            c.residual(&self.q, on)?;
        }
        Ok(())
    }

    /// [−K G(q)ᵀ; G(q) 0], K the stiffness on the constraints at the current λ.
    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        let n = self.q.len();
        let h = hessians(self.model.system, &self.q, self.t, false)?;
        let k = stiffness(self.model, &self.q, self.t, &h, &self.lambda)?;
        jac.fill(0.0);
        jac.view_mut((0, 0), (n, n)).copy_from(&(-k));
        if let Some(c) = self.model.constraints {
            c.jacobian(&self.q, &mut self.g)?;
            jac.view_mut((0, n), (n, self.lambda.len()))
                .copy_from(&self.g.transpose());
            jac.view_mut((n, 0), (self.lambda.len(), n)).copy_from(&self.g);
        }
        Ok(())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        let (dq, dl) = delta.split_at(self.q.len());
        let (a, b) = (
            Correction::relative(&mut self.q, dq),
            Correction::relative(&mut self.lambda, dl),
        );
        Correction {
            size: a.size.max(b.size),
            scale: 1.0,
        }
    }

    /// Back to the guess.
    fn restart(&mut self) {
        self.q.copy_from_slice(&self.guess.0);
        self.lambda.copy_from_slice(&self.guess.1);
    }

    /// Whether [−K Gᵀ; G 0] from the model's own ∂²L/∂q² agrees with differences of the balance
    /// in (q, λ): a model that supplies no Hessians agrees by construction.
    fn jacobian_agrees(&mut self) -> Result<bool, StepError> {
        let (n, u) = (self.q.len(), self.q.len() + self.lambda.len());
        if !self
            .model
            .system
            .hessians(&self.q, &vec![0.0; n], self.t, &mut Hessians::zeros(n))?
        {
            return Ok(true);
        }
        let (mut exact, mut differenced) = (DMatrix::zeros(u, u), DMatrix::zeros(u, u));
        self.jacobian(&mut exact)?;
        let (q, lambda) = (self.q.clone(), self.lambda.clone());
        let mut x: Vec<f64> = q.iter().chain(&lambda).copied().collect();
        let (mut plus, mut minus) = (vec![0.0; u], vec![0.0; u]);
        let at = Evaluations {
            plus: &mut plus,
            minus: &mut minus,
        };
        let balance = |x: &[f64], r: &mut [f64]| {
            self.q.copy_from_slice(&x[..n]);
            self.lambda.copy_from_slice(&x[n..]);
            self.residual(r)
        };
        let done = central_jacobian(balance, &mut x, unit, at, &mut differenced);
        (self.q, self.lambda) = (q, lambda);
        done?;
        Ok((&exact - &differenced).amax() <= 1e-4 * differenced.amax())
    }

    /// Not known beyond what the iteration adds ([`NewtonProblem::noise`]).
    fn noise(&self) -> f64 {
        0.0
    }
}

/// The multipliers that best balance the force at the guess, min ‖F + Gᵀλ‖ (GGᵀλ = −GF): the
/// Newton iteration's start, where λ = 0 would leave a potential linear in q (gravity) a
/// singular Jacobian.
fn least_squares_multipliers(balance: &mut Balance<'_>) -> Result<Vec<f64>, StepError> {
    let (n, m) = (balance.q.len(), balance.lambda.len());
    let mut r = vec![0.0; n + m];
    balance.residual(&mut r)?;
    let Some(c) = balance.model.constraints else {
        return Ok(Vec::new());
    };
    c.jacobian(&balance.q, &mut balance.g)?;
    let g = &balance.g;
    let rhs = -(g * DVector::from_column_slice(&r[..n]));
    let lambda = (g * g.transpose())
        .lu()
        .solve(&rhs)
        .ok_or_else(|| StepError::Model("the constraints' Jacobian G has dependent rows at the guess".into()))?;
    Ok(lambda.iter().copied().collect())
}

/// An equilibrium found from a guess.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    pub q: Vec<f64>,
    /// λ there (Lagrange's sign); empty without constraints.
    pub multipliers: Vec<f64>,
    /// ‖(∂L/∂q + Q + Gᵀλ, g)‖∞ there.
    pub residual: f64,
    pub iterations: usize,
}

/// The equilibrium of `model` at time t nearest `guess`: Newton on the generalized force at
/// rest and, on constraints, on g(q) = 0 with the multipliers λ (a guess off the constraints
/// is brought onto them), with the Jacobian [−K Gᵀ; G 0] (∂²L/∂q² exact where the model
/// supplies its Hessians).
///
/// # Errors
/// [`Error::Convergence`] (step 0, time t) with the residual where Newton fails: no equilibrium
/// near the guess, or a K singular there; the model's own.
pub fn equilibrium(model: Model<'_>, guess: &[f64], t: f64, options: &NewtonOptions) -> Result<Equilibrium, Error> {
    options.check()?;
    let n = guess.len();
    let m = model.constraints.map_or(0, |c| c.count());
    let mut balance = Balance {
        model,
        q: guess.to_vec(),
        lambda: vec![0.0; m],
        force: ForceAtRest::new(n, m),
        g: DMatrix::zeros(m, n),
        t,
        guess: (Vec::new(), Vec::new()),
    };
    if m > 0 {
        balance.lambda = least_squares_multipliers(&mut balance).map_err(|e| e.at(0, t))?;
    }
    balance.guess = (balance.q.clone(), balance.lambda.clone());
    let rules = Rules { simplified: false };
    let solution = Newton::new(n + m)
        .solve(&mut balance, options, rules)
        .map_err(|e| e.at(0, t))?;
    Ok(Equilibrium {
        q: balance.q,
        multipliers: balance.lambda,
        residual: solution.residual,
        iterations: solution.iterations,
    })
}

/// The shapes of the modes, columns in q's coordinates (δq = x), in the order of the
/// frequencies.
#[derive(Clone, Debug)]
pub enum Shapes {
    /// G = D = 0 and K symmetric: real, M-orthonormal (xᵀMx = 1).
    Real(DMatrix<f64>),
    /// Otherwise: x with (λ²M + λ(G + D) + K)x = 0 at the mode's λ = σ + iω (the one of larger σ
    /// for a mode of two real λ), xᴴMx = 1, its largest entry real and positive.
    Complex(DMatrix<Complex<f64>>),
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
    pub shapes: Shapes,
    /// For each mode, the symmetry whose direction it is (an index into the fields given to
    /// [`Modes::name_symmetries`]): zero modes only; None until named.
    pub symmetries: Vec<Option<usize>>,
}

/// Relative size below which an entry of a linearization counts as zero: central differences
/// are accurate to about ε^{2/3} ≈ 4e-11.
const ZERO: f64 = 1e-8;

/// How far (relative, in M's norm) a symmetry's direction may be from the zero modes' span and
/// still be one of them: differenced second derivatives put the shapes about 1e-8 off.
const ALONG: f64 = 1e-6;

/// The normal modes of `linear`: the generalized symmetric eigenproblem K x = ω² M x where
/// G = D = 0 and K is symmetric (zero modes, κ = 0 to `ZERO` relative, have ω = σ = 0), else
/// the eigenvalues of the first-order system (y, ẏ)' = [0 I; −M⁻¹K −M⁻¹(G + D)](y, ẏ),
/// paired into modes: a complex pair σ ± iω is one mode, two real eigenvalues one mode (the
/// larger its σ), each shape the null vector of the quadratic pencil at its λ. Shapes are
/// returned in q's coordinates, x = T y.
///
/// # Errors
/// M not symmetric positive definite; a non-finite entry.
pub fn modes(linear: &Linearization) -> Result<Modes, ModelError> {
    let Linearization {
        mass,
        stiffness,
        gyroscopic,
        damping,
        basis,
        ..
    } = linear;
    let n = mass.nrows();
    let finite = |m: &DMatrix<f64>| m.iter().all(|x| x.is_finite());
    if ![mass, stiffness, gyroscopic, damping].into_iter().all(finite) {
        return Err(format!(
            "the linearization has non-finite entries: the model's second derivatives are not finite at q = {:?}",
            linear.q
        )
        .into());
    }
    let size = |m: &DMatrix<f64>| m.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let cholesky = mass.clone().cholesky().ok_or_else(|| {
        format!(
            "the mass matrix M = ∂²L/∂q̇² is not positive definite at q = {:?}",
            linear.q
        )
    })?;
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
            shapes: Shapes::Real(basis * shapes),
            symmetries: vec![None; n],
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
    let shapes = complex_shapes(linear, &pairs, tiny.max(f64::MIN_POSITIVE));
    Ok(Modes {
        frequencies: pairs.iter().map(|p| p.0).collect(),
        growth: pairs.iter().map(|p| p.1).collect(),
        curvatures,
        inertia,
        shapes: Shapes::Complex(basis.map(Complex::from) * shapes),
        symmetries: vec![None; n],
    })
}

/// The shape of each mode (ω, σ) of `pairs`: the right singular vector of the quadratic pencil
/// Q(λ) = λ²M + λ(G + D) + K at λ = σ + iω for its smallest singular value; the k-th mode of
/// a λ repeated (to `tiny`) takes the k-th smallest, so that a degenerate pair gets two
/// independent shapes. Normalized xᴴMx = 1, the largest entry real and positive.
fn complex_shapes(linear: &Linearization, pairs: &[(f64, f64)], tiny: f64) -> DMatrix<Complex<f64>> {
    let n = linear.mass.nrows();
    let c = |m: &DMatrix<f64>| m.map(Complex::from);
    let (mass, first, stiffness) = (
        c(&linear.mass),
        c(&(&linear.gyroscopic + &linear.damping)),
        c(&linear.stiffness),
    );
    let mut shapes = DMatrix::zeros(n, pairs.len());
    for (j, &(omega, sigma)) in pairs.iter().enumerate() {
        let lambda = Complex::new(sigma, omega);
        let repeat = pairs[..j]
            .iter()
            .filter(|p| (p.0 - omega).abs() <= tiny && (p.1 - sigma).abs() <= tiny)
            .count();
        let pencil = &mass * (lambda * lambda) + &first * lambda + &stiffness;
        let svd = pencil.svd(false, true);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]));
        let Some(v_t) = svd.v_t else { continue };
        let mut x: DVector<Complex<f64>> = v_t.row(order[repeat.min(n - 1)]).adjoint();
        let norm = (x.adjoint() * &mass * &x)[(0, 0)].re.max(0.0).sqrt();
        let big = x
            .iter()
            .copied()
            .fold(Complex::new(0.0, 0.0), |a, z| if z.norm() > a.norm() { z } else { a });
        if norm > 0.0 && big.norm() > 0.0 {
            x *= big.conj() / (big.norm() * norm);
        }
        shapes.column_mut(j).copy_from(&x);
    }
    shapes
}

impl Modes {
    /// Names the zero modes after the symmetries whose directions they are: `fields` are the
    /// generators ξ(q) of the model's symmetries at the point (n entries each, in q's
    /// coordinates). A ξ tangent to the constraints and within the zero modes' span (to
    /// `ALONG`) becomes a zero mode's shape, M-normalized (and M-orthogonalized against the
    /// earlier ones); the remaining zero modes span the rest of that space, unnamed. Only real
    /// shapes are named (G = D = 0).
    pub fn name_symmetries(&mut self, linear: &Linearization, fields: &[Vec<f64>]) {
        let Shapes::Real(shapes) = &mut self.shapes else {
            return;
        };
        let zero: Vec<usize> = (0..self.frequencies.len())
            .filter(|&k| self.frequencies[k] == 0.0 && self.growth[k] == 0.0)
            .collect();
        if zero.is_empty() {
            return;
        }
        let (t, mass) = (&linear.basis, &linear.mass);
        let inner = |a: &DVector<f64>, b: &DVector<f64>| (a.transpose() * mass * b)[(0, 0)];
        // The zero modes in tangent coordinates, y = Tᵀx (T orthonormal).
        let span: Vec<DVector<f64>> = zero.iter().map(|&k| t.transpose() * shapes.column(k)).collect();
        let mut named: Vec<(usize, DVector<f64>)> = Vec::new();
        for (g, xi) in fields.iter().enumerate() {
            let xi = DVector::from_column_slice(xi);
            let mut y = t.transpose() * &xi;
            let size = inner(&y, &y).sqrt();
            if size == 0.0 || (t * &y - &xi).norm() > ALONG * xi.norm() {
                continue;
            }
            let outside = span.iter().fold(y.clone(), |r, z| &r - z * inner(z, &y));
            if inner(&outside, &outside).sqrt() > ALONG * size {
                continue;
            }
            for (_, e) in &named {
                y -= e * inner(e, &y);
            }
            let norm = inner(&y, &y).sqrt();
            if norm > ALONG * size && named.len() < zero.len() {
                named.push((g, y / norm));
            }
        }
        if named.is_empty() {
            return;
        }
        let mut rest: Vec<DVector<f64>> = Vec::new();
        for z in &span {
            let mut y = z.clone();
            for e in named.iter().map(|(_, e)| e).chain(&rest) {
                y -= e * inner(e, &y);
            }
            let norm = inner(&y, &y).sqrt();
            if norm > ALONG && named.len() + rest.len() < zero.len() {
                rest.push(y / norm);
            }
        }
        let chosen = named
            .iter()
            .map(|(g, y)| (Some(*g), y))
            .chain(rest.iter().map(|y| (None, y)));
        for (&k, (symmetry, y)) in zero.iter().zip(chosen) {
            shapes.column_mut(k).copy_from(&(t * y));
            self.symmetries[k] = symmetry;
        }
    }
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
    // Without constraints RATTLE and SHAKE are Störmer–Verlet, and rattle4 Yoshida's triple
    // jump of it (whence their limits): their phase on the constraints' modes is theirs.
    let method = match method {
        Method::Rattle | Method::Shake => Method::Verlet,
        Method::Rattle4 => Method::Yoshida4,
        other => other,
    };
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
    let (low, _) = bisect(within, (low, high), usize::MAX, |low, high| high - low > 1e-6 * low)?;
    Ok(low / omega_max)
}
