//! The native step loop allocates nothing: a long run makes exactly as many allocations as a
//! run of 100 steps (the set-up's), whatever the method.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use varmech::integrators::{integrate, Method, Options};
use varmech::scenes::NBody;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations(method: Method, steps: usize, max_energy_error: Option<f64>) -> usize {
    let problem = NBody::outer_solar_system();
    let options = Options {
        save_every: 10,
        max_energy_error,
        ..Options::new(10.0, steps)
    };
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let traj = integrate(
        &problem.system,
        method,
        &problem.initial.q,
        &problem.initial.p,
        &options,
        || Ok(()),
    )
    .unwrap();
    let count = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert_eq!(traj.steps, steps);
    count
}

#[test]
fn the_step_loop_allocates_nothing() {
    for method in Method::ALL {
        // Newton's difference Jacobians make the implicit methods slow on 18 coordinates; a
        // shorter long run proves the same.
        let long_steps = if method.info().implicit { 2_000 } else { 100_000 };
        for check in [None, Some(1.0)] {
            let short = allocations(method, 100, check);
            let long = allocations(method, long_steps, check);
            assert_eq!(
                short, long,
                "{method:?}: {short} allocations for 100 steps, {long} for {long_steps}"
            );
        }
    }
}
