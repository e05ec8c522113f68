//! Steps per second of every method on the native Kepler problem and outer solar system.
//!
//! `cargo bench --bench steps`; each iteration runs the public driver for a fixed number of
//! steps, keeping only the final state, so the figure includes the driver's checks and the
//! compensated summation, as users get them.
//!
//! The `overhead` group times varmech's driver against hand-written loops that do the same
//! arithmetic (`benches/reference`, held bit-identical by `tests/rust/bits.rs`): the ratio is
//! what the driver costs beyond the physics.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;
use varmech::integrators::{integrate, General, Method, Options};
use varmech::model::MechanicalSystem;
use varmech::scenes::{DoublePendulum, Kepler, NBody, Problem};

mod reference;

const STEPS: usize = 2_000;

fn bench_problem<S: MechanicalSystem>(c: &mut Criterion, name: &str, problem: &Problem<S>, dt: f64) {
    let mut group = c.benchmark_group(name);
    group.throughput(Throughput::Elements(STEPS as u64));
    for method in Method::ALL {
        let options = Options {
            save_every: STEPS,
            ..Options::new(dt, STEPS)
        };
        group.bench_with_input(
            BenchmarkId::from_parameter(method.info().name),
            &options,
            |b, options| {
                b.iter(|| {
                    let traj = integrate(
                        &problem.system,
                        method,
                        &problem.initial.q,
                        &problem.initial.p,
                        options,
                        || Ok(()),
                    );
                    black_box(traj.map(|t| t.q).unwrap_or_default())
                })
            },
        );
    }
    group.finish();
}

/// Kepler Verlet and the double pendulum's midpoint rule through `integrate` and through the
/// reference loops, side by side.
fn overhead(c: &mut Criterion) {
    let problem = Kepler::problem(0.6).unwrap();
    let h = 2.0 * std::f64::consts::PI / 200.0;
    let options = Options {
        save_every: STEPS,
        ..Options::new(h, STEPS)
    };
    let (q0, p0) = (&problem.initial.q, &problem.initial.p);
    let mut group = c.benchmark_group("overhead");
    group.throughput(Throughput::Elements(STEPS as u64));
    group.bench_function("kepler_verlet/varmech", |b| {
        b.iter(|| {
            let traj = integrate(&problem.system, Method::Verlet, q0, p0, &options, || Ok(()));
            black_box(traj.map(|t| t.q).unwrap_or_default())
        })
    });
    group.bench_function("kepler_verlet/reference", |b| {
        b.iter(|| {
            black_box(reference::kepler_verlet(
                [q0[0], q0[1]],
                [p0[0], p0[1]],
                black_box(h),
                STEPS,
            ))
        })
    });
    let pendulum = DoublePendulum::problem();
    let options = Options {
        save_every: STEPS,
        ..Options::new(0.01, STEPS)
    };
    let (q0, p0) = (&pendulum.initial.q, &pendulum.initial.p);
    group.bench_function("double_pendulum_midpoint/varmech", |b| {
        b.iter(|| {
            let traj = integrate(
                &General(&pendulum.system),
                Method::Midpoint,
                q0,
                p0,
                &options,
                || Ok(()),
            );
            black_box(traj.map(|t| t.q).unwrap_or_default())
        })
    });
    group.bench_function("double_pendulum_midpoint/reference", |b| {
        b.iter(|| {
            let (q0, p0) = ([q0[0], q0[1]], [p0[0], p0[1]]);
            black_box(reference::midpoint(&pendulum.system, q0, p0, black_box(0.01), STEPS))
        })
    });
    group.finish();
}

fn steps(c: &mut Criterion) {
    bench_problem(
        c,
        "kepler",
        &Kepler::problem(0.6).unwrap(),
        2.0 * std::f64::consts::PI / 200.0,
    );
    bench_problem(c, "outer_solar_system", &NBody::outer_solar_system(), 50.0);
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(30);
    targets = overhead, steps
}
criterion_main!(benches);
