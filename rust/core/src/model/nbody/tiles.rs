//! The vector pair loops: the bodies j taken a tile of [`TILE`] at a time, in
//! structure-of-arrays layout.
//!
//! The tile holds the bodies' x, y and z as three contiguous arrays, and their gradient
//! accumulators likewise, so that the loop over j (for each i < j) loads, updates and stores
//! whole vectors of consecutive bodies, with no gather or scatter; body i's own sums stay in
//! registers. A tile lives on the stack (48 bytes a body, in L1): no allocation, nothing
//! shared between threads. The equations are in `kernel.rs`.

use super::lanes::Lanes;
use std::mem::MaybeUninit;

/// Bodies per tile: 12 KiB of positions and accumulators.
const TILE: usize = 256;

/// The bodies j0..j0 + len in structure-of-arrays layout: coordinate c of body j0 + k at
/// `x[c·TILE + k]`, and its gradient accumulator at `acc[c·TILE + k]`; only the first `len`
/// of each third are written (a small N touches a few cache lines, not 12 KiB).
struct Tile {
    x: [MaybeUninit<f64>; 3 * TILE],
    acc: [MaybeUninit<f64>; 3 * TILE],
}

impl Tile {
    #[inline(always)]
    fn new() -> Self {
        Tile {
            x: [MaybeUninit::uninit(); 3 * TILE],
            acc: [MaybeUninit::uninit(); 3 * TILE],
        }
    }

    /// Copies the positions of `bodies` (body by body, at most TILE) and zeroes their
    /// accumulators.
    #[inline(always)]
    fn fill(&mut self, bodies: &[f64]) {
        for (k, body) in bodies.chunks_exact(3).enumerate() {
            for (c, &x) in body.iter().enumerate() {
                self.x[c * TILE + k].write(x);
                self.acc[c * TILE + k].write(0.0);
            }
        }
    }
}

/// The gradient of the pairs of body i (at `xi`, with G mᵢ = `gmi`) with the tile's bodies
/// `start..len` (m: their masses): returns body i's part, Σⱼ fᵢⱼ dᵢⱼ, and subtracts fᵢⱼ dᵢⱼ
/// from each body j's accumulator. Vectors of `V::WIDTH` bodies, the remainder a vector with
/// its lanes past the end switched off.
///
/// # Safety
/// `V`'s features are enabled; `tile` holds `len` bodies; `m` has `len` entries.
#[inline(always)]
unsafe fn pairs<V: Lanes>(xi: &[f64], gmi: f64, tile: &mut Tile, m: *const f64, start: usize, len: usize) -> [f64; 3] {
    let x = tile.x.as_ptr().cast::<f64>();
    let acc = tile.acc.as_mut_ptr().cast::<f64>();
    unsafe {
        let mut gi = [V::splat(0.0); 3];
        let mut j = start;
        while j + V::WIDTH <= len {
            pair::<V, false>(xi, gmi, x, acc, m, j, 0, &mut gi);
            j += V::WIDTH;
        }
        if j < len {
            pair::<V, true>(xi, gmi, x, acc, m, j, len - j, &mut gi);
        }
        [gi[0].sum(), gi[1].sum(), gi[2].sum()]
    }
}

/// The pairs (i, j..j + WIDTH): gᵢ += fᵢⱼ dᵢⱼ, accⱼ −= fᵢⱼ dᵢⱼ; with `PARTIAL`, only the first
/// `count` < WIDTH of them: the other lanes read mass 0 and position 0, whose denominator
/// [`Lanes::past`] keeps positive, so they add exactly 0, and store nothing.
///
/// # Safety
/// As [`pairs`], with j + WIDTH ≤ len, or j + count ≤ len with `PARTIAL`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn pair<V: Lanes, const PARTIAL: bool>(
    xi: &[f64],
    gmi: f64,
    x: *const f64,
    acc: *mut f64,
    m: *const f64,
    j: usize,
    count: usize,
    gi: &mut [V; 3],
) {
    unsafe {
        let d: [V; 3] = std::array::from_fn(|c| V::splat(xi[c]).sub(load::<V, PARTIAL>(x.add(c * TILE + j), count)));
        let mut r2 = d[2].mul_add(d[2], d[1].mul_add(d[1], d[0].mul(d[0])));
        if PARTIAL {
            r2 = r2.add(V::past(count));
        }
        // G mᵢ mⱼ, the product the pair table held.
        let k = V::splat(gmi).mul(load::<V, PARTIAL>(m.add(j), count));
        let f = k.div(r2.mul(r2.sqrt()));
        for c in 0..3 {
            gi[c] = f.mul_add(d[c], gi[c]);
            let a = acc.add(c * TILE + j);
            let updated = f.neg_mul_add(d[c], load::<V, PARTIAL>(a, count));
            if PARTIAL {
                updated.store_first(a, count)
            } else {
                updated.store(a)
            }
        }
    }
}

