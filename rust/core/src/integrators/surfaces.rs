//! Surfaces φ(q) ≥ 0, which contacts ([`super::Contact`]) and the native events share: the
//! [`Surface`] trait, and the native surfaces, evaluated in Rust with the arithmetic of the
//! native events [`crate::integrators::NativeEvent::Crossing`] and `::Ellipsoid`, which call
//! the same functions, so that a contact and its event agree to the bit.

use crate::ModelError;

/// A unilateral constraint's function φ(q) ≥ 0 (positive on the allowed side) and its gradient.
///
/// The binding implements it with Python callables, whose exceptions come back as the
/// [`ModelError`] unchanged.
pub trait Surface {
    /// φ(q).
    fn phi(&self, q: &[f64]) -> Result<f64, ModelError>;

    /// Writes ∇φ(q) into `out` (n entries).
    fn gradient(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError>;

    /// Why the surface cannot act on n coordinates, if it cannot (a native surface's
    /// coordinates out of range). By default it can.
    fn misfit(&self, _n: usize) -> Option<String> {
        None
    }

    /// The surface as a native one, which a run evaluates after every step without dispatch
    /// ([`super::Gaps`]); None (the default) for the others.
    fn native(&self) -> Option<&NativeSurface> {
        None
    }
}

/// A native surface φ(q) ≥ 0.
#[derive(Clone, Debug, PartialEq)]
pub enum NativeSurface {
    /// φ = q_k − value: the wall q_k ≥ value (a floor, a side of a box).
    Wall { coordinate: usize, value: f64 },
    /// φ = s(1 − Σᵢ ((q_{kᵢ} − cᵢ)/aᵢ)²), kᵢ the `coordinates`, c the `centre`, a the
    /// `semi_axes`, s = +1 `inside` (a billiard table) and −1 outside (an obstacle).
    Ellipsoid {
        coordinates: Vec<usize>,
        centre: Vec<f64>,
        semi_axes: Vec<f64>,
        inside: bool,
    },
}

/// φ = q_k − value.
#[inline]
pub(crate) fn wall(q: &[f64], coordinate: usize, value: f64) -> f64 {
    q[coordinate] - value
}

/// φ = s(1 − Σᵢ uᵢ²), uᵢ = (q_{kᵢ} − cᵢ)/aᵢ, summed in the order of the coordinates from 0.
#[inline]
pub(crate) fn ellipsoid(q: &[f64], coordinates: &[usize], centre: &[f64], semi_axes: &[f64], inside: bool) -> f64 {
    let sum = coordinates
        .iter()
        .zip(centre)
        .zip(semi_axes)
        .fold(0.0, |s, ((&k, c), a)| {
            let u = (q[k] - c) / a;
            s + u * u
        });
    if inside {
        1.0 - sum
    } else {
        sum - 1.0
    }
}

/// Why an ellipsoid cannot act on n coordinates, if it cannot: coordinates, centre and semi-axes
/// empty or of unequal lengths, a coordinate out of range, a centre not finite or a semi-axis
/// not finite and positive.
pub(crate) fn check_ellipsoid(coordinates: &[usize], centre: &[f64], semi_axes: &[f64], n: usize) -> Option<String> {
    let m = coordinates.len();
    if m == 0 || centre.len() != m || semi_axes.len() != m {
        return Some(format!(
            "coordinates, centre and semi_axes must be non-empty and of equal length, got {m}, {} and {}",
            centre.len(),
            semi_axes.len()
        ));
    }
    if let Some(k) = coordinates.iter().find(|&&k| k >= n) {
        return Some(format!("coordinate {k} is not in 0 … {}", n.saturating_sub(1)));
    }
    if let Some(c) = centre.iter().find(|c| !c.is_finite()) {
        return Some(format!("centre must be finite, got {c}"));
    }
    semi_axes
        .iter()
        .find(|a| !(a.is_finite() && **a > 0.0))
        .map(|a| format!("semi-axis must be finite and positive, got {a}"))
}

impl NativeSurface {
    /// φ(q), which a native surface always has.
    #[inline(always)]
    pub(crate) fn value(&self, q: &[f64]) -> f64 {
        match self {
            NativeSurface::Wall { coordinate, value } => wall(q, *coordinate, *value),
            NativeSurface::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                inside,
            } => ellipsoid(q, coordinates, centre, semi_axes, *inside),
        }
    }
}

impl Surface for NativeSurface {
    #[inline(always)]
    fn phi(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(self.value(q))
    }

    /// ∇φ: the unit vector e_k of the wall; −2s uᵢ/aᵢ in coordinate kᵢ of the ellipsoid.
    fn gradient(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        out.fill(0.0);
        match self {
            NativeSurface::Wall { coordinate, .. } => out[*coordinate] = 1.0,
            NativeSurface::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                inside,
            } => {
                let s = if *inside { -2.0 } else { 2.0 };
                for ((&k, c), a) in coordinates.iter().zip(centre).zip(semi_axes) {
                    out[k] += s * (q[k] - c) / (a * a);
                }
            }
        }
        Ok(())
    }

    fn misfit(&self, n: usize) -> Option<String> {
        match self {
            NativeSurface::Wall { coordinate, value } => {
                if *coordinate >= n {
                    Some(format!("coordinate {coordinate} is not in 0 … {}", n.saturating_sub(1)))
                } else if !value.is_finite() {
                    Some(format!("value must be finite, got {value}"))
                } else {
                    None
                }
            }
            NativeSurface::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                ..
            } => check_ellipsoid(coordinates, centre, semi_axes, n),
        }
    }

    fn native(&self) -> Option<&NativeSurface> {
        Some(self)
    }
}
