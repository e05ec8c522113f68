/// An infinitesimal symmetry ξ(q) of the configuration space. If L is invariant under the flow
/// of ξ, Noether's theorem gives the conserved momentum J(q, p) = p·ξ(q), and a variational
/// integrator whose L_d shares the invariance conserves J exactly (discrete Noether theorem).
///
/// Coordinates of particle systems are laid out body by body: q = (x₁, …, x_N) with each xᵢ in
/// ℝ^`spatial_dim`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Generator {
    /// Every body moves along `axis`: J is the total linear momentum along it.
    Translation { axis: usize, spatial_dim: usize },
    /// Every body turns about `axis` (in the plane when `spatial_dim` = 2, where `axis` is
    /// ignored): J is the total angular momentum about it.
    Rotation { axis: usize, spatial_dim: usize },
    /// Coordinate `index` is cyclic (∂L/∂q_index = 0): J = p_index.
    Cyclic { index: usize },
}

impl Generator {
    /// A short name: `P_x`, `L_z`, `p[3]`.
    pub fn name(&self) -> String {
        const AXES: [&str; 3] = ["x", "y", "z"];
        match *self {
            Generator::Translation { axis, .. } => format!("P_{}", AXES.get(axis).unwrap_or(&"?")),
            Generator::Rotation { spatial_dim: 2, .. } => "L".to_string(),
            Generator::Rotation { axis, .. } => format!("L_{}", AXES.get(axis).unwrap_or(&"?")),
            Generator::Cyclic { index } => format!("p[{index}]"),
        }
    }

    /// Checks that the generator applies to `n` coordinates ([`Generator::misfit`]), naming
    /// `generator`.
    pub fn check(&self, n: usize) -> Result<(), crate::Error> {
        self.misfit(n)
            .map_or(Ok(()), |reason| Err(crate::Error::invalid("generator", reason)))
    }

    /// Why the generator does not apply to `n` coordinates, if it does not: a cyclic index
    /// beyond them; bodies of `spatial_dim` coordinates that do not divide them, an axis beyond
    /// a body's, a rotation outside the plane or space.
    pub fn misfit(&self, n: usize) -> Option<String> {
        let (ok, what, rule) = match *self {
            Generator::Translation { axis, spatial_dim } => (
                spatial_dim > 0 && axis < spatial_dim && n.is_multiple_of(spatial_dim),
                format!("Translation(axis={axis}, spatial_dim={spatial_dim})"),
                format!("spatial_dim must divide {n} and axis be below spatial_dim"),
            ),
            Generator::Rotation { axis, spatial_dim } => (
                (spatial_dim == 2 || (spatial_dim == 3 && axis < 3)) && n.is_multiple_of(spatial_dim),
                format!("Rotation(axis={axis}, spatial_dim={spatial_dim})"),
                format!("spatial_dim must be 2 (the plane) or 3 (space, about axis 0, 1 or 2) and divide {n}"),
            ),
            Generator::Cyclic { index } => (
                index < n,
                format!("Cyclic({index})"),
                format!("its index must be below {n}"),
            ),
        };
        (!ok).then(|| format!("{what} does not apply to a model of {n} coordinates: {rule}"))
    }

    /// Writes ξ(q) into `out` (n entries): eₐ at each body for a translation along axis a, eₐ × xᵦ
    /// (in the plane (−y, x)) for a rotation, e_index for a cyclic coordinate.
    pub fn field(&self, q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        match *self {
            Generator::Translation { axis, spatial_dim } => {
                out.iter_mut().skip(axis).step_by(spatial_dim).for_each(|x| *x = 1.0);
            }
            Generator::Rotation { spatial_dim: 2, .. } => {
                for (x, o) in q.chunks_exact(2).zip(out.chunks_exact_mut(2)) {
                    (o[0], o[1]) = (-x[1], x[0]);
                }
            }
            Generator::Rotation { axis, .. } => {
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                for (x, o) in q.chunks_exact(3).zip(out.chunks_exact_mut(3)) {
                    (o[a], o[b]) = (-x[b], x[a]);
                }
            }
            Generator::Cyclic { index } => out[index] = 1.0,
        }
    }

    /// J(q, p) = p·ξ(q).
    pub fn momentum(&self, q: &[f64], p: &[f64]) -> f64 {
        self.momentum_terms(q, p).0
    }

    /// J(q, p) = p·ξ(q) and its size, which sets its rounding error and the scale its error is
    /// judged against: the larger of Σ|pᵢξᵢ(q)|, the products it sums, and ‖p‖∞‖ξ(q)‖∞. The
    /// second matters where J is one term or its terms vanish: a cart's momentum p_x at rest
    /// under a swinging bob is computed from the whole motion (p_x = (M + m)ẋ + ml cos θ θ̇),
    /// whose size its rounding error has, not that of p_x ≈ 0.
    pub fn momentum_terms(&self, q: &[f64], p: &[f64]) -> (f64, f64) {
        let ((j, terms), xi) = match *self {
            Generator::Translation { axis, spatial_dim } => {
                (sum(&mut p.iter().skip(axis).step_by(spatial_dim).copied()), 1.0)
            }
            Generator::Rotation { spatial_dim: 2, .. } => (
                sum(&mut q
                    .chunks_exact(2)
                    .zip(p.chunks_exact(2))
                    .flat_map(|(x, y)| [x[0] * y[1], -x[1] * y[0]])),
                largest(q),
            ),
            Generator::Rotation { axis, .. } => {
                // (x × p)·e_axis
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                let terms = sum(&mut q
                    .chunks_exact(3)
                    .zip(p.chunks_exact(3))
                    .flat_map(|(x, y)| [x[a] * y[b], -x[b] * y[a]]));
                (terms, largest(q))
            }
            Generator::Cyclic { index } => ((p[index], p[index].abs()), 1.0),
        };
        (j, size(terms, p, xi))
    }
}

/// J = p·ξ and its size, as [`Generator::momentum_terms`] gives them, for a field ξ given at q
/// (a user's ξ(q)).
pub fn momentum_along(xi: &[f64], p: &[f64]) -> (f64, f64) {
    let (j, terms) = sum(&mut p.iter().zip(xi).map(|(p, x)| p * x));
    (j, size(terms, p, largest(xi)))
}

/// (Σ xᵢ, Σ|xᵢ|).
fn sum(terms: &mut dyn Iterator<Item = f64>) -> (f64, f64) {
    terms.fold((0.0, 0.0), |(j, size), x| (j + x, size + x.abs()))
}

/// ‖x‖∞.
fn largest(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// The size of J: the larger of Σ|pᵢξᵢ| (`terms`) and ‖p‖∞‖ξ‖∞ (`xi`: ‖ξ‖∞).
fn size(terms: f64, p: &[f64], xi: f64) -> f64 {
    terms.max(largest(p) * xi)
}
