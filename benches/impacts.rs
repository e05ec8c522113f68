//! Impacts resolved in the core: the cost of one impact, and of contacts that are never hit.
//!
//! `cargo bench --bench impacts`. The circular billiard (a free particle in |q| ≤ 1, a native
//! ellipsoid, verlet) runs with and without its table side by side: the difference per impact
//! is what an impact costs (`billiard/<law>` against `billiard/free`), and the same run in a
//! table it never reaches (radius 10⁶) against no table is the overhead of watching a contact
//! (target ≤ 1.05×). The impacts per run are printed once.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use varmech::integrators::{integrate, integrate_watching, Contacts, Law, Method, Options, Watch};
use varmech::scenes::EllipticBilliard;

#[path = "../tests/rust/common/contacts.rs"]
#[allow(dead_code)] // the others serve the tests
mod contacts;
use contacts::table;

const STEPS: usize = 20_000;
const DT: f64 = 0.05;
const Q0: [f64; 2] = [0.3, -0.2];
const P0: [f64; 2] = [0.6, 0.8];

fn run(free: &EllipticBilliard, contacts: Option<&Contacts<'_>>, method: Method) -> usize {
    let options = Options {
        save_every: STEPS,
        ..Options::new(DT, STEPS)
    };
    let traj = match contacts {
        None => integrate(free, method, &Q0, &P0, &options, || Ok(())),
        Some(contacts) => {
            let watch = Watch {
                events: None,
                contacts: Some(contacts),
                ..Watch::default()
            };
            integrate_watching(free, method, &Q0, &P0, &options, || Ok(()), watch)
        }
    };
    traj.unwrap().impacts.len()
}

fn billiard(c: &mut Criterion) {
    let free = EllipticBilliard::new(1.0, 1.0).unwrap();
    let mut group = c.benchmark_group("billiard");
    let laws = [("reflect", Law::Reflect), ("variational", Law::Variational)];
    for (name, law) in laws {
        let contacts = table(1.0, law);
        // A law the build refuses is left out.
        let options = Options::new(DT, 1);
        let watch = Watch {
            events: None,
            contacts: Some(&contacts),
            ..Watch::default()
        };
        if integrate_watching(&free, Method::Verlet, &Q0, &P0, &options, || Ok(()), watch).is_err() {
            continue;
        }
        eprintln!(
            "billiard/{name}: {} impacts in {STEPS} steps",
            run(&free, Some(&contacts), Method::Verlet)
        );
        group.bench_function(name, |b| {
            b.iter(|| black_box(run(&free, Some(&contacts), Method::Verlet)))
        });
    }
    group.bench_function("free", |b| b.iter(|| black_box(run(&free, None, Method::Verlet))));
    let far = table(1e6, Law::Reflect);
    group.bench_function("never_hit", |b| {
        b.iter(|| black_box(run(&free, Some(&far), Method::Verlet)))
    });
    group.finish();
}

criterion_group!(benches, billiard);
criterion_main!(benches);