/// The WIDTH f64 from `p`, or with `PARTIAL` the first `count` and zeros.
///
/// # Safety
/// As [`Lanes::load`] and [`Lanes::load_first`].
#[inline(always)]
unsafe fn load<V: Lanes, const PARTIAL: bool>(p: *const f64, count: usize) -> V {
    unsafe {
        if PARTIAL {
            V::load_first(p, count)
        } else {
            V::load(p)
        }
    }
}

/// ∇V(q) into `grad`: for each tile of bodies j, every body i < j against it.
///
/// # Safety
/// `V`'s features are enabled; gm and m have N entries, q and grad 3N.
#[inline(always)]
unsafe fn gradient<V: Lanes>(gm: &[f64], m: &[f64], q: &[f64], grad: &mut [f64]) {
    let n = m.len();
    grad.fill(0.0);
    let mut tile = Tile::new();
    for j0 in (0..n).step_by(TILE) {
        let len = TILE.min(n - j0);
        tile.fill(&q[3 * j0..3 * (j0 + len)]);
        for i in 0..j0 + len - 1 {
            let start = (i + 1).saturating_sub(j0);
            // SAFETY: the tile holds `len` bodies and m[j0..] at least `len`.
            let gi = unsafe { pairs::<V>(&q[3 * i..3 * i + 3], gm[i], &mut tile, m[j0..].as_ptr(), start, len) };
            for (g, v) in grad[3 * i..3 * i + 3].iter_mut().zip(gi) {
                *g += v;
            }
        }
        for (k, g) in grad[3 * j0..3 * (j0 + len)].chunks_exact_mut(3).enumerate() {
            for (c, g) in g.iter_mut().enumerate() {
                // SAFETY: `fill` wrote the first `len` accumulators of each coordinate.
                *g += unsafe { tile.acc[c * TILE + k].assume_init() };
            }
        }
    }
}

/// V(q) = −Σᵢ<ⱼ G mᵢ mⱼ / rᵢⱼ, summed lane by lane over the whole sweep.
///
/// # Safety
/// As [`gradient`].
#[inline(always)]
unsafe fn potential<V: Lanes>(gm: &[f64], m: &[f64], q: &[f64]) -> f64 {
    let n = m.len();
    let mut tile = Tile::new();
    unsafe {
        let mut v = V::splat(0.0);
        for j0 in (0..n).step_by(TILE) {
            let len = TILE.min(n - j0);
            tile.fill(&q[3 * j0..3 * (j0 + len)]);
            let (x, m) = (tile.x.as_ptr().cast::<f64>(), m[j0..].as_ptr());
            for i in 0..j0 + len - 1 {
                let xi = &q[3 * i..3 * i + 3];
                let mut j = (i + 1).saturating_sub(j0);
                while j + V::WIDTH <= len {
                    v = v.sub(term::<V, false>(xi, gm[i], x, m, j, 0));
                    j += V::WIDTH;
                }
                if j < len {
                    v = v.sub(term::<V, true>(xi, gm[i], x, m, j, len - j));
                }
            }
        }
        v.sum()
    }
}

/// G mᵢ mⱼ / rᵢⱼ for the bodies j..j + WIDTH of the tile at `x`, or with `PARTIAL` the first
/// `count` of them and 0 in the other lanes, as in [`pair`].
///
/// # Safety
/// As [`pair`].
#[inline(always)]
unsafe fn term<V: Lanes, const PARTIAL: bool>(
    xi: &[f64],
    gmi: f64,
    x: *const f64,
    m: *const f64,
    j: usize,
    count: usize,
) -> V {
    unsafe {
        let d: [V; 3] = std::array::from_fn(|c| V::splat(xi[c]).sub(load::<V, PARTIAL>(x.add(c * TILE + j), count)));
        let mut r2 = d[2].mul_add(d[2], d[1].mul_add(d[1], d[0].mul(d[0])));
        if PARTIAL {
            r2 = r2.add(V::past(count));
        }
        V::splat(gmi).mul(load::<V, PARTIAL>(m.add(j), count)).div(r2.sqrt())
    }
}

/// The loops instantiated with the x86 vector lanes, inside functions that enable their
/// features so that the lanes' intrinsics inline.
pub(super) mod x86 {
    use std::arch::x86_64::{__m256d, __m512d};

    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn gradient_avx2(gm: &[f64], m: &[f64], q: &[f64], grad: &mut [f64]) {
        unsafe { super::gradient::<__m256d>(gm, m, q, grad) }
    }

    #[target_feature(enable = "avx512f")]
    pub unsafe fn gradient_avx512(gm: &[f64], m: &[f64], q: &[f64], grad: &mut [f64]) {
        unsafe { super::gradient::<__m512d>(gm, m, q, grad) }
    }

    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn potential_avx2(gm: &[f64], m: &[f64], q: &[f64]) -> f64 {
        unsafe { super::potential::<__m256d>(gm, m, q) }
    }

    #[target_feature(enable = "avx512f")]
    pub unsafe fn potential_avx512(gm: &[f64], m: &[f64], q: &[f64]) -> f64 {
        unsafe { super::potential::<__m512d>(gm, m, q) }
    }
}
