//! Numerical solvers shared by every layer, each allocation-free in its loop:
//!
//! - `lu`: LU factorisation with partial pivoting, in place;
//! - `cholesky`: Cholesky factorisation of a small symmetric positive-definite matrix, in
//!   place, and its triangular solves;
//! - [`difference`]: gradients and Jacobians by central differences;
//!   equations built from them;
//! - `newton`: Newton's method, simplified (a kept Jacobian) or full, with [`NewtonOptions`];
//!   `newton::plain`, its plain form for equations that judge their own residuals, and on a
//!   scalar equation;
//! - `fixed_point`: Picard's iteration x ← G(x), stopped at its round-off floor;
//! - [`bracket`]: a root of a function on a bracket (Illinois, or Newton kept in it), for
//!   locating events, and bisection (of a bracket found by doubling, or of a predicate);
//! - `laguerre`: a root of a scalar function by Laguerre's iteration (Conway's, for Kepler);
//! - `secant`: a root of a scalar function by the secant method, without a bracket;
//! - `secular`: the secular equation of a trust region's boundary (Moré–Sorensen);
//! - [`lanczos`]: the extreme eigenvalues of a symmetric-definite pencil, from its products;
//! - [`interrupt`]: when to poll for Ctrl-C, and the check the iterative solves poll;
//! - `scratch`: per-thread workspaces, for functions whose signatures take none.

/// Calls `$f(args…, n)` with n a literal for n ≤ 8, so that the inlined body (an
/// `#[inline(always)]` function of n) is specialised: the small systems most steps solve then run
/// unrolled loops, where loops of unknown length cost more than their arithmetic.
macro_rules! sized {
    ($f:ident($($arg:expr),*; $n:expr)) => {
        match $n {
            1 => $f($($arg),*, 1),
            2 => $f($($arg),*, 2),
            3 => $f($($arg),*, 3),
            4 => $f($($arg),*, 4),
            5 => $f($($arg),*, 5),
            6 => $f($($arg),*, 6),
            7 => $f($($arg),*, 7),
            8 => $f($($arg),*, 8),
            n => $f($($arg),*, n),
        }
    };
}
pub(crate) use sized;

/// `dst.copy_from_slice(src)` unrolled for n ≤ 8 ([`sized!`]): a step copies a model's few
/// coordinates many times (a force's arguments, the gradients out of their tape, the delayed
/// forces' past), and a call to `memcpy` costs more than the copy of so few numbers (and its
/// masked stores stall the loads that read them back, [`fill`]). Panics where the lengths
/// differ, as `copy_from_slice` does.
#[inline(always)]
pub(crate) fn copy(dst: &mut [f64], src: &[f64]) {
    #[inline(always)]
    fn fixed(dst: &mut [f64], src: &[f64], n: usize) {
        dst.copy_from_slice(&src[..n]);
    }
    sized!(fixed(dst, src; src.len()))
}

/// `dst.fill(value)` unrolled for n ≤ 8, as [`copy`]: glibc's `memset` and `memmove` write so
/// few bytes with masked vector stores, which the loads that soon read them back cannot take
/// from the store buffer.
#[inline(always)]
pub(crate) fn fill(dst: &mut [f64], value: f64) {
    #[inline(always)]
    fn fixed(dst: &mut [f64], value: f64, n: usize) {
        dst[..n].fill(value);
    }
    sized!(fixed(dst, value; dst.len()))
}

pub mod bracket;
pub(crate) mod cholesky;
pub mod difference;
pub(crate) mod fixed_point;
pub mod interrupt;
pub(crate) mod laguerre;
pub mod lanczos;
pub(crate) mod lu;
pub(crate) mod newton;
pub(crate) mod scratch;
pub(crate) mod secant;
pub(crate) mod secular;
pub(crate) mod splitmix;

pub use newton::{Diagnosis, NewtonOptions};
