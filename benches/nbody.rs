//! The N-body gradient per unique pair, each pair kernel, against the throughput limit of its
//! arithmetic.
//!
//! `cargo bench --bench nbody`. Criterion's throughput is in pairs: ns per unique pair is
//! 1000 / (Melem/s).
//!
//! - `nbody_gradient/<kernel>/<N>`: ∇V of a Plummer cluster of N bodies, N(N − 1)/2 pairs;
//! - `inverse_cube_limit/<kernel>`: f = (G mᵢ)·mⱼ / (r²·√r²) over contiguous arrays of r² and
//!   mⱼ, vectorised by the compiler with the kernel's instructions, with no pair bookkeeping
//!   (differences, accumulators): the square root and the division are what a pair cannot
//!   avoid, so this is the floor ns per pair is judged against.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;
use varmech::model::{MechanicalSystem, NBody, PairKernel};

/// N bodies of total mass 1 at Plummer radii in uniform directions (a fixed linear congruential
/// sequence: the same cluster every run).
fn plummer(n: usize) -> (NBody, Vec<f64>) {
    let mut state = 12345u64;
    let mut unit = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let masses = (0..n).map(|_| (0.5 + unit()) / n as f64).collect();
    let q = (0..n)
        .flat_map(|_| {
            let r = ((0.01 + 0.98 * unit()).powf(-2.0 / 3.0) - 1.0).powf(-0.5);
            let z = 2.0 * unit() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * unit();
            let s = (1.0 - z * z).sqrt();
            [r * s * phi.cos(), r * s * phi.sin(), r * z]
        })
        .collect();
    (NBody::new(1.0, masses).unwrap(), q)
}

fn available() -> impl Iterator<Item = PairKernel> {
    PairKernel::ALL.into_iter().filter(|k| k.is_available())
}

fn gradient(c: &mut Criterion) {
    let mut group = c.benchmark_group("nbody_gradient");
    for n in [64, 256, 1024] {
        let (system, q) = plummer(n);
        let mut grad = vec![0.0; 3 * n];
        group.throughput(Throughput::Elements((n * (n - 1) / 2) as u64));
        for kernel in available() {
            let system = system.clone().with_kernel(kernel).unwrap();
            group.bench_function(BenchmarkId::new(format!("{kernel:?}"), n), |b| {
                b.iter(|| system.gradient(black_box(&q), &mut grad).unwrap())
            });
        }
    }
    group.finish();
}

/// f = (G mᵢ)·mⱼ / (r²·√r²) for each j.
#[inline(always)]
fn inverse_cubes(gmi: f64, m: &[f64], r2: &[f64], f: &mut [f64]) {
    for ((f, m), r2) in f.iter_mut().zip(m).zip(r2) {
        *f = gmi * m / (r2 * r2.sqrt());
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn inverse_cubes_avx2(gmi: f64, m: &[f64], r2: &[f64], f: &mut [f64]) {
    inverse_cubes(gmi, m, r2, f)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn inverse_cubes_avx512(gmi: f64, m: &[f64], r2: &[f64], f: &mut [f64]) {
    inverse_cubes(gmi, m, r2, f)
}

fn limit(c: &mut Criterion) {
    const LEN: usize = 1024;
    let mut group = c.benchmark_group("inverse_cube_limit");
    group.throughput(Throughput::Elements(LEN as u64));
    let m: Vec<f64> = (0..LEN).map(|j| 1.0 + j as f64 / LEN as f64).collect();
    let r2: Vec<f64> = (0..LEN).map(|j| 0.5 + (j * 7 % LEN) as f64 / 64.0).collect();
    let mut f = vec![0.0; LEN];
    for kernel in available() {
        let run: fn(f64, &[f64], &[f64], &mut [f64]) = match kernel {
            // SAFETY (both): the kernel is available, so the CPU has the features.
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx2 => |g, m, r2, f| unsafe { inverse_cubes_avx2(g, m, r2, f) },
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx512 => |g, m, r2, f| unsafe { inverse_cubes_avx512(g, m, r2, f) },
            _ => inverse_cubes,
        };
        group.bench_function(format!("{kernel:?}"), |b| {
            b.iter(|| run(black_box(0.5), black_box(&m), black_box(&r2), &mut f))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(30);
    targets = gradient, limit
}
criterion_main!(benches);
