//! Interrupts (Ctrl-C): when to poll for them, often enough to stop promptly and rarely enough
//! to cost nothing, and the check that iterative solves poll between the driver's polls.

use std::cell::Cell;
use std::time::{Duration, Instant};

use crate::ModelError;

/// The interrupt check of the iterative solves: an error (the binding's KeyboardInterrupt)
/// stops the solve. A plain function, so that it holds no borrow and may live in a
/// thread-local for the span of a run.
pub type InterruptCheck = fn() -> Result<(), ModelError>;

thread_local! {
    static CHECK: Cell<Option<InterruptCheck>> = const { Cell::new(None) };
}

/// Runs `body` with `check` as the interrupt check of every iterative solve on this thread
/// (Newton's method, SHAKE's sweeps), so that one long solve (a huge system, a
/// `newton_max_iterations` in the thousands) stops on Ctrl-C as promptly as the step loop; the
/// previous check is restored afterwards, also on unwinding.
pub fn with_interrupt_check<R>(check: InterruptCheck, body: impl FnOnce() -> R) -> R {
    struct Restore(Option<InterruptCheck>);
    impl Drop for Restore {
        fn drop(&mut self) {
            CHECK.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(CHECK.with(|c| c.replace(Some(check))));
    body()
}

/// The interrupt check of this thread, Ok where none is set (plain Rust callers).
pub(crate) fn check_interrupt() -> Result<(), ModelError> {
    CHECK.with(Cell::get).map_or(Ok(()), |check| check())
}

/// Polls for interrupts at a stride that adapts to keep polls about 10–40 ms apart (the first
/// at least 2 ms into the run), so that a step of 50 ns and a step of 50 ms are both
/// interruptible promptly and cheaply.
#[derive(Clone, Debug)]
pub(crate) struct InterruptPoll {
    stride: usize,
    countdown: usize,
    last: Instant,
}

impl Default for InterruptPoll {
    fn default() -> Self {
        InterruptPoll::new()
    }
}

impl InterruptPoll {
    const FAST: Duration = Duration::from_millis(10);
    const SLOW: Duration = Duration::from_millis(40);
    /// The least time between two polls. While the stride ramps up from one step, a due poll
    /// that comes sooner is skipped: a poll takes the GIL, and a run's first milliseconds are
    /// when another thread holds it (a long run's commit of its last segment to its file), so
    /// that each early poll would wait for that thread.
    const LEAST: Duration = Duration::from_millis(2);

    pub(crate) fn new() -> Self {
        InterruptPoll {
            stride: 1,
            countdown: 1,
            last: Instant::now(),
        }
    }

    /// Whether to poll before this step.
    #[inline]
    pub(crate) fn due(&mut self) -> bool {
        self.countdown -= 1;
        if self.countdown > 0 {
            return false;
        }
        let now = Instant::now();
        let elapsed = now - self.last;
        if elapsed < Self::LEAST {
            self.stride = (self.stride * 2).min(1 << 24);
            self.countdown = self.stride;
            return false;
        }
        if elapsed < Self::FAST {
            self.stride = (self.stride * 2).min(1 << 24);
        } else if elapsed > Self::SLOW {
            self.stride = (self.stride / 2).max(1);
        }
        self.last = now;
        self.countdown = self.stride;
        true
    }

    /// How many of the next `wanted` steps need no poll before them, taken off the countdown:
    /// a loop may run them without asking [`InterruptPoll::due`] each time.
    #[inline]
    pub(crate) fn quiet(&mut self, wanted: usize) -> usize {
        let k = wanted.min(self.countdown - 1);
        self.countdown -= k;
        k
    }

    /// Gives back to the countdown `k` steps that [`InterruptPoll::quiet`] took off and a loop
    /// did not run (it stopped early).
    #[inline]
    pub(crate) fn unquiet(&mut self, k: usize) {
        self.countdown += k;
    }
}
