//! When to poll for interrupts (Ctrl-C): often enough to stop promptly, rarely enough to cost
//! nothing.

use std::time::{Duration, Instant};

/// Polls for interrupts at a stride that adapts to keep polls about 10–40 ms apart, so that a
/// step of 50 ns and a step of 50 ms are both interruptible promptly and cheaply.
#[derive(Clone, Debug)]
pub(super) struct InterruptPoll {
    stride: usize,
    countdown: usize,
    last: Instant,
}

impl InterruptPoll {
    const FAST: Duration = Duration::from_millis(10);
    const SLOW: Duration = Duration::from_millis(40);

    pub(super) fn new() -> Self {
        InterruptPoll {
            stride: 1,
            countdown: 1,
            last: Instant::now(),
        }
    }

    /// Whether to poll before this step.
    #[inline]
    pub(super) fn due(&mut self) -> bool {
        self.countdown -= 1;
        if self.countdown > 0 {
            return false;
        }
        let now = Instant::now();
        let elapsed = now - self.last;
        if elapsed < Self::FAST {
            self.stride = (self.stride * 2).min(1 << 24);
        } else if elapsed > Self::SLOW {
            self.stride = (self.stride / 2).max(1);
        }
        self.last = now;
        self.countdown = self.stride;
        true
    }
}
