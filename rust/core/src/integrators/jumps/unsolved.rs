//! A held contact's solve that failed ([`Unsolved`]): which solve, its residual against its
//! round-off floor, and what helps, diagnosed from how it failed. The run reports it as
//! [`Error::Contact`], a model's own error as [`Error::Model`] ([`run_error`]).

use std::fmt;

use super::{Contact, Surface};
use crate::{Error, ModelError};

/// Why a held solve failed: what its diagnosis found.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Cause {
    /// The step carries the body past what the solve resolves in one step (`past`: the
    /// surface's curvature, the sliding force's turn): its iteration diverged or cycled far from
    /// round-off.
    Step { past: &'static str },
    /// `contact`'s gradient is not ∇φ: it differs from central differences of φ by `mismatch`
    /// of its size at every difference step.
    Gradient { contact: String, mismatch: f64 },
    /// The residual stalled near round-off, far within the step's reach: φ rounds more than
    /// the coordinates it combines.
    Precision,
    /// The rows are dependent at the state: closed surfaces whose normals align, or slip rows
    /// along a normal.
    Dependent,
}

/// A held solve that failed: `solve` (what it solves), its `cause`, the `residual` at its last
/// iterate and its round-off `floor` (the rounding of the quantities it combines), after
/// `iterations`.
#[derive(Clone, Debug)]
pub(super) struct Unsolved {
    pub solve: &'static str,
    pub cause: Cause,
    pub residual: f64,
    pub floor: f64,
    pub iterations: usize,
}

impl Unsolved {
    /// The rows of `solve` dependent at the state.
    pub(super) fn dependent(solve: &'static str) -> ModelError {
        Box::new(Unsolved {
            solve,
            cause: Cause::Dependent,
            residual: f64::NAN,
            floor: f64::NAN,
            iterations: 0,
        })
    }
}

impl fmt::Display for Unsolved {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Unsolved {
            solve,
            cause,
            residual,
            floor,
            iterations,
        } = self;
        if *cause == Cause::Dependent {
            return write!(
                f,
                "the held contacts' {solve} has dependent rows here: the closed surfaces' normals and the stuck \
                 contacts' slip rows are not independent at this q (surfaces meeting at a corner whose normals \
                 align, or slip rows along a normal); a smaller step does not help"
            );
        }
        write!(
            f,
            "the held contacts' {solve} did not converge: its residual is {residual:.3e}, {:.3e} × its round-off \
             floor {floor:.3e}, after {iterations} iterations; ",
            residual / floor
        )?;
        match cause {
            Cause::Step { past } => write!(
                f,
                "the step carries the body past {past} in one step, so a smaller step helps"
            ),
            Cause::Gradient { contact, mismatch } => write!(
                f,
                "the gradient of contact {contact:?} is not ∇φ: it differs from central differences of φ by \
                 {mismatch:.1e} of its size there; correct the gradient (a smaller step does not help)"
            ),
            Cause::Precision => write!(
                f,
                "it stalls near round-off, far within the step's reach: φ loses its precision there (a sum of \
                 large terms that cancel); write φ so that it keeps it (a smaller step does not help)"
            ),
            Cause::Dependent => Ok(()),
        }
    }
}

impl std::error::Error for Unsolved {}

/// Why the held step's position Newton failed at its last iterate q (moving at q̇ = `v` over
/// the step s), row a the worst with `residual` (a stuck slip row's given, a closed contact's
/// its gradient at q): a closed contact's gradient that is not ∇φ ([`disagreement`] beyond
/// 10⁻³, along ∇φ or q̇), a residual near round-off far within the step's reach |row|·s|q̇|
/// (φ's precision), or else the step, past the surface's curvature. A cold path: it allocates.
#[cold]
pub(super) fn diagnosis(
    (contacts, closed): (&[Contact<'_>], &[usize]),
    (q, v, s): (&[f64], &[f64], f64),
    (a, stuck, residual): (usize, Option<&[f64]>, f64),
) -> Result<Cause, ModelError> {
    let mut gradient = vec![0.0; q.len()];
    for &j in closed {
        let contact = &contacts[j];
        contact.surface.gradient(q, &mut gradient)?;
        let along = |e: &[f64]| disagreement(&*contact.surface, q, &gradient, e);
        let mismatch = along(&gradient)?.max(along(v)?);
        if mismatch > 1e-3 {
            let contact = contact.name.clone();
            return Ok(Cause::Gradient { contact, mismatch });
        }
    }
    let row = match stuck {
        Some(row) => row,
        None => {
            contacts[closed[a]].surface.gradient(q, &mut gradient)?;
            &gradient[..]
        }
    };
    let reach: f64 = row.iter().zip(v).map(|(g, v)| (g * s * v).abs()).sum();
    Ok(if residual <= 1e-8 * reach {
        Cause::Precision
    } else {
        Cause::Step {
            past: "the surface's curvature radius",
        }
    })
}

/// How far `gradient`, the surface's ∇φ at q, lies from central differences of φ along the
/// direction e: the least |(φ(q + he) − φ(q − he))/2h − ∇φ·e| / (|∇φ||e|) over steps h from a
/// quarter of the scale of q along e down to 10⁻¹⁵ of it, so that whatever the surface's own
/// scale one step balances its truncation against its rounding. 0 for e = 0. A cold path: it
/// allocates.
fn disagreement(surface: &dyn Surface, q: &[f64], gradient: &[f64], e: &[f64]) -> Result<f64, ModelError> {
    let norm = |x: &[f64]| x.iter().map(|y| y * y).sum::<f64>().sqrt();
    let size = norm(e);
    let magnitude = norm(gradient);
    if size == 0.0 || magnitude == 0.0 {
        return Ok(0.0);
    }
    let along = gradient.iter().zip(e).map(|(g, x)| g * x).sum::<f64>() / size;
    let scale = q.iter().zip(e).map(|(q, x)| (q * x).abs()).sum::<f64>().max(size) / size;
    let mut shifted = vec![0.0; q.len()];
    let mut least = f64::INFINITY;
    let mut h = 0.25 * scale;
    while h > 1e-15 * scale {
        let mut phi = |sign: f64| {
            for ((s, q), x) in shifted.iter_mut().zip(q).zip(e) {
                *s = q + sign * h * x / size;
            }
            surface.phi(&shifted)
        };
        let difference = (phi(1.0)? - phi(-1.0)?) / (2.0 * h);
        least = least.min((difference - along).abs() / magnitude);
        h *= 0.25;
    }
    Ok(least)
}

/// The run's error for a held step's `source` in `step` (from `time`): [`Error::Contact`] for
/// a held solve that failed, [`Error::Model`] for the model's or a surface's own error.
pub(super) fn run_error(source: ModelError, step: usize, time: f64) -> Error {
    match source.downcast::<Unsolved>() {
        Ok(unsolved) => Error::Contact {
            step,
            time,
            reason: unsolved.to_string(),
        },
        Err(source) => Error::Model { step, time, source },
    }
}
