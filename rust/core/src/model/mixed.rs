use super::{ConstraintSet, HolonomicConstraints, Lagrangian, VelocityConstraints};

/// A Lagrangian system S on holonomic constraints H, g(q) = 0, and velocity constraints C,
/// A(q)q̇ + b(q) = 0, together: a rolling body whose contact is held on a surface, say. The
/// constraint forces are Gᵀλ + Aᵀμ (Lagrange–d'Alembert), and a consistent state has g(q) = 0
/// and the velocity on both, [G(q); A(q)]q̇ + [0; b(q)] = 0 (the hidden constraint G(q)q̇ = 0
/// of the positions' and the velocity constraints). What the discrete Lagrange–d'Alembert
/// integrator with holonomic constraints ([`crate::integrators::Del`]) integrates.
#[derive(Clone, Debug)]
pub struct Mixed<S, H, C> {
    pub system: S,
    pub holonomic: H,
    pub velocity: C,
}

impl<S: Lagrangian, H: HolonomicConstraints, C: VelocityConstraints> Mixed<S, H, C> {
    /// Both sets of constraints, as one record.
    pub fn constraints(&self) -> ConstraintSet<'_> {
        ConstraintSet {
            holonomic: Some(&self.holonomic),
            velocity: Some(&self.velocity),
        }
    }
}
