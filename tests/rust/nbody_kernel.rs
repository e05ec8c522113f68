//! The N-body pair kernels (`model::PairKernel`): the SIMD kernels agree with the scalar one to
//! round-off, the scalar one reproduces the pair-table loops bit for bit, ∇V is the derivative
//! of V, and Σᵢ ∂V/∂xᵢ = 0 (translation invariance) to round-off; on random Plummer clusters of
//! sizes that leave every vector remainder and cross the 256-body tiles.

use crate::common::Points;
use varmech::model::{MechanicalSystem, NBody, PairKernel};

const EPS: f64 = f64::EPSILON;
const SIZES: [usize; 7] = [2, 3, 7, 64, 257, 300, 513];

/// N bodies of total mass 1 (each in [0.5, 1.5]/N) at Plummer radii r = (u^(−2/3) − 1)^(−1/2)
/// (u uniform in (0, 0.99]: no body beyond r ≈ 7) in uniform directions; G = 1.
fn plummer(n: usize, seed: u64) -> (NBody, Vec<f64>) {
    let mut rng = Points(seed);
    let masses = (0..n).map(|_| (1.0 + rng.uniform(0.5)) / n as f64).collect();
    let q = (0..n)
        .flat_map(|_| {
            let u = 0.495 + rng.uniform(0.495);
            let r = (u.powf(-2.0 / 3.0) - 1.0).powf(-0.5);
            let z = rng.uniform(1.0);
            let phi = std::f64::consts::PI * rng.uniform(1.0);
            let s = (1.0 - z * z).sqrt();
            [r * s * phi.cos(), r * s * phi.sin(), r * z]
        })
        .collect();
    (NBody::new(1.0, masses).unwrap(), q)
}

/// The loops of the pair-table model: a table of (G mᵢ) mⱼ for i < j and one pass over it, in
/// the order the scalar kernel must reproduce. Returns V, ∇V and, per coordinate, the sum of
/// the magnitudes of its terms, Σⱼ |fᵢⱼ dᵢⱼ|.
fn pair_table(system: &NBody, q: &[f64]) -> (f64, Vec<f64>, Vec<f64>) {
    let m = system.masses();
    let n = m.len();
    let gmm: Vec<f64> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| system.gravitational_constant() * m[i] * m[j])
        .collect();
    let (mut v, mut grad, mut size) = (0.0, vec![0.0; 3 * n], vec![0.0; 3 * n]);
    let mut k = 0;
    for i in 0..n {
        let mut gi = [0.0; 3];
        for j in i + 1..n {
            let d = [
                q[3 * i] - q[3 * j],
                q[3 * i + 1] - q[3 * j + 1],
                q[3 * i + 2] - q[3 * j + 2],
            ];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            v -= gmm[k] / r2.sqrt();
            let f = gmm[k] / (r2 * r2.sqrt());
            for c in 0..3 {
                gi[c] += f * d[c];
                grad[3 * j + c] -= f * d[c];
                size[3 * i + c] += (f * d[c]).abs();
                size[3 * j + c] += (f * d[c]).abs();
            }
            k += 1;
        }
        for c in 0..3 {
            grad[3 * i + c] += gi[c];
        }
    }
    (v, grad, size)
}

/// Σ |G mᵢ mⱼ / rᵢⱼ|, the size V's round-off is judged against.
fn potential_size(system: &NBody, q: &[f64]) -> f64 {
    // At positive masses −V is a sum of positive terms: its own size.
    -system
        .clone()
        .with_kernel(PairKernel::Scalar)
        .unwrap()
        .potential(q)
        .unwrap()
}

fn gradient(system: &NBody, q: &[f64]) -> Vec<f64> {
    let mut g = vec![0.0; q.len()];
    system.gradient(q, &mut g).unwrap();
    g
}

#[test]
fn nbody_is_send_and_sync_and_picks_the_widest_kernel_of_the_cpu() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<NBody>();
    let (system, _) = plummer(3, 1);
    assert_eq!(system.kernel(), PairKernel::detect());
    assert!(system.kernel().is_available());
    #[cfg(target_arch = "x86_64")]
    if is_x86_feature_detected!("avx512f") {
        assert_eq!(system.kernel(), PairKernel::Avx512);
    }
    for kernel in PairKernel::ALL {
        match system.clone().with_kernel(kernel) {
            Ok(s) => assert_eq!(s.kernel(), kernel),
            Err(e) => {
                assert!(!kernel.is_available());
                assert!(e.to_string().starts_with("kernel:"), "{e}");
            }
        }
    }
}

/// The scalar kernel adds the same terms in the same order as the pair-table loops, whose
/// products it forms as (G mᵢ)·mⱼ like the table did: the same bits.
#[test]
fn the_scalar_kernel_reproduces_the_pair_table_loops_bit_for_bit() {
    for n in SIZES {
        let (system, q) = plummer(n, n as u64);
        let scalar = system.with_kernel(PairKernel::Scalar).unwrap();
        let (v, grad, _) = pair_table(&scalar, &q);
        assert_eq!(scalar.potential(&q).unwrap().to_bits(), v.to_bits(), "N = {n}");
        let g = gradient(&scalar, &q);
        assert!(g.iter().zip(&grad).all(|(a, b)| a.to_bits() == b.to_bits()), "N = {n}");
    }
}

