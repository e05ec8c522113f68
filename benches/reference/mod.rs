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

/// The implicit midpoint rule's variational integrator on a Lagrangian of 2 coordinates, as
/// varmech's DEL solver runs it: the unknown is δq = q₁ − q₀, predicted by extrapolating the
/// last two increments; F(δq) = p₀ + (h/2)∂L/∂q − ∂L/∂q̇ at (q₀ + δq/2, δq/h) is solved by
/// simplified Newton with the exact Jacobian (h/4)L_qq + (L_qq̇ − L_q̇q)/2 − L_q̇q̇/h, kept while
/// the corrections halve, stopping when ‖δ‖∞ ≤ tol·‖δq‖∞ or, where a correction with a fresh
/// Jacobian does not halve the smallest, at the noise floor: ‖F‖∞ within 4 × the rounding of
/// its terms, 4ε(‖J‖∞(‖δq‖∞ + ‖q₀‖∞) + ‖p₀‖∞) (the model's derivatives are exact); then
/// δp = h∂L/∂q − F, and compensated summation. Returns the final state and the Newton
/// iterations.
pub fn midpoint<L: varmech::model::Lagrangian>(
    sys: &L,
    q0: [f64; 2],
    p0: [f64; 2],
    h: f64,
    steps: usize,
) -> ([f64; 2], [f64; 2], u64) {
    const TOLERANCE: f64 = 1e-14;
    let norm = |x: [f64; 2]| x[0].abs().max(x[1].abs());
    let mut hessians = varmech::model::Hessians::zeros(2);
    let (mut q, mut p) = (q0, p0);
    let (mut eq, mut ep) = ([0.0; 2], [0.0; 2]);
    let (mut last, mut before_last, mut history) = ([0.0; 2], [0.0; 2], 0);
    let mut iterations = 0;
    // F(x) and, on request, h∂L/∂q, at the midpoint of the step with increment x.
    let equations = |q: &[f64; 2], p: &[f64; 2], x: &[f64; 2], lq: &mut [f64; 2]| {
        let mid = [q[0] + 0.5 * x[0], q[1] + 0.5 * x[1]];
        let v = [x[0] / h, x[1] / h];
        let mut lv = [0.0; 2];
        sys.gradients(&mid, &v, 0.0, lq, &mut lv).unwrap();
        [0.5 * h * lq[0] - lv[0] + p[0], 0.5 * h * lq[1] - lv[1] + p[1]]
    };
    for _ in 0..steps {
        let mut x = match history {
            0 => [0.0; 2],
            1 => last,
            _ => [2.0 * last[0] - before_last[0], 2.0 * last[1] - before_last[1]],
        };
        let mut lq = [0.0; 2];
        let mut r = equations(&q, &p, &x, &mut lq);
        let (mut lu, mut swap) = ([[0.0; 2]; 2], false);
        let (mut keep, mut previous, mut smallest) = (false, f64::INFINITY, f64::INFINITY);
        let mut jacobian_norm = 0.0_f64;
        loop {
            let fresh = !keep;
            if fresh {
                let mid = [q[0] + 0.5 * x[0], q[1] + 0.5 * x[1]];
                sys.hessians(&mid, &[x[0] / h, x[1] / h], 0.0, &mut hessians).unwrap();
                let j = |a: usize, e: usize| {
                    0.25 * h * hessians.qq[(a, e)] + 0.5 * hessians.qv[(a, e)]
                        - 0.5 * hessians.qv[(e, a)]
                        - hessians.vv[(a, e)] / h
                };
                // Partial pivoting of a 2×2 matrix.
                let mut m = [[j(0, 0), j(0, 1)], [j(1, 0), j(1, 1)]];
                jacobian_norm = (m[0][0].abs() + m[0][1].abs()).max(m[1][0].abs() + m[1][1].abs());
                swap = m[1][0].abs() > m[0][0].abs();
                if swap {
                    m.swap(0, 1);
                }
                let l = m[1][0] / m[0][0];
                lu = [[m[0][0], m[0][1]], [l, m[1][1] - l * m[0][1]]];
            }
            iterations += 1;
            let b = if swap { [r[1], r[0]] } else { r };
            let y1 = b[1] - lu[1][0] * b[0];
            let d1 = y1 / lu[1][1];
            let d0 = (b[0] - lu[0][1] * d1) / lu[0][0];
            x = [x[0] - d0, x[1] - d1];
            let size = d0.abs().max(d1.abs());
            let scale = x[0].abs().max(x[1].abs());
            r = equations(&q, &p, &x, &mut lq);
            let rounding = 4.0 * f64::EPSILON * (jacobian_norm * (scale + norm(q)) + norm(p));
            let at_floor = fresh && size > 0.5 * smallest && norm(r) <= 4.0 * rounding;
            smallest = smallest.min(size);
            if size <= TOLERANCE * scale || at_floor {
                break;
            }
            keep = size <= 0.5 * previous;
            previous = size;
        }
        let dp = [h * lq[0] - r[0], h * lq[1] - r[1]];
        (before_last, last) = (last, x);
        history = (history + 1).min(2);
        compensated(&mut q, &mut eq, x);
        compensated(&mut p, &mut ep, dp);
    }
    (q, p, iterations)
}
