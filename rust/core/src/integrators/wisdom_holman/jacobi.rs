//! Jacobi coordinates: each body relative to the centre of mass of the bodies before it.

use crate::model::NBody;
use serde::{Deserialize, Serialize};

/// Jacobi coordinates of N bodies with masses m₀ (the central body), m₁, …: with ηᵢ = m₀ + … + mᵢ
/// and Rᵢ the centre of mass of bodies 0…i,
///
///   x′ᵢ = xᵢ − Rᵢ₋₁ (i ≥ 1),  x′₀ = R_{N−1},  Rᵢ = Rᵢ₋₁ + (mᵢ/ηᵢ)x′ᵢ,
///
/// and the same linear map on velocities (and accelerations). With the Jacobi masses
/// m′ᵢ = mᵢηᵢ₋₁/ηᵢ the map is canonical for p′ᵢ = m′ᵢv′ᵢ, and the kinetic energy separates:
/// T = ½η_{N−1}|v′₀|² + Σᵢ ½m′ᵢ|v′ᵢ|² (Wisdom & Holman 1991, §3).
///
/// The inverse runs the recursion backwards, Rᵢ₋₁ = Rᵢ − (mᵢ/ηᵢ)x′ᵢ, xᵢ = x′ᵢ + Rᵢ₋₁, so that
/// the round trip is exact to a few ulps per body. Holds the masses, allocates nothing after
/// [`Jacobi::new`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Jacobi {
    g: f64,
    masses: Vec<f64>,
    /// G·ηᵢ: the gravitational parameter of the Kepler problem of Jacobi coordinate i.
    mu: Vec<f64>,
    /// mᵢ/ηᵢ.
    ratio: Vec<f64>,
}

impl Jacobi {
    /// The Jacobi coordinates of `model`'s bodies, body 0 the central one.
    pub fn new(model: &NBody) -> Self {
        let mut jacobi = Self::sized(model.masses().len());
        jacobi.set_model(model);
        jacobi
    }

    /// Zeros for `bodies` bodies, before a model's values are set.
    pub(in crate::integrators) fn sized(bodies: usize) -> Self {
        Jacobi {
            g: 0.0,
            masses: vec![0.0; bodies],
            mu: vec![0.0; bodies],
            ratio: vec![0.0; bodies],
        }
    }

    /// Whether these are the coordinates of `model` (the same G and masses).
    pub fn is_of(&self, model: &NBody) -> bool {
        self.g == model.gravitational_constant() && self.masses == model.masses()
    }

    /// Takes the masses and G of `model`, which has as many bodies as `self` (no allocation).
    pub fn set_model(&mut self, model: &NBody) {
        self.g = model.gravitational_constant();
        self.masses.copy_from_slice(model.masses());
        let mut eta = 0.0;
        for (i, &m) in self.masses.iter().enumerate() {
            eta += m;
            self.mu[i] = self.g * eta;
            self.ratio[i] = m / eta;
        }
    }

    /// The number of bodies N.
    pub fn bodies(&self) -> usize {
        self.masses.len()
    }

    /// G.
    pub fn gravitational_constant(&self) -> f64 {
        self.g
    }

    /// The masses mᵢ.
    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    /// G·ηᵢ, the Kepler parameter of Jacobi coordinate i ≥ 1 (μ₀ = G·m₀).
    pub fn mu(&self) -> &[f64] {
        &self.mu
    }

    /// Jacobi positions and velocities (x′, v′) of the body-by-body positions and momenta (q, p),
    /// vᵢ = pᵢ/mᵢ.
    pub fn from_cartesian(&self, q: &[f64], p: &[f64], x: &mut [[f64; 3]], v: &mut [[f64; 3]]) {
        x.copy_from_slice(q.as_chunks::<3>().0);
        for ((vi, pi), m) in v.iter_mut().zip(p.as_chunks::<3>().0).zip(&self.masses) {
            *vi = pi.map(|c| c / m);
        }
        self.forward(x);
        self.forward(v);
    }

    /// Positions and momenta (q, p) of the Jacobi positions and velocities (x′, v′): the inverse
    /// of [`Jacobi::from_cartesian`].
    pub fn to_cartesian(&self, x: &[[f64; 3]], v: &[[f64; 3]], q: &mut [f64], p: &mut [f64]) {
        let q = q.as_chunks_mut::<3>().0;
        let p = p.as_chunks_mut::<3>().0;
        q.copy_from_slice(x);
        p.copy_from_slice(v);
        self.backward(q);
        self.backward(p);
        for (pi, m) in p.iter_mut().zip(&self.masses) {
            *pi = pi.map(|c| c * m);
        }
    }

    /// Jacobi vectors of body-by-body vectors, in place (x → x′; the same map for v and a).
    pub fn forward(&self, w: &mut [[f64; 3]]) {
        let mut centre = w[0];
        for (wi, &ratio) in w.iter_mut().zip(&self.ratio).skip(1) {
            for k in 0..3 {
                wi[k] -= centre[k];
                centre[k] += ratio * wi[k];
            }
        }
        w[0] = centre;
    }

    /// Body-by-body vectors of Jacobi vectors, in place: the inverse of [`Jacobi::forward`].
    pub fn backward(&self, w: &mut [[f64; 3]]) {
        let mut centre = w[0];
        for (wi, &ratio) in w.iter_mut().zip(&self.ratio).skip(1).rev() {
            for k in 0..3 {
                centre[k] -= ratio * wi[k];
                wi[k] += centre[k];
            }
        }
        w[0] = centre;
    }
}
