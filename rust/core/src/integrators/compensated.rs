//! Compensated (Kahan) summation of the step increments (Hairer, Lubich & Wanner, GNI VIII.5,
//! Algorithm 5.1): the round-off lost in xₙ₊₁ = xₙ + δx is carried in `err` and added back at
//! the next step, so that round-off grows like √N rather than N over N steps.

/// x_next = x + δx with the lost low-order bits carried from `err` into `err_next`. Returns
/// whether every entry of x_next is finite.
#[inline]
pub fn add(x: &[f64], err: &[f64], dx: &[f64], x_next: &mut [f64], err_next: &mut [f64]) -> bool {
    // Indexed over slices cut to one length, so that the bounds checks fold away: a five-way
    // zip costs a Verlet step of Kepler a fifth of its instructions (callgrind).
    let n = x.len();
    let (err, dx, x_next, err_next) = (&err[..n], &dx[..n], &mut x_next[..n], &mut err_next[..n]);
    let mut finite = true;
    for i in 0..n {
        let e = err[i] + dx[i];
        x_next[i] = x[i] + e;
        err_next[i] = e + (x[i] - x_next[i]);
        finite &= x_next[i].is_finite();
    }
    finite
}

/// x_next = x + δx, plainly. Returns whether every entry of x_next is finite.
#[inline]
pub fn add_plain(x: &[f64], dx: &[f64], x_next: &mut [f64]) -> bool {
    let n = x.len();
    let (dx, x_next) = (&dx[..n], &mut x_next[..n]);
    let mut finite = true;
    for i in 0..n {
        x_next[i] = x[i] + dx[i];
        finite &= x_next[i].is_finite();
    }
    finite
}
