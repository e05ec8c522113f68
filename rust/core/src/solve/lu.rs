//! LU factorisation with partial pivoting that allocates nothing, for the Newton loops.

use nalgebra::{DMatrix, DVector};

/// LU factorisation with partial pivoting, in place (L below the diagonal with unit diagonal,
/// U on and above it); `pivots[i]` is the row swapped into row i. Returns the sign of the
/// determinant, or None for a singular matrix. Written out because nalgebra's `LU`
/// allocates its permutation on every factorisation, and Newton loops must not allocate.
pub(crate) fn lu_in_place(a: &mut DMatrix<f64>, pivots: &mut [usize]) -> Option<f64> {
    let n = a.nrows();
    let mut sign = 1.0;
    for k in 0..n {
        let piv = k + a.view_range(k.., k).iamax();
        pivots[k] = piv;
        if a[(piv, k)] == 0.0 {
            return None;
        }
        if piv != k {
            sign = -sign;
        }
        sign *= a[(piv, k)].signum();
        a.swap_rows(k, piv);
        let inv = 1.0 / a[(k, k)];
        for i in k + 1..n {
            a[(i, k)] *= inv;
            let l = a[(i, k)];
            for j in k + 1..n {
                a[(i, j)] -= l * a[(k, j)];
            }
        }
    }
    Some(sign)
}

/// Solves A x = b in place with the factors of [`lu_in_place`].
pub(crate) fn lu_solve(lu: &DMatrix<f64>, pivots: &[usize], b: &mut DVector<f64>) {
    for (k, &piv) in pivots.iter().enumerate() {
        b.swap_rows(k, piv);
    }
    lu.solve_lower_triangular_with_diag_mut(b, 1.0);
    lu.solve_upper_triangular_mut(b);
}
