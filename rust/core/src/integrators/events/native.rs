//! The built-in event functions, evaluated in Rust (no call out of the core per step).

use super::EventFunctions;
use crate::integrators::surfaces::{check_ellipsoid, ellipsoid, wall, NativeSurface, Surface};
use crate::integrators::Dynamics;
use crate::model::Reaction;
use crate::{Error, ModelError};

/// A built-in event function g(t, q, p). `Crossing` and `Ellipsoid` are the native surfaces'
/// φ ([`NativeSurface`]), computed by the same functions.
#[derive(Clone, Debug, PartialEq)]
pub enum NativeEvent {
    /// g = q_k − value: the coordinate k crossing a value.
    Crossing { coordinate: usize, value: f64 },
    /// g = s(1 − Σᵢ ((q_{kᵢ} − cᵢ)/aᵢ)²), kᵢ the `coordinates`, c the `centre`, a the
    /// `semi_axes`, s = +1 `inside` (g ≥ 0 in the ellipsoid: a billiard table) and −1 outside
    /// (an obstacle): the state crossing the ellipsoid's surface. The sum runs in the order of
    /// the coordinates from 0, so a function written the same way agrees to the bit.
    Ellipsoid {
        coordinates: Vec<usize>,
        centre: Vec<f64>,
        semi_axes: Vec<f64>,
        inside: bool,
    },
    /// g = |E(q, p) − E₀| − bound, E₀ the energy at the start of the run (NaN until the run
    /// starts; a resumed run is given its first run's): the energy error growing beyond a bound.
    EnergyError { bound: f64, initial: f64 },
    /// g = maxⱼ |x_j|² − r², x_j = q\[groups\[j\]\] (e.g. a body's position): a group leaving the
    /// ball of radius r about the origin (escape).
    Escape { radius: f64, groups: Vec<Vec<usize>> },
    /// g = min_{i<j} |x_i − x_j|² − r² over the groups (e.g. bodies), or |x₀|² − r² for a single
    /// group: two groups closer than r (a close encounter), or one closer to the origin.
    Encounter { radius: f64, groups: Vec<Vec<usize>> },
    /// g = λ_row, a multiplier of the model's constraints ([`Dynamics::reaction`]): a contact's
    /// force or a string's tension reaching 0 (lift-off, slack). `reaction` holds the buffers,
    /// made at the run's start for the model's sizes.
    Multiplier {
        row: usize,
        reaction: Option<Box<Reaction>>,
    },
}

/// The crossing of a native surface: g = φ.
impl From<NativeSurface> for NativeEvent {
    fn from(surface: NativeSurface) -> Self {
        match surface {
            NativeSurface::Wall { coordinate, value } => NativeEvent::Crossing { coordinate, value },
            NativeSurface::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                inside,
            } => NativeEvent::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                inside,
            },
        }
    }
}

impl NativeEvent {
    /// Refuses coordinates outside 0 … n − 1, empty or unequal groups, and radii, bounds or
    /// semi-axes that are not finite and positive (naming `events` and the event's `name`).
    pub fn check(&self, name: &str, n: usize) -> Result<(), Error> {
        let fail = |reason: String| Err(Error::invalid("events", format!("{name}: {reason}")));
        let positive = |what: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                fail(format!("{what} must be finite and positive, got {x}"))
            }
        };
        match self {
            NativeEvent::Crossing { coordinate, value } => {
                let wall = NativeSurface::Wall {
                    coordinate: *coordinate,
                    value: *value,
                };
                wall.misfit(n).map_or(Ok(()), fail)
            }
            NativeEvent::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                ..
            } => check_ellipsoid(coordinates, centre, semi_axes, n).map_or(Ok(()), fail),
            NativeEvent::EnergyError { bound, .. } => positive("bound", *bound),
            // The row is checked against the model's constraints at the run's start.
            NativeEvent::Multiplier { .. } => Ok(()),
            NativeEvent::Escape { radius, groups } | NativeEvent::Encounter { radius, groups } => {
                positive("radius", *radius)?;
                let width = groups.first().map_or(0, Vec::len);
                if width == 0 || groups.iter().any(|g| g.len() != width) {
                    return fail(format!("groups must be non-empty and of equal size, got {groups:?}"));
                }
                if let Some(k) = groups.iter().flatten().find(|&&k| k >= n) {
                    return fail(format!("groups: coordinate {k} is not in 0 … {}", n - 1));
                }
                Ok(())
            }
        }
    }

    /// Takes E₀ for the energy error, and makes a multiplier's buffers for the model (refusing
    /// a row it does not have); nothing for the others.
    pub fn start(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64]) -> Result<(), ModelError> {
        match self {
            // E₀ given (a resumed run's, the whole run's first energy) is kept; NaN is computed here.
            NativeEvent::EnergyError { initial, .. } if initial.is_nan() => {
                *initial = model.as_lagrangian().energy_terms(q, p, t)?.energy;
            }
            NativeEvent::Multiplier { row, reaction } => {
                let m = model.constraint_counts().0;
                if *row >= m {
                    return Err(format!("multiplier({row}): the model has {m} constraint rows").into());
                }
                *reaction = Some(Box::new(Reaction::new(q.len(), m)));
            }
            _ => {}
        }
        Ok(())
    }

    /// g(t, q, p).
    pub fn value(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64]) -> Result<f64, ModelError> {
        let squared = |x: &[usize]| x.iter().map(|&k| q[k] * q[k]).sum::<f64>();
        let apart = |x: &[usize], y: &[usize]| x.iter().zip(y).map(|(&i, &j)| (q[i] - q[j]).powi(2)).sum::<f64>();
        Ok(match self {
            NativeEvent::Crossing { coordinate, value } => wall(q, *coordinate, *value),
            NativeEvent::Ellipsoid {
                coordinates,
                centre,
                semi_axes,
                inside,
            } => ellipsoid(q, coordinates, centre, semi_axes, *inside),
            NativeEvent::EnergyError { bound, initial } => {
                (model.as_lagrangian().energy_terms(q, p, t)?.energy - *initial).abs() - *bound
            }
            NativeEvent::Multiplier { row, reaction } => {
                let reaction = reaction
                    .as_deref_mut()
                    .ok_or("multiplier: evaluated before the run's start")?;
                model
                    .reaction(reaction, q, p, t)
                    .ok_or("multiplier: the model has no constraints")??;
                reaction.multipliers[*row]
            }
            NativeEvent::Escape { radius, groups } => {
                groups.iter().map(|g| squared(g)).fold(f64::NEG_INFINITY, f64::max) - *radius * *radius
            }
            NativeEvent::Encounter { radius, groups } => {
                let closest = match groups.as_slice() {
                    [only] => squared(only),
                    _ => groups
                        .iter()
                        .enumerate()
                        .flat_map(|(i, x)| groups[i + 1..].iter().map(move |y| (x, y)))
                        .map(|(x, y)| apart(x, y))
                        .fold(f64::INFINITY, f64::min),
                };
                closest - *radius * *radius
            }
        })
    }
}

impl EventFunctions for Vec<NativeEvent> {
    fn len(&self) -> usize {
        Vec::len(self)
    }

    fn start(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64]) -> Result<(), ModelError> {
        self.iter_mut().try_for_each(|e| e.start(model, t, q, p))
    }

    fn evaluate(
        &mut self,
        model: &dyn Dynamics,
        t: f64,
        q: &[f64],
        p: &[f64],
        g: &mut [f64],
    ) -> Result<(), ModelError> {
        for (e, g) in self.iter_mut().zip(g) {
            *g = e.value(model, t, q, p)?;
        }
        Ok(())
    }
}
