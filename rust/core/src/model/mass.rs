use nalgebra::{DMatrix, DVector};

use crate::Error;

/// A constant symmetric positive-definite mass matrix M.
#[derive(Clone, Debug, PartialEq)]
pub enum Mass {
    /// M = m·I.
    Scalar(f64),
    /// M = diag(m₁, …, mₙ), stored with the reciprocals that the drifts multiply by.
    Diagonal { m: DVector<f64>, inverse: DVector<f64> },
    /// A full matrix, stored with its inverse so that M⁻¹p costs one matrix–vector product.
    Full {
        matrix: DMatrix<f64>,
        inverse: DMatrix<f64>,
    },
}

impl Mass {
    /// M = m·I with m > 0.
    pub fn scalar(m: f64) -> Result<Self, Error> {
        if !(m.is_finite() && m > 0.0) {
            return Err(Error::invalid("mass", format!("must be finite and positive, got {m}")));
        }
        Ok(Mass::Scalar(m))
    }

    /// M = diag(m) with every mᵢ > 0.
    pub fn diagonal(m: Vec<f64>) -> Result<Self, Error> {
        if let Some(i) = m.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(Error::invalid(
                "mass",
                format!("entry {i} must be finite and positive, got {}", m[i]),
            ));
        }
        let m = DVector::from_vec(m);
        Ok(Mass::Diagonal {
            inverse: m.map(|x| 1.0 / x),
            m,
        })
    }

    /// A full matrix; it must be symmetric (to 1e-12 relative) and positive definite.
    pub fn full(matrix: DMatrix<f64>) -> Result<Self, Error> {
        if !matrix.is_square() {
            return Err(Error::invalid(
                "mass",
                format!("must be square, got {}×{}", matrix.nrows(), matrix.ncols()),
            ));
        }
        if matrix.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid("mass", "has non-finite entries"));
        }
        let scale = matrix.amax();
        if (&matrix - matrix.transpose()).amax() > 1e-12 * scale {
            return Err(Error::invalid("mass", "must be symmetric"));
        }
        let chol = matrix
            .clone()
            .cholesky()
            .ok_or_else(|| Error::invalid("mass", "must be positive definite"))?;
        Ok(Mass::Full {
            inverse: chol.inverse(),
            matrix,
        })
    }

    /// The dimension this mass fixes, if any (a scalar mass fits every dimension).
    pub fn dim(&self) -> Option<usize> {
        match self {
            Mass::Scalar(_) => None,
            Mass::Diagonal { m, .. } => Some(m.len()),
            Mass::Full { matrix, .. } => Some(matrix.nrows()),
        }
    }

    /// The drift of a splitting method in one pass: δq ← δq + c·M⁻¹p, then q̃ = q + δq (the
    /// position the next force is evaluated at); allocation-free.
    #[inline(always)]
    pub fn drift(&self, c: f64, p: &[f64], q: &[f64], dq: &mut [f64], q_stage: &mut [f64]) {
        // Indexed over slices cut to one length, so that the bounds checks fold away and a
        // step loop of known length unrolls.
        let n = p.len();
        let (q, dq, q_stage) = (&q[..n], &mut dq[..n], &mut q_stage[..n]);
        match self {
            // p/1 is p to the bit: unit masses skip the division.
            Mass::Scalar(m) if *m == 1.0 => {
                for i in 0..n {
                    dq[i] += c * p[i];
                    q_stage[i] = q[i] + dq[i];
                }
            }
            Mass::Scalar(m) => {
                for i in 0..n {
                    dq[i] += c * (p[i] / m);
                    q_stage[i] = q[i] + dq[i];
                }
            }
            Mass::Diagonal { inverse, .. } => {
                let w = &inverse.as_slice()[..n];
                for i in 0..n {
                    dq[i] += c * (w[i] * p[i]);
                    q_stage[i] = q[i] + dq[i];
                }
            }
            Mass::Full { inverse, .. } => {
                for i in 0..n {
                    let v: f64 = p.iter().enumerate().map(|(j, pj)| inverse[(i, j)] * pj).sum();
                    dq[i] += c * v;
                    q_stage[i] = q[i] + dq[i];
                }
            }
        }
    }

    /// v = M⁻¹p.
    #[inline]
    pub fn velocity(&self, p: &[f64], v: &mut [f64]) {
        match self {
            Mass::Scalar(m) => v.iter_mut().zip(p).for_each(|(vi, pi)| *vi = pi / m),
            Mass::Diagonal { inverse, .. } => {
                for ((vi, pi), wi) in v.iter_mut().zip(p).zip(inverse.as_slice()) {
                    *vi = wi * pi;
                }
            }
            Mass::Full { inverse, .. } => {
                for (i, vi) in v.iter_mut().enumerate() {
                    *vi = p.iter().enumerate().map(|(j, pj)| inverse[(i, j)] * pj).sum();
                }
            }
        }
    }

    /// p = M v.
    pub fn momentum(&self, v: &[f64], p: &mut [f64]) {
        match self {
            Mass::Scalar(m) => p.iter_mut().zip(v).for_each(|(pi, vi)| *pi = m * vi),
            Mass::Diagonal { m, .. } => {
                for ((pi, vi), mi) in p.iter_mut().zip(v).zip(m.as_slice()) {
                    *pi = mi * vi;
                }
            }
            Mass::Full { matrix, .. } => {
                for (i, pi) in p.iter_mut().enumerate() {
                    *pi = v.iter().enumerate().map(|(j, vj)| matrix[(i, j)] * vj).sum();
                }
            }
        }
    }

    /// T = ½ pᵀ M⁻¹ p.
    pub fn kinetic_energy(&self, p: &[f64]) -> f64 {
        match self {
            Mass::Scalar(m) => 0.5 * p.iter().map(|x| x * x).sum::<f64>() / m,
            Mass::Diagonal { inverse, .. } => {
                0.5 * p.iter().zip(inverse.as_slice()).map(|(x, wi)| wi * x * x).sum::<f64>()
            }
            Mass::Full { inverse, .. } => 0.5 * quadratic_form(inverse, p),
        }
    }

    /// T = ½ vᵀ M v.
    pub fn kinetic_energy_of_velocity(&self, v: &[f64]) -> f64 {
        match self {
            Mass::Scalar(m) => 0.5 * m * v.iter().map(|x| x * x).sum::<f64>(),
            Mass::Diagonal { m, .. } => 0.5 * v.iter().zip(m.as_slice()).map(|(x, mi)| mi * x * x).sum::<f64>(),
            Mass::Full { matrix, .. } => 0.5 * quadratic_form(matrix, v),
        }
    }
}

/// xᵀ A x.
fn quadratic_form(a: &DMatrix<f64>, x: &[f64]) -> f64 {
    let x = nalgebra::DVectorView::from_slice(x, x.len());
    x.dot(&(a * x))
}
