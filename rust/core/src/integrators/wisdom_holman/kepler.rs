//! The Kepler drift: the exact flow of a two-body problem, by a universal-variable solver.

use super::stumpff::universal_functions;
use crate::solve::bracket::bisection;
use crate::solve::laguerre::laguerre;
use crate::solve::newton::plain;

/// Newton iterations before the bracketed fallback; from the second-order guess Newton converges
/// in 2–4 iterations for a step below a tenth of the period.
const NEWTON_ITERATIONS: usize = 32;
/// Laguerre–Conway iterations for a poor guess, to a relative correction of 1e-8.
const LAGUERRE_ITERATIONS: usize = 64;
/// Bound on the fallback's doublings and bisections: 2·1100 halvings span the doubles.
const FALLBACK_ITERATIONS: usize = 2200;

/// The increments (δx, δv) of the Kepler flow ẍ = −μx/|x|³ over time `dt` from (x, v): the exact
/// two-body motion of a Jacobi coordinate, elliptic, parabolic or hyperbolic, forwards or
/// backwards.
///
/// In Stiefel's universal variable X (r dX/dt = 1), with r₀ = |x|, η₀ = x·v, β = 2μ/r₀ − |v|²
/// and ζ₀ = μ − βr₀, the time of flight is Kepler's equation
///
///   t(X) = r₀X + η₀G₂(β, X) + ζ₀G₃(β, X) = dt,   t′(X) = r = r₀ + η₀G₁ + ζ₀G₂ > 0,
///
/// and the flow is linear in (x, v) through Gauss's f and g functions:
///
///   δx = (f − 1)x + g v,  δv = ḟx + (ġ − 1)v,
///   f − 1 = −μG₂/r₀,  g = dt − μG₃,  ḟ = −μG₁/(r₀r),  ġ − 1 = −μG₂/r
///
/// (Danby 1988, ch. 6.9; Wisdom & Hernandez 2015; Rein & Tamayo 2015, whose WHFast uses the
/// same forms, written as increments so that the caller may add them with compensated
/// summation). Bound orbits first drop whole periods P = 2πμ/β^{3/2} from dt (the flow is
/// P-periodic), so that a drift over many periods costs as much as one. Newton's iteration from
/// the second-order guess X ≈ (dt/r₀)(1 − η₀dt/2r₀²) (or, when its first correction exceeds a
/// hundredth of a period, from Laguerre–Conway's iteration, as WHFast) runs to round-off;
/// should it not settle within 32 iterations, t(X) = dt is bracketed by doubling and solved by
/// bisection (t is increasing), within a bounded number of evaluations. Allocates nothing; a
/// degenerate orbit (x = 0) or non-finite data give non-finite increments.
#[inline]
pub fn kepler_drift(x: [f64; 3], v: [f64; 3], mu: f64, dt: f64) -> ([f64; 3], [f64; 3]) {
    let r0 = dot(x, x).sqrt();
    let r0i = 1.0 / r0;
    let v2 = dot(v, v);
    let beta = 2.0 * mu * r0i - v2;
    let eta0 = dot(x, v);
    let zeta0 = mu - beta * r0;
    let dt = if beta > 0.0 {
        let period = 2.0 * std::f64::consts::PI * mu / (beta * beta.sqrt());
        dt - (dt / period).round() * period
    } else {
        dt
    };

    let dtr0i = dt * r0i;
    let mut xu = dtr0i * (1.0 - 0.5 * dtr0i * eta0 * r0i);
    let newton = |xu: f64| {
        let g = universal_functions(beta, xu);
        let s = eta0 * g[1] + zeta0 * g[2];
        // X − (t(X) − dt)/r, arranged so that r₀X and dt do not cancel.
        ((xu * s - eta0 * g[2] - zeta0 * g[3] + dt) / (r0 + s), g, r0 + s)
    };
    // A first Newton step beyond a hundredth of a period means the guess is poor (a step
    // across a close pericentre): Laguerre–Conway's iteration, which converges from anywhere on
    // Kepler's equation (Conway 1986), from the mean-motion guess X = βdt/μ brings X close.
    let (first, mut g, mut r) = newton(xu);
    let x_period = if beta > 0.0 {
        2.0 * std::f64::consts::PI / beta.sqrt()
    } else {
        f64::INFINITY
    };
    let mut polishing = false;
    if (first - xu).abs() <= 0.01 * x_period {
        polishing = (first - xu).abs() <= 1e-9 * first.abs();
        xu = first;
    } else {
        xu = if beta > 0.0 { beta * dt / mu } else { dtr0i };
        // A NaN step stops too: Newton and the fallback take over.
        let derivatives = |xu: f64| {
            let g = universal_functions(beta, xu);
            let t = r0 * xu + eta0 * g[2] + zeta0 * g[3] - dt;
            (t, r0 + eta0 * g[1] + zeta0 * g[2], eta0 * g[0] + zeta0 * g[1])
        };
        xu = laguerre(derivatives, xu, LAGUERRE_ITERATIONS, 1e-8);
    }
    // Newton's iteration, quadratic: once a correction is below 1e-9 of X one more step reaches
    // round-off, where a close pericentre leaves X wandering by a few ulps.
    let map = |xu: f64| {
        let next;
        (next, g, r) = newton(xu);
        next
    };
    let (_, converged) = plain::scalar(map, xu, polishing, (NEWTON_ITERATIONS, 1e-9));
    // On convergence g and r are those of the X before the last correction, a round-off away.
    if !converged {
        let root = bisection(
            |xu| {
                let g = universal_functions(beta, xu);
                r0 * xu + eta0 * g[2] + zeta0 * g[3] - dt
            },
            dt * r0i,
            FALLBACK_ITERATIONS,
        );
        g = universal_functions(beta, root);
        r = r0 + eta0 * g[1] + zeta0 * g[2];
    }

    let f = -mu * g[2] * r0i;
    let gg = dt - mu * g[3];
    let fd = -mu * g[1] * r0i / r;
    let gd = -mu * g[2] / r;
    let mut dx = [0.0; 3];
    let mut dv = [0.0; 3];
    for k in 0..3 {
        dx[k] = f * x[k] + gg * v[k];
        dv[k] = fd * x[k] + gd * v[k];
    }
    (dx, dv)
}

#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
