//! Cholesky factorisation of a small symmetric positive-definite matrix, in place, and its
//! triangular solves: allocation-free, on a caller's row-major n × n slice.

/// A = LLᵀ in place (Cholesky–Crout, row by row): reads A's lower triangle, row-major n × n,
/// and leaves L there, the upper triangle untouched. Whether A is positive definite: false at
/// the first pivot that is not positive (or NaN), L then only partly written.
pub(crate) fn factorise(a: &mut [f64], n: usize) -> bool {
    for i in 0..n {
        for j in 0..=i {
            let mut sum = a[i * n + j];
            for l in 0..j {
                sum -= a[i * n + l] * a[j * n + l];
            }
            if i == j {
                // Not positive, or NaN: not positive definite.
                if sum.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    return false;
                }
                a[i * n + i] = sum.sqrt();
            } else {
                a[i * n + j] = sum / a[j * n + j];
            }
        }
    }
    true
}

/// y = L⁻¹b, forward substitution on the lower triangle L of `factor` (n × n).
pub(crate) fn forward(factor: &[f64], b: &[f64], y: &mut [f64], n: usize) {
    for i in 0..n {
        let sum: f64 = (0..i).map(|l| factor[i * n + l] * y[l]).sum();
        y[i] = (b[i] - sum) / factor[i * n + i];
    }
}

/// x = L⁻ᵀy, back substitution on the transpose of the lower triangle L of `factor` (n × n).
pub(crate) fn backward(factor: &[f64], y: &[f64], x: &mut [f64], n: usize) {
    for i in (0..n).rev() {
        let sum: f64 = (i + 1..n).map(|l| factor[l * n + i] * x[l]).sum();
        x[i] = (y[i] - sum) / factor[i * n + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_positive_definite_system_and_refuses_an_indefinite_one() {
        // A = [[4, 2], [2, 3]], b = A·(1, −1) = (2, −1).
        let mut a = [4.0, f64::NAN, 2.0, 3.0];
        assert!(factorise(&mut a, 2));
        let (mut y, mut x) = ([0.0; 2], [0.0; 2]);
        forward(&a, &[2.0, -1.0], &mut y, 2);
        backward(&a, &y, &mut x, 2);
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] + 1.0).abs() < 1e-15, "{x:?}");
        assert!(!factorise(&mut [1.0, 0.0, 2.0, 1.0], 2));
    }
}
