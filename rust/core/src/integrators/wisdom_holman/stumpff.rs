//! Stumpff's functions c₀…c₃ and the universal functions G₀…G₃ of the Kepler flow.

/// 1/k! for k = 0…13, the Taylor coefficients of the series below.
const INV_FACTORIAL: [f64; 14] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362880.0,
    1.0 / 3628800.0,
    1.0 / 39916800.0,
    1.0 / 479001600.0,
    1.0 / 6227020800.0,
];

/// Stumpff's functions cₖ(z) = Σⱼ (−z)ʲ/(k + 2j)! for k = 0…3 (c₀ = cos√z, c₁ = sin√z/√z for
/// z > 0, cosh and sinh for z < 0).
///
/// z is quartered n times until |z| ≤ 0.1, where the series to 1/13! is exact to round-off (the
/// first term left out is below 5e-18 relatively); the quadruplication formulas
/// c₀(4z) = 2c₀² − 1, c₁(4z) = c₀c₁, c₂(4z) = c₁²/2, c₃(4z) = (c₂ + c₀c₃)/4 then climb back, as
/// in Stumpff (1959) and REBOUND's WHFast (Rein & Tamayo 2015). A z that is not finite gives NaN.
#[inline]
pub fn stumpff(z: f64) -> [f64; 4] {
    if !z.is_finite() {
        return [f64::NAN; 4];
    }
    let (mut z, mut n) = (z, 0);
    while z.abs() > 0.1 {
        z *= 0.25;
        n += 1;
    }
    let (mut c3, mut c2) = (INV_FACTORIAL[13], INV_FACTORIAL[12]);
    for k in [11, 9, 7, 5, 3] {
        c3 = INV_FACTORIAL[k] - z * c3;
        c2 = INV_FACTORIAL[k - 1] - z * c2;
    }
    let (mut c0, mut c1) = (1.0 - z * c2, 1.0 - z * c3);
    for _ in 0..n {
        c3 = 0.25 * (c2 + c0 * c3);
        c2 = 0.5 * c1 * c1;
        c1 *= c0;
        c0 = 2.0 * c0 * c0 - 1.0;
    }
    [c0, c1, c2, c3]
}

/// The universal functions Gₖ(β, X) = Xᵏ cₖ(βX²), k = 0…3, of the universal anomaly X (Stiefel &
/// Scheifele 1971): r dX/dt = 1 along a Kepler orbit of energy −β/2 per unit reduced mass.
#[inline]
pub fn universal_functions(beta: f64, x: f64) -> [f64; 4] {
    let x2 = x * x;
    let [c0, c1, c2, c3] = stumpff(beta * x2);
    [c0, c1 * x, c2 * x2, c3 * x2 * x]
}
