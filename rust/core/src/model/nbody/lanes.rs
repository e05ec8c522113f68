//! SIMD lanes of f64: the few operations the pair loops need, for AVX2 + FMA (4 lanes) and
//! AVX-512F (8 lanes) on x86-64. Other targets run the scalar loops.
//!
//! The vector operations are `#[target_feature]` functions: the pair loops, generic over
//! [`Lanes`] and `#[inline(always)]`, are instantiated inside functions that enable the same
//! features (`kernel.rs`), which is where these inline.

/// A vector of [`Lanes::WIDTH`] f64 with IEEE arithmetic per lane.
///
/// # Safety
///
/// The methods are `unsafe` because the vector types need their CPU features: callers must
/// have checked them ([`super::PairKernel::is_available`]). Loads read and stores write
/// `WIDTH` consecutive f64 from the pointer (no alignment required).
pub(super) trait Lanes: Copy {
    const WIDTH: usize;
    unsafe fn splat(x: f64) -> Self;
    unsafe fn load(p: *const f64) -> Self;
    unsafe fn store(self, p: *mut f64);
    unsafe fn add(self, b: Self) -> Self;
    unsafe fn sub(self, b: Self) -> Self;
    unsafe fn mul(self, b: Self) -> Self;
    unsafe fn div(self, b: Self) -> Self;
    unsafe fn sqrt(self) -> Self;
    /// a·b + c, fused where the lanes have FMA (then rounded once, not twice).
    unsafe fn mul_add(self, b: Self, c: Self) -> Self;
    /// c − a·b, fused where the lanes have FMA.
    unsafe fn neg_mul_add(self, b: Self, c: Self) -> Self;
    /// The sum of the lanes, in a fixed order.
    unsafe fn sum(self) -> f64;
    /// The first `count` < WIDTH f64 from the pointer and zeros after them (the rest is not
    /// read): a vector loop's remainder.
    unsafe fn load_first(p: *const f64, count: usize) -> Self;
    /// Stores the first `count` < WIDTH lanes (the rest is not written).
    unsafe fn store_first(self, p: *mut f64, count: usize);
    /// 0 in the first `count` < WIDTH lanes, 1 after: added to a remainder's denominators, it
    /// keeps the lanes past the end finite.
    unsafe fn past(count: usize) -> Self;
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Lanes;
    use std::arch::x86_64::*;

    /// The [`Lanes`] methods that are one intrinsic of the lanes: `name(b, …) = intrinsic` gives
    /// `name(self, b, …)`, `intrinsic(self, b, …)`.
    macro_rules! lane_ops {
        ($features:literal; $($name:ident($($arg:ident),*) = $intrinsic:ident),* $(,)?) => {
            $(
                #[inline]
                #[target_feature(enable = $features)]
                unsafe fn $name(self, $($arg: Self),*) -> Self {
                    $intrinsic(self, $($arg),*)
                }
            )*
        };
    }

    /// Generates the [`Lanes`] impl of one x86 vector type from its intrinsics.
    macro_rules! lanes {
        ($t:ty, $width:expr, $features:literal, $set1:ident, $loadu:ident, $storeu:ident, $add:ident,
         $sub:ident, $mul:ident, $div:ident, $sqrt:ident, $fmadd:ident, $fnmadd:ident, |$v:ident| $sum:block, $($remainder:item),* $(,)?) => {
            impl Lanes for $t {
                const WIDTH: usize = $width;
                #[inline]
                #[target_feature(enable = $features)]
                unsafe fn splat(x: f64) -> Self {
                    $set1(x)
                }
                #[inline]
                #[target_feature(enable = $features)]
                unsafe fn load(p: *const f64) -> Self {
                    unsafe { $loadu(p) }
                }
                #[inline]
                #[target_feature(enable = $features)]
                unsafe fn store(self, p: *mut f64) {
                    unsafe { $storeu(p, self) }
                }
                lane_ops!(
                    $features;
                    add(b) = $add,
                    sub(b) = $sub,
                    mul(b) = $mul,
                    div(b) = $div,
                    sqrt() = $sqrt,
                    mul_add(b, c) = $fmadd,
                    neg_mul_add(b, c) = $fnmadd,
                );
                #[inline]
                #[target_feature(enable = $features)]
                unsafe fn sum(self) -> f64 {
                    let $v = self;
                    $sum
                }
                $($remainder)*
            }
        };
    }

    lanes!(
        __m256d,
        4,
        "avx2,fma",
        _mm256_set1_pd,
        _mm256_loadu_pd,
        _mm256_storeu_pd,
        _mm256_add_pd,
        _mm256_sub_pd,
        _mm256_mul_pd,
        _mm256_div_pd,
        _mm256_sqrt_pd,
        _mm256_fmadd_pd,
        _mm256_fnmadd_pd,
        |v| {
            // (lane 0 + lane 2) + (lane 1 + lane 3).
            let half = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd::<1>(v));
            _mm_cvtsd_f64(_mm_add_sd(half, _mm_unpackhi_pd(half, half)))
        },
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn load_first(p: *const f64, count: usize) -> Self {
            unsafe { _mm256_maskload_pd(p, first(count)) }
        },
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn store_first(self, p: *mut f64, count: usize) {
            unsafe { _mm256_maskstore_pd(p, first(count), self) }
        },
        #[inline]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn past(count: usize) -> Self {
            _mm256_andnot_pd(_mm256_castsi256_pd(first(count)), _mm256_set1_pd(1.0))
        }
    );

    /// All ones in the first `count` 64-bit lanes, zeros after.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn first(count: usize) -> __m256i {
        _mm256_cmpgt_epi64(_mm256_set1_epi64x(count as i64), _mm256_setr_epi64x(0, 1, 2, 3))
    }

    lanes!(
        __m512d,
        8,
        "avx512f",
        _mm512_set1_pd,
        _mm512_loadu_pd,
        _mm512_storeu_pd,
        _mm512_add_pd,
        _mm512_sub_pd,
        _mm512_mul_pd,
        _mm512_div_pd,
        _mm512_sqrt_pd,
        _mm512_fmadd_pd,
        _mm512_fnmadd_pd,
        |v| {
            // The 4-lane sum of (lanes 0–3) + (lanes 4–7).
            let half = _mm256_add_pd(_mm512_castpd512_pd256(v), _mm512_extractf64x4_pd::<1>(v));
            let half = _mm_add_pd(_mm256_castpd256_pd128(half), _mm256_extractf128_pd::<1>(half));
            _mm_cvtsd_f64(_mm_add_sd(half, _mm_unpackhi_pd(half, half)))
        },
        #[inline]
        #[target_feature(enable = "avx512f")]
        unsafe fn load_first(p: *const f64, count: usize) -> Self {
            unsafe { _mm512_maskz_loadu_pd((1u8 << count) - 1, p) }
        },
        #[inline]
        #[target_feature(enable = "avx512f")]
        unsafe fn store_first(self, p: *mut f64, count: usize) {
            unsafe { _mm512_mask_storeu_pd(p, (1u8 << count) - 1, self) }
        },
        #[inline]
        #[target_feature(enable = "avx512f")]
        unsafe fn past(count: usize) -> Self {
            _mm512_maskz_mov_pd(!((1u8 << count) - 1), _mm512_set1_pd(1.0))
        }
    );
}
