//! The stepper's interrupt poll, which the solvers share (see [`crate::solve::interrupt`]).

pub(super) use crate::solve::interrupt::InterruptPoll;
