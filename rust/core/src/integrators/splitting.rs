use super::{Composition, Method};

/// Which flow a splitting method opens its step with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Leading {
    /// BAB: a kick p ← p − a₀h∇V(q) first (and last).
    Kick,
    /// ABA: a drift q ← q + b₁hM⁻¹p first (and last); no force is evaluated before it.
    Drift,
}

/// A splitting method for H = T(p) + V(q), T = ½pᵀM⁻¹p with constant M: the kick fractions
/// a₀, …, aₛ and drift fractions b₁, …, bₛ of the step
///
/// Ψ_h = φ^V_{aₛh} ∘ φ^T_{bₛh} ∘ … ∘ φ^V_{a₁h} ∘ φ^T_{b₁h} ∘ φ^V_{a₀h},
///
/// with φ^V_τ the kick p ← p − τ∇V(q) and φ^T_τ the drift q ← q + τM⁻¹p, Σaᵢ = Σbᵢ = 1.
/// A BAB method has a₀ ≠ 0 (and, symmetric, aₛ = a₀); an ABA method has a₀ = aₛ = 0.
///
/// The coefficients alone, independent of what the flows are: the kick–drift integrator
/// ([`super::KickDrift`]) applies them to the free drift, and a Wisdom–Holman method may apply
/// them to a Kepler drift and interaction kicks (the near-integrable families below were built
/// for that).
///
/// The Runge–Kutta–Nyström methods (Blanes & Moan's, McLachlan's) satisfy their order
/// conditions only where [V, [V, [V, T]]] = 0, true for T quadratic in p with constant M: the
/// kick–drift methods integrate exactly those systems (see [`super::ModelKind`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Splitting {
    method: Method,
    kicks: Vec<f64>,
    drifts: Vec<f64>,
}

impl Splitting {
    /// The splitting behind `method`, or `None` for methods that are not kick–drift methods.
    ///
    /// Symmetric methods are given by the independent coefficients of the first half of each
    /// flow, as the papers tabulate them; the central one of each flow follows from
    /// consistency, Σaᵢ = Σbᵢ = 1 (see `reference/splittings.json`).
    pub fn of(method: Method) -> Option<Splitting> {
        if let Some(c) = Composition::of(method) {
            return Some(Self::composition(method, &c));
        }
        if method == Method::McLachlan8Dkd {
            let c = Composition::of(Method::McLachlan8)?;
            return Some(Self::position_composition(method, &c));
        }
        let (kicks, drifts) = match method {
            // p₁ = p₀ − h∇V(q₀), q₁ = q₀ + hM⁻¹p₁.
            Method::SymplecticEuler => (vec![1.0, 0.0], vec![1.0]),
            // Blanes & Moan (2002), Table 3, SRKN₆ᵇ: b₁, b₂, b₃ kicks, a₁, a₂ drifts.
            Method::BlanesMoan4 => symmetric(
                Leading::Kick,
                6,
                &[0.0829844064174052, 0.396309801498368, -0.0390563049223486],
                &[0.245298957184271, 0.604872665711080],
            ),
            // Blanes & Moan (2002), Table 3, SRKN₁₁ᵇ.
            Method::BlanesMoan6 => symmetric(
                Leading::Kick,
                11,
                &[
                    0.0414649985182624,
                    0.198128671918067,
                    -0.0400061921041533,
                    0.0752539843015807,
                    -0.0115113874206879,
                ],
                &[
                    0.123229775946271,
                    0.290553797799558,
                    -0.127049212625417,
                    -0.246331761062075,
                    0.357208872795928,
                ],
            ),
            // Blanes, Casas, Farrés, Laskar, Makazaga & Murua (2013), ABA(8,6,4): drifts
            // a₁..a₃, kicks b₁..b₃.
            Method::Aba864 => symmetric(
                Leading::Drift,
                7,
                &[0.07113342649822312, 0.2411534279566401, 0.5214117617728148],
                &[0.18308368747219722, 0.31078285989857485, -0.0265646185119588],
            ),
            // The same paper, ABA(10,6,4): drifts a₁..a₄, kicks b₁..b₃.
            Method::Aba1064 => symmetric(
                Leading::Drift,
                8,
                &[
                    0.038094497422412193,
                    0.14529871611691375,
                    0.20762769572554124,
                    0.43590970365152615,
                ],
                &[0.09585888083707521, 0.20444615314299877, 0.2170703479789911],
            ),
            _ => return None,
        };
        Some(Splitting { method, kicks, drifts })
    }

