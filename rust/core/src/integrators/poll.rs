//! What a run calls between its steps, every 10–40 ms of run time.

use crate::ModelError;

/// A run's poll: called with the steps completed so far, every 10–40 ms of run time; an error
/// stops the run (the binding checks for Ctrl-C there, and reports progress). Any
/// `FnMut() -> Result<(), ModelError>` closure is one, ignoring the count; [`Counting`] wraps a
/// closure that takes it.
pub trait Poll {
    fn poll(&mut self, steps: usize) -> Result<(), ModelError>;
}

impl<F: FnMut() -> Result<(), ModelError>> Poll for F {
    fn poll(&mut self, _steps: usize) -> Result<(), ModelError> {
        self()
    }
}

/// A poll that takes the steps completed so far.
pub struct Counting<F>(pub F);

impl<F: FnMut(usize) -> Result<(), ModelError>> Poll for Counting<F> {
    fn poll(&mut self, steps: usize) -> Result<(), ModelError> {
        (self.0)(steps)
    }
}
