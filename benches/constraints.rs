//! RATTLE's cost on holonomic constraints: steps per second on planar chains of 2 to 64 links,
//! with the exponent of the time a step against the number of links; and the Cartesian
//! pendulum under RATTLE against the same pendulum in its angle under Verlet, each at the step
//! that reaches the same error at T = 10.
//!
//! `cargo bench --bench constraints`; the summaries printed after each group (steps/s, the
//! exponents, the time ratio) are criterion's estimates, recomputed from its own samples.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use std::time::{Duration, Instant};
use varmech::integrators::{integrate, Dynamics, Method, Options, Trajectory};
use varmech::scenes::{self, Pendulum};

/// Links of the chains, and the steps (h = 0.01) of one iteration on each.
const LINKS: [usize; 6] = [2, 4, 8, 16, 32, 64];
const CHAIN_STEPS: usize = 500;
const CHAIN_DT: f64 = 0.01;

/// The pendulum's release angle, end time, and the error both runs are held to at T.
const THETA0: f64 = 2.0;
const T_END: f64 = 10.0;
const TARGET_ERROR: f64 = 1e-4;

/// Criterion's samples a benchmark (the configuration's `sample_size`).
const SAMPLES: usize = 30;

/// `steps` steps of `dt` from (q0, p0), keeping only the initial and the final state.
fn run<S: Dynamics + ?Sized>(sys: &S, method: Method, q0: &[f64], p0: &[f64], dt: f64, steps: usize) -> Trajectory {
    let options = Options {
        save_every: steps,
        ..Options::new(dt, steps)
    };
    integrate(sys, method, q0, p0, &options, || Ok(()))
        .unwrap_or_else(|f| panic!("{method:?}, {steps} steps of {dt}: {}", f.error))
}

/// Benchmarks `routine` as `id` and returns criterion's estimate of the time of one call,
/// recomputed from the same samples: the slope of their total times against their iteration
/// counts, over the last `samples` (the measurement; the warm-up comes first). `None` when a
/// filter skipped it.
fn bench_time<R>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    id: BenchmarkId,
    samples: usize,
    mut routine: impl FnMut() -> R,
) -> Option<f64> {
    let mut taken = Vec::new();
    group.bench_function(id, |b| {
        b.iter_custom(|iters| {
            let start = Instant::now();
            for _ in 0..iters {
                black_box(routine());
            }
            let elapsed = start.elapsed();
            taken.push((iters as f64, elapsed.as_secs_f64()));
            elapsed
        })
    });
    let measured = &taken[taken.len().saturating_sub(samples)..];
    let xx: f64 = measured.iter().map(|(x, _)| x * x).sum();
    (xx > 0.0).then(|| measured.iter().map(|(x, y)| x * y).sum::<f64>() / xx)
}

/// Least-squares slope of ln y against ln x.
fn log_slope(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let cov: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let var: f64 = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    cov / var
}

fn chains(c: &mut Criterion) {
    let mut group = c.benchmark_group("rattle_chain");
    group.throughput(Throughput::Elements(CHAIN_STEPS as u64));
    let mut per_step = Vec::new();
    let mut samples = SAMPLES;
    for links in LINKS {
        let problem = scenes::planar_chain(links).expect("a chain");
        let chain = || {
            run(
                &problem.system,
                Method::Rattle,
                &problem.initial.q,
                &problem.initial.p,
                CHAIN_DT,
                CHAIN_STEPS,
            )
        };
        let newton = chain().newton_iterations as f64 / CHAIN_STEPS as f64;
        println!("{links} links: {newton:.2} Newton iterations a step");
        if links >= 64 {
            // Hundreds of milliseconds an iteration: fewer, longer samples.
            samples = 10;
            group.sample_size(samples).measurement_time(Duration::from_secs(5));
        }
        let id = BenchmarkId::from_parameter(links);
        if let Some(time) = bench_time(&mut group, id, samples, || chain().q) {
            per_step.push((links as f64, time / CHAIN_STEPS as f64));
        }
    }
    group.finish();
    for &(links, time) in &per_step {
        println!(
            "rattle_chain/{links}: {:.3} µs a step, {:.0} steps/s",
            time * 1e6,
            1.0 / time
        );
    }
    for pair in per_step.windows(2) {
        println!(
            "rattle_chain: exponent {:.2} from {} to {} links",
            log_slope(pair),
            pair[0].0,
            pair[1].0
        );
    }
    if per_step.len() == LINKS.len() {
        let large: Vec<_> = per_step.iter().copied().filter(|&(links, _)| links >= 8.0).collect();
        println!(
            "rattle_chain: time a step ∝ N^{:.2} over 2–64 links, N^{:.2} over 8–64",
            log_slope(&per_step),
            log_slope(&large)
        );
    }
}

