//! Steps per second of the implicit variational integrators (midpoint, trapezoid, Galerkin) on the
//! native double pendulum, a general Lagrangian; the Newton iterations a step are printed.
//!
//! `cargo bench --bench implicit`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;
use varmech::integrators::{integrate, General, Method, Options};
use varmech::scenes::DoublePendulum;

const STEPS: usize = 1_000;

fn implicit(c: &mut Criterion) {
    let problem = DoublePendulum::problem();
    let options = Options {
        save_every: STEPS,
        ..Options::new(0.01, STEPS)
    };
    let run = |method| {
        integrate(
            &General(&problem.system),
            method,
            &problem.initial.q,
            &problem.initial.p,
            &options,
            || Ok(()),
        )
    };
    let mut group = c.benchmark_group("double_pendulum");
    group.throughput(Throughput::Elements(STEPS as u64));
    for method in [
        Method::Midpoint,
        Method::Trapezoid,
        Method::Galerkin4,
        Method::Galerkin6,
    ] {
        let traj = run(method).expect("h = 0.01 converges");
        println!(
            "{}: {:.2} Newton iterations a step",
            method.info().name,
            traj.newton_iterations as f64 / STEPS as f64
        );
        group.bench_with_input(
            BenchmarkId::from_parameter(method.info().name),
            &method,
            |b, &method| b.iter(|| black_box(run(method).map(|t| t.q).unwrap_or_default())),
        );
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(30);
    targets = implicit
}
criterion_main!(benches);
