//! φ of a run's contacts at a state, for the resolver (the check after each step of the
//! method's own loop is [`crate::integrators::Gaps`]).

use crate::integrators::clear::gap;
use crate::integrators::jumps::Contact;
use crate::Error;

/// φ of every contact at q into `phi`; a surface's error names the run's step and time.
pub(super) fn evaluate(
    contacts: &[Contact<'_>],
    q: &[f64],
    phi: &mut [f64],
    step: usize,
    time: f64,
) -> Result<(), Error> {
    for (c, phi) in contacts.iter().zip(phi) {
        *phi = gap((&*c.surface, &c.name), None, q).map_err(|source| Error::model(step, time, source))?;
    }
    Ok(())
}
