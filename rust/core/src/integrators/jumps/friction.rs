//! Coulomb friction on a held contact: a force μ_k N opposing the slip of the contact point
//! while it slides, and a constraint on its slip while it sticks, kept as long as the force it
//! needs is at most μ_s N (N = λ|∇φ|, the normal force of the contact's multiplier λ).
//!
//! The slip is s = J(q)q̇, k rows J: the velocity of the contact point along the surface. A
//! particle's own coordinates (n = 2 or 3) need none given: J is then an orthonormal basis of
//! the tangent plane of ∇φ. A body that turns gives its rows (a ball of radius r on a floor,
//! slip ẋ − rθ̇: J = (1, 0, −r) in (x, y, θ)).

use crate::ModelError;

/// The slip of a contact point, s = J(q)q̇.
#[derive(Clone, Debug, PartialEq)]
pub enum Slip {
    /// A particle's own coordinates (n = 2 or 3): J an orthonormal basis of the tangent plane
    /// of ∇φ(q).
    Tangent,
    /// Constant rows J, k × n, row by row.
    Rows { rows: usize, jacobian: Vec<f64> },
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
            _ => None,
        }
    }

    /// k, the slip's rows on n coordinates.
    pub(super) fn rows(&self, n: usize) -> usize {
        match &self.slip {
            Slip::Tangent => n - 1,
            Slip::Rows { rows, .. } => *rows,
        }
    }

    /// J at a state where the surface's gradient is `gradient`, into `out` (k × n).
    pub(super) fn jacobian(&self, gradient: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let gradient = match &self.slip {
            Slip::Rows { jacobian, .. } => {
                out.copy_from_slice(jacobian);
                return Ok(());
            }
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
