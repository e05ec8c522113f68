//! Compensated (Kahan) summation of the step increments (Hairer, Lubich & Wanner, GNI VIII.5,
//! Algorithm 5.1): the round-off lost in xₙ₊₁ = xₙ + δx is carried in `err` and added back at
//! the next step, so that round-off grows like √N rather than N over N steps.

/// x_next = x + δx with the lost low-order bits carried from `err` into `err_next`. Returns
/// whether every entry of x_next is finite.
#[inline]
pub fn add(x: &[f64], err: &[f64], dx: &[f64], x_next: &mut [f64], err_next: &mut [f64]) -> bool {
    let mut finite = true;
    for ((((a, e0), d), xn), en) in x
        .iter()
        .zip(err)
        .zip(dx)
        .zip(x_next.iter_mut())
        .zip(err_next.iter_mut())
    {
        let e = e0 + d;
        *xn = a + e;
        *en = e + (a - *xn);
        finite &= xn.is_finite();
    }
    finite
}

/// x_next = x + δx, plainly. Returns whether every entry of x_next is finite.
#[inline]
pub fn add_plain(x: &[f64], dx: &[f64], x_next: &mut [f64]) -> bool {
    let mut finite = true;
    for ((a, d), xn) in x.iter().zip(dx).zip(x_next.iter_mut()) {
        *xn = a + d;
        finite &= xn.is_finite();
    }
    finite
}
