//! Coulomb friction on a held contact: a force μ_k N opposing the slip of the contact point
//! while it slides, and a constraint on its slip while it sticks, kept as long as the force it
//! needs is at most μ_s N (N = λ|∇φ|, the normal force of the contact's multiplier λ).
//!
//! The slip is s = J(q)q̇, k rows J: the velocity of the contact point along the surface. A
//! particle's own coordinates (n = 2 or 3) need none given: J is then an orthonormal basis of
//! the tangent plane of ∇φ. A body that turns gives its rows (a ball of radius r on a floor,
//! slip ẋ − rθ̇: J = (1, 0, −r) in (x, y, θ)); rows that turn with q ([`SlipRows`]) are a
//! velocity constraint J(q)q̇ = 0 that holds while it sticks: a wheel rolling on its heading φ,
//! J = (1, 0, −r cos φ; 0, 1, −r sin φ) in (x, y, θ, …), skids where rolling needs more than μ_s N.

use std::sync::Arc;

use crate::solve::secular;
use crate::ModelError;

/// Slip rows J(q) that depend on the configuration, k × n: a velocity constraint J(q)q̇ = 0,
/// nonholonomic as a rolling wheel's, kept while the contact sticks.
pub trait SlipRows: Send + Sync {
    /// k, the number of rows.
    fn count(&self) -> usize;

    /// Writes J(q), k × n row by row, into `out`.
    fn jacobian(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError>;
}

/// The slip of a contact point, s = J(q)q̇.
#[derive(Clone)]
pub enum Slip {
    /// A particle's own coordinates (n = 2 or 3): J an orthonormal basis of the tangent plane
    /// of ∇φ(q).
    Tangent,
    /// Constant rows J, k × n, row by row.
    Rows { rows: usize, jacobian: Vec<f64> },
    /// Rows J(q) that turn with the configuration.
    Field(Arc<dyn SlipRows>),
}

impl std::fmt::Debug for Slip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Slip::Tangent => f.write_str("Tangent"),
            Slip::Rows { rows, jacobian } => f
                .debug_struct("Rows")
                .field("rows", rows)
                .field("jacobian", jacobian)
                .finish(),
            Slip::Field(field) => f
                .debug_struct("Field")
                .field("rows", &field.count())
                .finish_non_exhaustive(),
        }
    }
}