/// The Cartesian pendulum's position at T_END from the angle: Kahan–Li 8 at h = 1e-3 on the
/// pendulum in its angle (checked against h = 5e-4), as (sin θ, −cos θ).
fn reference() -> [f64; 2] {
    let angle = |steps: usize| {
        run(
            &Pendulum::new(),
            Method::KahanLi8,
            &[THETA0],
            &[0.0],
            T_END / steps as f64,
            steps,
        )
        .q_at(1)[0]
    };
    let (theta, finer) = (angle(10_000), angle(20_000));
    println!(
        "reference: θ(T) = {theta:.15}, {:.1e} from the run at half the step",
        (theta - finer).abs()
    );
    [theta.sin(), -theta.cos()]
}

/// The smallest number of steps whose error at T_END is at most TARGET_ERROR, searching from a
/// second-order estimate off `first`; `error(n)` is the error with n steps.
fn steps_for_target(error: impl Fn(usize) -> f64, first: usize) -> usize {
    let mut n = ((first as f64) * (error(first) / TARGET_ERROR).sqrt()).ceil() as usize;
    while error(n) > TARGET_ERROR {
        n += 1;
    }
    while n > 1 && error(n - 1) <= TARGET_ERROR {
        n -= 1;
    }
    n
}

fn equal_accuracy(c: &mut Criterion) {
    let reference = reference();
    let cartesian = scenes::cartesian_pendulum();
    let angle = Pendulum::new();
    let rattle = |steps: usize| {
        run(
            &cartesian.system,
            Method::Rattle,
            &cartesian.initial.q,
            &cartesian.initial.p,
            T_END / steps as f64,
            steps,
        )
    };
    let verlet = |steps: usize| run(&angle, Method::Verlet, &[THETA0], &[0.0], T_END / steps as f64, steps);
    // Both errors are distances in the plane from the reference position.
    let rattle_error = |steps: usize| {
        let q = rattle(steps).q;
        (q[2] - reference[0]).hypot(q[3] - reference[1])
    };
    let verlet_error = |steps: usize| {
        let theta = verlet(steps).q[1];
        (theta.sin() - reference[0]).hypot(-theta.cos() - reference[1])
    };
    let n_rattle = steps_for_target(rattle_error, 1_000);
    let n_verlet = steps_for_target(verlet_error, 1_000);
    for (name, steps, error) in [
        ("RATTLE, Cartesian", n_rattle, rattle_error(n_rattle)),
        ("Verlet, angle", n_verlet, verlet_error(n_verlet)),
    ] {
        println!(
            "{name}: {steps} steps (h = {:.5}) reach {error:.3e} at T = {T_END} (target {TARGET_ERROR:.0e})",
            T_END / steps as f64
        );
    }

    let mut group = c.benchmark_group("pendulum_equal_accuracy");
    group.throughput(Throughput::Elements(n_rattle as u64));
    let rattle_time = bench_time(
        &mut group,
        BenchmarkId::new("rattle_cartesian", n_rattle),
        SAMPLES,
        || rattle(n_rattle).q,
    );
    group.throughput(Throughput::Elements(n_verlet as u64));
    let verlet_time = bench_time(&mut group, BenchmarkId::new("verlet_angle", n_verlet), SAMPLES, || {
        verlet(n_verlet).q
    });
    group.finish();
    if let (Some(r), Some(v)) = (rattle_time, verlet_time) {
        println!(
            "pendulum at error {TARGET_ERROR:.0e}: RATTLE {:.1} µs ({:.0} steps/s), Verlet {:.1} µs ({:.0} steps/s); \
             time ratio RATTLE / Verlet = {:.2}, per step {:.2}",
            r * 1e6,
            n_rattle as f64 / r,
            v * 1e6,
            n_verlet as f64 / v,
            r / v,
            (r / n_rattle as f64) / (v / n_verlet as f64)
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(SAMPLES);
    targets = chains, equal_accuracy
}
criterion_main!(benches);