    /// The composition of Störmer–Verlet in velocity form (kick–drift–kick) with the fractions γ
    /// of `c`: bᵢ = γᵢ, a₀ = γ₁/2, aᵢ = (γᵢ + γᵢ₊₁)/2 and aₛ = γₛ/2, adjacent half kicks merged.
    fn composition(method: Method, c: &Composition) -> Splitting {
        Splitting {
            method,
            kicks: merged_halves(c.gamma()),
            drifts: c.gamma().to_vec(),
        }
    }

    /// The composition of Störmer–Verlet in position form (drift–kick–drift), an ABA method:
    /// kicks γᵢ between the merged half drifts γ₁/2, (γᵢ + γᵢ₊₁)/2, γₛ/2.
    fn position_composition(method: Method, c: &Composition) -> Splitting {
        let g = c.gamma();
        Splitting {
            method,
            kicks: [0.0].into_iter().chain(g.iter().copied()).chain([0.0]).collect(),
            drifts: merged_halves(g),
        }
    }

    /// The method these are the coefficients of.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The method's order (for the near-integrable families, the order in h alone: ABA(8,6,4)
    /// has error O(εh⁸ + ε²h⁶ + ε³h⁴) on H = A + εB, order 4).
    pub fn order(&self) -> u32 {
        self.method.info().order
    }

    /// The kick fractions a₀, …, aₛ (a₀ = aₛ = 0 for an ABA method).
    pub fn kicks(&self) -> &[f64] {
        &self.kicks
    }

    /// The drift fractions b₁, …, bₛ.
    pub fn drifts(&self) -> &[f64] {
        &self.drifts
    }

    /// Whether the step opens with a kick (BAB) or a drift (ABA).
    pub fn leading(&self) -> Leading {
        if self.kicks[0] == 0.0 {
            Leading::Drift
        } else {
            Leading::Kick
        }
    }

    /// Whether the step ends with a kick at the point where the next one starts with a kick, so
    /// that one force evaluation serves both (first same as last).
    pub fn first_same_as_last(&self) -> bool {
        self.kicks[0] != 0.0 && self.kicks[self.kicks.len() - 1] != 0.0
    }

    /// Stages: the force evaluations ∇V of a step, first-same-as-last evaluations reused.
    pub fn stages(&self) -> usize {
        let kicks = self.kicks.iter().filter(|a| **a != 0.0).count();
        kicks - usize::from(self.first_same_as_last())
    }

    /// Whether the step is its own adjoint: both sequences are palindromes.
    pub fn symmetric(&self) -> bool {
        let palindrome = |x: &[f64]| x.iter().eq(x.iter().rev());
        palindrome(&self.kicks) && palindrome(&self.drifts)
    }
}

/// γ₁/2, (γ₁ + γ₂)/2, …, (γₛ₋₁ + γₛ)/2, γₛ/2: the half steps of adjacent Verlet steps merged.
fn merged_halves(g: &[f64]) -> Vec<f64> {
    let s = g.len();
    (0..=s)
        .map(|i| match i {
            0 => 0.5 * g[0],
            i if i == s => 0.5 * g[s - 1],
            i => 0.5 * (g[i - 1] + g[i]),
        })
        .collect()
}

/// The kicks and drifts of a symmetric method with `evaluations` force evaluations, from the
/// independent coefficients of the first half of the `leading` flow (`outer`) and of the other
/// one (`inner`): a BAB method has `evaluations` + 1 kicks and `evaluations` drifts, an ABA
/// method the reverse.
fn symmetric(leading: Leading, evaluations: usize, outer: &[f64], inner: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let outer = palindrome(outer, evaluations + 1);
    let inner = palindrome(inner, evaluations);
    match leading {
        Leading::Kick => (outer, inner),
        Leading::Drift => {
            let kicks = [0.0].into_iter().chain(inner).chain([0.0]).collect();
            (kicks, outer)
        }
    }
}

/// The palindrome c₁, …, c_len summing to 1 whose first ⌈len/2⌉ − 1 entries are `independent`:
/// the central entry is 1 − 2Σ (odd length) or the central pair ½ − Σ each (even length).
fn palindrome(independent: &[f64], len: usize) -> Vec<f64> {
    debug_assert_eq!(independent.len() + 1, len.div_ceil(2));
    let sum: f64 = independent.iter().sum();
    let centre = if len % 2 == 1 { 1.0 - 2.0 * sum } else { 0.5 - sum };
    let half = independent.iter().copied().chain([centre]);
    let mirrored = independent.iter().rev().copied();
    if len % 2 == 1 {
        half.chain(mirrored).collect()
    } else {
        half.chain([centre]).chain(mirrored).collect()
    }
}