/// Rows given as functions are the same where they are the same functions.
impl PartialEq for Slip {
    fn eq(&self, other: &Slip) -> bool {
        match (self, other) {
            (Slip::Tangent, Slip::Tangent) => true,
            (Slip::Rows { rows, jacobian }, Slip::Rows { rows: r, jacobian: j }) => rows == r && jacobian == j,
            (Slip::Field(a), Slip::Field(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

/// Coulomb friction on a contact: the static coefficient μ_s ≥ μ_k, the kinetic μ_k ≥ 0, and
/// the slip whose rows they act along.
#[derive(Clone, Debug, PartialEq)]
pub struct Friction {
    pub static_coefficient: f64,
    pub kinetic: f64,
    pub slip: Slip,
}

impl Friction {
    /// Why the coefficients are not a friction law's, if they are not.
    pub(super) fn invalid(&self) -> Option<String> {
        let (s, k) = (self.static_coefficient, self.kinetic);
        if !(k.is_finite() && k >= 0.0) {
            return Some(format!("friction: mu_k must be a finite number ≥ 0, got {k}"));
        }
        if !(s.is_finite() && s >= k) {
            return Some(format!(
                "friction: mu_s must be finite and at least mu_k = {k}, got {s}"
            ));
        }
        None
    }

    /// Why the slip cannot act on n coordinates, if it cannot.
    pub(super) fn misfit(&self, n: usize) -> Option<String> {
        match &self.slip {
            Slip::Tangent if n != 2 && n != 3 => Some(format!(
                "friction without slip rows acts on a particle's own coordinates (2 or 3), not {n}: give the slip \
                 rows J, s = J(q)q̇ the velocity of the contact point along the surface"
            )),
            Slip::Rows { rows, jacobian } if *rows == 0 || jacobian.len() != rows * n => Some(format!(
                "friction: the slip rows must be k × {n} (k ≥ 1), got {} entries for {rows} rows",
                jacobian.len()
            )),
            Slip::Field(field) if field.count() == 0 => {
                Some("friction: the slip rows J(q) must number at least one".to_string())
            }
            _ => None,
        }
    }

    /// k, the slip's rows on n coordinates.
    pub(super) fn rows(&self, n: usize) -> usize {
        match &self.slip {
            Slip::Tangent => n - 1,
            Slip::Rows { rows, .. } => *rows,
            Slip::Field(field) => field.count(),
        }
    }

    /// Whether J turns with q of its own ([`Slip::Field`]): a stuck step holds it at its
    /// midpoint.
    #[inline]
    pub(super) fn turns(&self) -> bool {
        matches!(self.slip, Slip::Field(_))
    }

    /// Whether J is made of the surface's gradient ([`Self::jacobian`] reads it).
    #[inline]
    pub(super) fn on_gradient(&self) -> bool {
        matches!(self.slip, Slip::Tangent)
    }

    /// J at q, where the surface's gradient is `gradient` (read only [`Self::on_gradient`]),
    /// into `out` (k × n).
    pub(super) fn jacobian(&self, q: &[f64], gradient: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let gradient = match &self.slip {
            Slip::Rows { jacobian, .. } => {
                out.copy_from_slice(jacobian);
                return Ok(());
            }
            Slip::Field(field) => return field.jacobian(q, out),
            Slip::Tangent => gradient,
        };
        let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return Err("friction: the contact's ∇φ vanishes or is not finite, so it has no tangent plane".into());
        }
        let mut u = [0.0; 3];
        for (x, g) in u.iter_mut().zip(gradient) {
            *x = g / norm;
        }
        if gradient.len() == 2 {
            out.copy_from_slice(&[-u[1], u[0]]);
            return Ok(());
        }
        // n = 3: t₁ the axis least along u, made orthogonal to it; t₂ = u × t₁.
        let axis = (0..3)
            .min_by(|&i, &j| u[i].abs().total_cmp(&u[j].abs()))
            .expect("three axes");
        let mut t = [0.0; 3];
        for (i, x) in t.iter_mut().enumerate() {
            *x = f64::from(u8::from(i == axis)) - u[axis] * u[i];
        }
        let size = t.iter().map(|x| x * x).sum::<f64>().sqrt();
        t.iter_mut().for_each(|x| *x /= size);
        let cross = [
            u[1] * t[2] - u[2] * t[1],
            u[2] * t[0] - u[0] * t[2],
            u[0] * t[1] - u[1] * t[0],
        ];
        out[..3].copy_from_slice(&t);
        out[3..].copy_from_slice(&cross);
        Ok(())
    }
}

/// The direction ŝ of the slip s̃ (`slipped`, k entries) after a kick −cWŝ against itself, W =
/// JM⁻¹Jᵀ the slip's metric (`metric`, k × k; `factor` its scratch): ŝ = x/|x| with
/// x = (ρI + cW)⁻¹s̃ and |x| = 1, the slip after the kick ρŝ (ρ ≥ 0), by Moré and Sorensen's
/// secular equation ([`secular::direction`]); ρ = 0 where the kick stops the slip. A backward
/// kick (c < 0, a composition's backward substep) keeps s̃'s direction: its equation has a root
/// near each of W's eigenvectors once the slip is small. `direction` gets ŝ (0 for s̃ = 0);
/// `work` holds 2k entries.
pub(super) fn slip_after_kick(
    (metric, factor): (&[f64], &mut [f64]),
    slipped: &[f64],
    c: f64,
    (direction, work): (&mut [f64], &mut [f64]),
) {
    let size = slipped.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(size > 0.0 && c > 0.0 && c.is_finite()) {
        secular::unit(direction, slipped);
        return;
    }
    secular::direction((metric, c), slipped, factor, (direction, work));
}
