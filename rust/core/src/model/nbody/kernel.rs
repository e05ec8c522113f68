//! The pair loops of Newtonian gravity, each unique pair once: [`PairKernel`], the
//! instruction set chosen at run time, and the scalar loops (`tiles.rs` holds the vector ones).
//!
//! For bodies i < j with dᵢⱼ = xᵢ − xⱼ, rᵢⱼ² = |dᵢⱼ|² and fᵢⱼ = G mᵢ mⱼ / (rᵢⱼ² √rᵢⱼ²),
//!
//! ∂V/∂xᵢ = Σⱼ₍ⱼ≠ᵢ₎ fᵢⱼ (xᵢ − xⱼ),   V = −Σᵢ<ⱼ G mᵢ mⱼ / rᵢⱼ,
//!
//! so a pair adds +fᵢⱼ dᵢⱼ to body i's gradient and −fᵢⱼ dᵢⱼ to body j's.

#[cfg(target_arch = "x86_64")]
use super::tiles::x86;

/// The instruction set of the pair loops.
///
/// Every kernel computes each pair's terms with the same IEEE operations; the vector kernels
/// fuse the multiply–adds and sum body i's terms lane by lane, so they agree with
/// [`PairKernel::Scalar`] to round-off, not bit for bit. The scalar kernel is the loop of the
/// pair-table model, bit for bit, with each product (G mᵢ)·mⱼ formed as the pair is visited;
/// it runs in place of a vector kernel below two vectors' width of bodies (16 for AVX-512, 8
/// for AVX2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PairKernel {
    /// One pair at a time, plain f64: every target, and the reference of the others.
    Scalar,
    /// Four pairs at a time, AVX2 with FMA (x86-64).
    Avx2,
    /// Eight pairs at a time, AVX-512F (x86-64).
    Avx512,
}

impl PairKernel {
    pub const ALL: [PairKernel; 3] = [PairKernel::Scalar, PairKernel::Avx2, PairKernel::Avx512];

    /// The widest kernel this CPU runs.
    pub fn detect() -> Self {
        [PairKernel::Avx512, PairKernel::Avx2]
            .into_iter()
            .find(|k| k.is_available())
            .unwrap_or(PairKernel::Scalar)
    }

    /// Whether this CPU has the kernel's instructions.
    pub fn is_available(self) -> bool {
        match self {
            PairKernel::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx2 => is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx512 => is_x86_feature_detected!("avx512f"),
            #[cfg(not(target_arch = "x86_64"))]
            PairKernel::Avx2 | PairKernel::Avx512 => false,
        }
    }

    /// Pairs per vector operation.
    pub fn width(self) -> usize {
        match self {
            PairKernel::Scalar => 1,
            PairKernel::Avx2 => 4,
            PairKernel::Avx512 => 8,
        }
    }

    /// The kernel that runs for `n` bodies: below two vectors' width most rows i of the pair
    /// triangle are shorter than one vector, mostly masked lanes, and the scalar loop is faster
    /// (the outer solar system, N = 6, would lose 20% a step to AVX-512).
    fn for_bodies(self, n: usize) -> Self {
        if n < 2 * self.width() {
            PairKernel::Scalar
        } else {
            self
        }
    }

    /// ∇V(q) into `grad`, for gm = (G mᵢ) and m = (mᵢ); q and grad body by body.
    ///
    /// The kernel must be available ([`NBody`](super::NBody) only holds one that is).
    pub(super) fn gradient(self, gm: &[f64], m: &[f64], q: &[f64], grad: &mut [f64]) {
        debug_assert!(self.is_available());
        match self.for_bodies(m.len()) {
            // SAFETY: the CPU has the kernel's features (the caller's contract).
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx2 => unsafe { x86::gradient_avx2(gm, m, q, grad) },
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx512 => unsafe { x86::gradient_avx512(gm, m, q, grad) },
            _ => scalar_gradient(gm, m, q, grad),
        }
    }

    /// V(q), as [`PairKernel::gradient`].
    pub(super) fn potential(self, gm: &[f64], m: &[f64], q: &[f64]) -> f64 {
        debug_assert!(self.is_available());
        match self.for_bodies(m.len()) {
            // SAFETY: the CPU has the kernel's features (the caller's contract).
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx2 => unsafe { x86::potential_avx2(gm, m, q) },
            #[cfg(target_arch = "x86_64")]
            PairKernel::Avx512 => unsafe { x86::potential_avx512(gm, m, q) },
            _ => scalar_potential(gm, m, q),
        }
    }
}

/// ∇V(q) into `grad`, one pair at a time straight from q (body by body): body i's sums in
/// registers, body j's in `grad`. For a few bodies a tile's copies would cost more than the
/// pairs.
fn scalar_gradient(gm: &[f64], m: &[f64], q: &[f64], grad: &mut [f64]) {
    grad.fill(0.0);
    for (i, &gmi) in gm.iter().enumerate() {
        let (head, tail) = grad.split_at_mut(3 * i + 3);
        let xi = &q[3 * i..3 * i + 3];
        let mut gi = [0.0; 3];
        for ((xj, gj), mj) in q[3 * i + 3..]
            .chunks_exact(3)
            .zip(tail.chunks_exact_mut(3))
            .zip(&m[i + 1..])
        {
            let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            // G mᵢ mⱼ, the product the pair table held.
            let f = gmi * mj / (r2 * r2.sqrt());
            for c in 0..3 {
                gi[c] += f * d[c];
                gj[c] -= f * d[c];
            }
        }
        for (g, v) in head[3 * i..].iter_mut().zip(gi) {
            *g += v;
        }
    }
}

/// V(q), one pair at a time, as [`scalar_gradient`].
fn scalar_potential(gm: &[f64], m: &[f64], q: &[f64]) -> f64 {
    let mut v = 0.0;
    for (i, (xi, &gmi)) in q.chunks_exact(3).zip(gm).enumerate() {
        for (xj, mj) in q[3 * i + 3..].chunks_exact(3).zip(&m[i + 1..]) {
            let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
            v -= gmi * mj / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        }
    }
    v
}
