//! Compensated (Kahan) summation of the step increments (Hairer, Lubich & Wanner, GNI VIII.5,
//! Algorithm 5.1): the round-off lost in xₙ₊₁ = xₙ + δx is carried in `err` and added back at
//! the next step, so that round-off grows like √N rather than N over N steps.

/// x ← x + δx, carrying the lost low-order bits in `err`.
#[inline]
pub fn add(x: &mut [f64], err: &mut [f64], dx: &[f64]) {
    for ((xi, ei), di) in x.iter_mut().zip(err.iter_mut()).zip(dx) {
        let a = *xi;
        let e = *ei + di;
        *xi = a + e;
        *ei = e + (a - *xi);
    }
}
