//! LU factorisation with partial pivoting that allocates nothing, for the Newton loops.
//!
//! Both functions run on the column-major slice of the matrix, specialised for n ≤ 4
//! ([`super::sized`]).

use nalgebra::DMatrix;

/// LU factorisation with partial pivoting, in place (L below the diagonal with unit diagonal,
/// U on and above it); `pivots[i]` is the row swapped into row i. Returns the sign of the
/// determinant, or None for a singular matrix. Written out because nalgebra's `LU`
/// allocates its permutation on every factorisation, and Newton loops must not allocate.
pub(crate) fn lu_in_place(a: &mut DMatrix<f64>, pivots: &mut [usize]) -> Option<f64> {
    let n = a.nrows();
    sized!(factorise(a.as_mut_slice(), pivots; n))
}

#[inline(always)]
fn factorise(a: &mut [f64], pivots: &mut [usize], n: usize) -> Option<f64> {
    let (a, pivots) = (&mut a[..n * n], &mut pivots[..n]);
    let mut sign = 1.0;
    for k in 0..n {
        // The first entry of largest modulus on and below the diagonal (nalgebra's `iamax`).
        let mut piv = k;
        for i in k + 1..n {
            if a[k * n + i].abs() > a[k * n + piv].abs() {
                piv = i;
            }
        }
        pivots[k] = piv;
        let pivot = a[k * n + piv];
        if pivot == 0.0 {
            return None;
        }
        if piv != k {
            sign = -sign;
            for j in 0..n {
                a.swap(j * n + k, j * n + piv);
            }
        }
        sign *= pivot.signum();
        let inv = 1.0 / a[k * n + k];
        for i in k + 1..n {
            a[k * n + i] *= inv;
            let l = a[k * n + i];
            for j in k + 1..n {
                a[j * n + i] -= l * a[j * n + k];
            }
        }
    }
    Some(sign)
}

/// Solves A x = b in place with the factors of [`lu_in_place`]: the row swaps, then L y = b
/// (unit diagonal) and U x = y, column by column: the operations of nalgebra's
/// `solve_lower_triangular_with_diag_mut` and `solve_upper_triangular_mut`, in their order.
pub(crate) fn lu_solve(lu: &DMatrix<f64>, pivots: &[usize], b: &mut [f64]) {
    let n = pivots.len();
    sized!(substitute(lu.as_slice(), pivots, b; n))
}

#[inline(always)]
fn substitute(a: &[f64], pivots: &[usize], b: &mut [f64], n: usize) {
    let (a, b) = (&a[..n * n], &mut b[..n]);
    for (k, &piv) in pivots[..n].iter().enumerate() {
        b.swap(k, piv);
    }
    for k in 0..n {
        let c = b[k];
        for i in k + 1..n {
            b[i] -= c * a[k * n + i];
        }
    }
    for k in (0..n).rev() {
        let c = b[k] / a[k * n + k];
        b[k] = c;
        for i in 0..k {
            b[i] -= c * a[k * n + i];
        }
    }
}