/// Each kernel computes the same terms t = fᵢⱼ dᵢⱼ with the same IEEE operations, except that
/// the vector kernels fuse the multiply–adds of r² (2 roundings fewer, r² relative change
/// ≤ 2ε, hence f's ≤ 3ε and t's ≤ 4ε) and of the sums. A component of ∇V sums at most N − 1
/// terms, in order (scalar) or lane by lane then across the lanes (vector): each sum is within
/// (N − 1)ε Σ|t| of the exact sum of its own terms (recursive summation, Higham 2002, §4.2),
/// and the terms differ by ≤ 4ε|t| plus their own few roundings. So
///
/// |∂V/∂x_SIMD − ∂V/∂x_scalar| ≤ (2N + 16) ε Σ|t|  per component,
///
/// and for V (P = N(N − 1)/2 terms), |V_SIMD − V_scalar| ≤ (2P + 16) ε Σ|G mᵢmⱼ/rᵢⱼ|. A pair
/// missed or counted twice would be off by a whole term, ≫ this on every size tested.
#[test]
fn simd_and_scalar_kernels_agree_to_round_off() {
    let available: Vec<PairKernel> = PairKernel::ALL.into_iter().filter(|k| k.is_available()).collect();
    for n in SIZES {
        let (system, q) = plummer(n, 100 + n as u64);
        let scalar = system.clone().with_kernel(PairKernel::Scalar).unwrap();
        let (_, _, size) = pair_table(&scalar, &q);
        let (g_scalar, v_scalar) = (gradient(&scalar, &q), scalar.potential(&q).unwrap());
        let v_size = potential_size(&system, &q);
        for &kernel in &available {
            let simd = system.clone().with_kernel(kernel).unwrap();
            let g = gradient(&simd, &q);
            let bound = (2 * n + 16) as f64 * EPS;
            let worst = g
                .iter()
                .zip(&g_scalar)
                .zip(&size)
                .map(|((a, b), s)| (a - b).abs() / (bound * s))
                .fold(0.0, f64::max);
            assert!(
                worst <= 1.0,
                "{kernel:?}, N = {n}: gradient off by {worst:.3} of the bound"
            );
            let pairs = n * (n - 1) / 2;
            let dv = (simd.potential(&q).unwrap() - v_scalar).abs();
            let v_bound = (2 * pairs + 16) as f64 * EPS * v_size;
            assert!(dv <= v_bound, "{kernel:?}, N = {n}: |ΔV| = {dv:e} > {v_bound:e}");
        }
    }
}

/// Every kernel's ∇V is the derivative of its V: central differences with step h = 1e-4 (the
/// bodies are ≥ about 1e-2 apart in these clusters) have truncation error h²/6·|V'''| and
/// round-off about ε|V|/h, together below 1e-6 of the gradient's size Σ|t| here.
#[test]
fn the_gradient_is_the_derivative_of_the_potential() {
    let h = 1e-4;
    for n in [2, 3, 7, 64] {
        let (system, q) = plummer(n, 200 + n as u64);
        let (_, _, size) = pair_table(&system, &q);
        for kernel in PairKernel::ALL.into_iter().filter(|k| k.is_available()) {
            let system = system.clone().with_kernel(kernel).unwrap();
            let g = gradient(&system, &q);
            for k in 0..q.len() {
                let mut at = q.clone();
                at[k] = q[k] + h;
                let up = system.potential(&at).unwrap();
                at[k] = q[k] - h;
                let down = system.potential(&at).unwrap();
                let difference = (up - down) / (2.0 * h);
                assert!(
                    (difference - g[k]).abs() <= 1e-6 * size[k],
                    "{kernel:?}, N = {n}, coordinate {k}: difference {difference:e}, gradient {:e}",
                    g[k]
                );
            }
        }
    }
}

/// Translation invariance, V(x + a) = V(x): Σᵢ ∂V/∂xᵢ = 0. Each pair adds +t to body i and −t
/// to body j, the same computed t, so only the summation round-off remains: at most
/// (N − 1)ε per sum over the 2·(terms) of a coordinate, then N sums, ≤ 2Nε Σ|t| in all.
#[test]
fn the_forces_sum_to_zero_to_round_off() {
    for n in SIZES {
        let (system, q) = plummer(n, 300 + n as u64);
        let (_, _, size) = pair_table(&system, &q);
        for kernel in PairKernel::ALL.into_iter().filter(|k| k.is_available()) {
            let g = gradient(&system.clone().with_kernel(kernel).unwrap(), &q);
            for c in 0..3 {
                let total: f64 = g.iter().skip(c).step_by(3).sum();
                let scale: f64 = size.iter().skip(c).step_by(3).sum();
                let bound = 2.0 * n as f64 * EPS * scale;
                assert!(
                    total.abs() <= bound,
                    "{kernel:?}, N = {n}, axis {c}: Σ∇V = {total:e} > {bound:e}"
                );
            }
        }
    }
}
