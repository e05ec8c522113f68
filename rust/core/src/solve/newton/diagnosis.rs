//! What a failed Newton iteration says would help ([`Diagnosis`]), in the words of its problem
//! ([`Reasons`]).

use nalgebra::DMatrix;

use super::NewtonProblem;
use crate::error::StepError;

/// Why an iteration failed, in the words of its problem.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Reasons {
    /// The Jacobian is singular.
    pub singular: &'static str,
    /// F is non-finite at the starting guess.
    pub non_finite_start: &'static str,
    /// A correction or F became non-finite.
    pub non_finite: &'static str,
    /// The iteration cap was reached.
    pub not_converged: &'static str,
    /// What it means, and what helps, when the start lies outside the region where Newton's
    /// iteration converges ([`Diagnosis::Diverged`]).
    pub outside: &'static str,
}

/// What the history of a failed iteration says would help: the advice of its error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagnosis {
    /// No contraction at the start (Deuflhard's θ₀ ≥ 1), no headway, or a slow fall with a
    /// Jacobian that agrees with F: the predictor lies outside Newton's region; a smaller step
    /// brings it closer.
    Diverged,
    /// The corrections fell linearly or not at all, with fresh Jacobians that disagree with
    /// differences of F: the model's second derivatives are not those of its first.
    Linear,
    /// The corrections repeat: a cycle about a point where F jumps (a kink in the model).
    Cycle,
    /// The corrections contracted, then stopped falling well above the noise of the equations:
    /// no solution near the predictor (a step too large for the motion), or F is not smooth.
    Stalled,
    /// Still converging fast at the cap: too few iterations allowed.
    Cap,
    /// The Jacobian is singular.
    Singular,
    /// The model's ∂²L/∂q̇² is nearly singular here, beyond what the sizes of its masses make
    /// it (`degenerate`): coordinates close to a singularity of theirs.
    Degenerate,
}

/// Whether ∂²L/∂q̇² = `mass` is nearly singular beyond the disparity of its diagonal: the
/// condition number of D^(-1/2) M D^(-1/2), D = diag M, over 10³. A model whose masses differ
/// (a planet and its moon) is not degenerate; coordinates near a singularity of their own are,
/// whose rows of M become dependent (Euler angles at θ → 0: the φ and ψ rows, by 1/sin²θ).
pub fn degenerate(mass: &DMatrix<f64>) -> bool {
    let d = mass.diagonal().map(|x| x.abs().sqrt());
    if d.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return true;
    }
    let scaled = DMatrix::from_fn(mass.nrows(), mass.ncols(), |i, j| mass[(i, j)] / (d[i] * d[j]));
    let s = scaled.singular_values();
    let (least, most) = (s.min(), s.max());
    least.is_nan() || most.is_nan() || least * 1e3 < most
}

impl Diagnosis {
    /// The advice for a failure so diagnosed, of a problem that fails for `reasons`.
    pub(crate) fn advice(self, reasons: &Reasons) -> &'static str {
        match self {
            Diagnosis::Diverged => reasons.outside,
            Diagnosis::Linear => {
                "the corrections fell only linearly or not at all, and the Jacobian disagrees with differences \
                 of the equations: the model's second derivatives (hessians) are not those of its first; check \
                 them (varmech.check_derivatives); a smaller step does not help"
            }
            Diagnosis::Cycle => {
                "the corrections repeat, a cycle about a jump of the equations: the model is not smooth here (a \
                 kink or jump in L, its derivatives or forces); a smaller step does not help"
            }
            Diagnosis::Stalled => {
                "the corrections stopped falling far above the noise of the equations: they have no solution \
                 near the predictor, as at a step too large for the motion (a smaller step (dt) helps), or the \
                 model is not smooth here (a kink or jump in L, its derivatives or forces)"
            }
            Diagnosis::Cap => "it was still converging: allow more iterations (newton_max_iterations)",
            // The problem's reason says why, and what helps.
            Diagnosis::Singular => "",
            Diagnosis::Degenerate => {
                "∂²L/∂q̇² is nearly singular here: the coordinates approach a singularity of theirs (Euler \
                 angles at θ → 0 or π), where the velocities, and so what a step must resolve, grow without \
                 bound; a smaller step helps only for a while, coordinates without the singularity help"
            }
        }
    }

    /// The diagnosis once the problem is looked at, back at its start
    /// ([`NewtonProblem::restart`]): a model nearly singular there
    /// ([`NewtonProblem::degenerate`]) explains a failure that is no cap; a linear convergence
    /// with a Jacobian that agrees with differences of F ([`NewtonProblem::jacobian_agrees`]) is
    /// the iteration not yet near the root, where F's curvature, not J, slows it; corrections
    /// that grow or wander with a Jacobian that disagrees are the wrong Jacobian's (a Hessian too
    /// small by half or more overshoots from every start), which no smaller step mends.
    pub(crate) fn confirmed<P: NewtonProblem>(self, problem: &mut P) -> Result<Self, StepError> {
        if matches!(self, Diagnosis::Cap | Diagnosis::Singular) {
            return Ok(self);
        }
        problem.restart();
        Ok(match self {
            _ if problem.degenerate()? => Diagnosis::Degenerate,
            Diagnosis::Linear if problem.jacobian_agrees()? => Diagnosis::Diverged,
            Diagnosis::Diverged if !problem.jacobian_agrees()? => Diagnosis::Linear,
            other => other,
        })
    }
}
