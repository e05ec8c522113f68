//! Per-thread workspaces, for functions whose signatures leave no room to pass one.

use std::cell::RefCell;
use std::thread::LocalKey;

/// Runs `body` with this thread's workspace in `key`, so that a function called at every step
/// allocates only until its workspace has its size. A nested call, which finds the workspace
/// busy (an evaluation that calls back into the same function), gets a new one from `fresh`
/// rather than a panic.
pub(crate) fn with_scratch<T: 'static, R>(
    key: &'static LocalKey<RefCell<T>>,
    fresh: impl FnOnce() -> T,
    body: impl FnOnce(&mut T) -> R,
) -> R {
    key.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => body(&mut scratch),
        Err(_) => body(&mut fresh()),
    })
}
