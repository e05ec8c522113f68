//! Hand-written reference loops: the arithmetic of varmech's step loops with nothing around it
//! (fixed sizes, no dispatch, no checks), to measure the driver's overhead against. The tests
//! include this file and hold its results bit-identical to varmech's.

#![allow(dead_code)]

/// Störmer–Verlet on Kepler, H = |p|²/2 − 1/|q|, as varmech's kick–drift loop computes it: the
/// force of the step's end kept for the next step's first kick, the increments (δq, δp) added
/// to (q, p) with compensated summation.
pub fn kepler_verlet(q0: [f64; 2], p0: [f64; 2], h: f64, steps: usize) -> ([f64; 2], [f64; 2]) {
    let gradient = |q: [f64; 2]| {
        let r2 = q[0] * q[0] + q[1] * q[1];
        let k = 1.0 / (r2 * r2.sqrt());
        [k * q[0], k * q[1]]
    };
    let (mut q, mut p) = (q0, p0);
    let (mut eq, mut ep) = ([0.0; 2], [0.0; 2]);
    let mut force = gradient(q);
    let a = 0.5 * h;
    for _ in 0..steps {
        let mut dp = [-a * force[0], -a * force[1]];
        let (mut dq, mut stage) = ([0.0; 2], [0.0; 2]);
        for i in 0..2 {
            dq[i] = 0.0 + h * (p[i] + dp[i]);
            stage[i] = q[i] + dq[i];
        }
        force = gradient(stage);
        for i in 0..2 {
            dp[i] -= a * force[i];
        }
        compensated(&mut q, &mut eq, dq);
        compensated(&mut p, &mut ep, dp);
    }
    (q, p)
}

/// x ← x + δx, the lost low-order bits carried in e (Kahan).
#[inline(always)]
fn compensated<const N: usize>(x: &mut [f64; N], e: &mut [f64; N], dx: [f64; N]) {
    for i in 0..N {
        let s = e[i] + dx[i];
        let next = x[i] + s;
        e[i] = s + (x[i] - next);
        x[i] = next;
    }
}
