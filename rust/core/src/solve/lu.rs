//! LU factorisation with partial pivoting that allocates nothing, for the Newton loops.
//!
//! Both functions run on the column-major slice of the matrix, specialised for n ≤ 8
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
pub(crate) fn factorise(a: &mut [f64], pivots: &mut [usize], n: usize) -> Option<f64> {
    let (a, pivots) = (&mut a[..n * n], &mut pivots[..n]);
    let mut sign = 1.0;
    for k in 0..n {
        // The first entry of largest modulus on and below the diagonal (nalgebra's `iamax`).
        let column = &a[k * n..(k + 1) * n];
        let mut piv = k;
        for i in k + 1..n {
            if column[i].abs() > column[piv].abs() {
                piv = i;
            }
        }
        pivots[k] = piv;
        let pivot = column[piv];
        if pivot == 0.0 {
            return None;
        }
        if piv != k {
            sign = -sign;
            a.chunks_exact_mut(n).for_each(|c| c.swap(k, piv));
        }
        sign *= pivot.signum();
        // Column by column, each entry taking the same one update per k as row by row.
        let (left, right) = a.split_at_mut((k + 1) * n);
        let column = &mut left[k * n..];
        let inv = 1.0 / column[k];
        column[k + 1..].iter_mut().for_each(|l| *l *= inv);
        for c in right.chunks_exact_mut(n) {
            let u = c[k];
            for (x, l) in c[k + 1..].iter_mut().zip(&column[k + 1..]) {
                *x -= l * u;
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
pub(crate) fn substitute(a: &[f64], pivots: &[usize], b: &mut [f64], n: usize) {
    let (a, b) = (&a[..n * n], &mut b[..n]);
    for (k, &piv) in pivots[..n].iter().enumerate() {
        b.swap(k, piv);
    }
    for (k, column) in a.chunks_exact(n).enumerate() {
        let (head, tail) = b.split_at_mut(k + 1);
        let c = head[k];
        tail.iter_mut().zip(&column[k + 1..]).for_each(|(x, l)| *x -= c * l);
    }
    for (k, column) in a.chunks_exact(n).enumerate().rev() {
        let (head, tail) = b.split_at_mut(k);
        let c = tail[0] / column[k];
        tail[0] = c;
        head.iter_mut().zip(&column[..k]).for_each(|(x, u)| *x -= c * u);
    }
}
