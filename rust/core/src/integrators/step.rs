//! The arguments every one-step method shares: where a step starts, and where it writes.

/// The start of one step of size h: the time t and the state (q₀, p₀).
#[derive(Clone, Copy, Debug)]
pub struct StepStart<'a> {
    pub t: f64,
    pub h: f64,
    pub q: &'a [f64],
    pub p: &'a [f64],
}

/// The increments (δq, δp) of one step, so that (q₁, p₁) = (q₀ + δq, p₀ + δp); the stepper adds
/// them with compensated summation.
#[derive(Debug)]
pub struct Increment<'a> {
    pub dq: &'a mut [f64],
    pub dp: &'a mut [f64],
}

impl Increment<'_> {
    /// The same buffers, borrowed again for a method that takes its increment by value.
    pub fn reborrow(&mut self) -> Increment<'_> {
        Increment {
            dq: self.dq,
            dp: self.dp,
        }
    }
}
