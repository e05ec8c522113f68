use super::Method;

/// A symmetric composition Ψ_h = Φ_{γₛh} ∘ … ∘ Φ_{γ₁h} of Störmer–Verlet Φ, with γᵢ = γₛ₊₁₋ᵢ
/// and Σγᵢ = 1 (HLW V.3).
///
/// Coefficients as in Hairer's `gni_comp.f` and the cited papers; each is given by its first
/// half and its middle value.
#[derive(Clone, Debug, PartialEq)]
pub struct Composition {
    gamma: Vec<f64>,
}

impl Composition {
    /// The composition behind `method`, or `None` for methods that are not Verlet compositions.
    pub fn of(method: Method) -> Option<Composition> {
        let (half, middle): (&[f64], Option<f64>) = match method {
            Method::Verlet => (&[], Some(1.0)),
            Method::Yoshida4 => (&[1.3512071919596578], Some(-1.7024143839193153)),
            Method::Suzuki4 => (&[0.4144907717943757, 0.4144907717943757], Some(-0.6579630871775028)),
            // McLachlan (1995), SS5: the free parameter of the one-parameter family, γ₁ = 0.28,
            // is McLachlan's short value near the least error norm.
            Method::McLachlan4 => (&[0.28, 0.6254664284676701], None),
            // McLachlan (1995), SS9, order 6 (γ₁ = 0.1867 chosen likewise); Blanes & Casas (2016), p. 89.
            Method::McLachlan6 => (
                &[0.1867, 0.5554970237124784, 0.12946694891347535, -0.8432656233877346],
                None,
            ),
            Method::Yoshida6 => (
                &[0.7845136104775573, 0.23557321335935813, -1.177679984178871],
                Some(1.3151863206839112),
            ),
            Method::KahanLi6 => (
                &[
                    0.3921614440073141,
                    0.33259913678935943,
                    -0.7062461725576393,
                    0.0822135962935508,
                ],
                Some(0.79854399093483),
            ),
            Method::SuzukiUmeno8 => (
                &[
                    0.741670364350613,
                    -0.4091008258000316,
                    0.1907547102962384,
                    -0.5738624711160822,
                    0.2990641813036559,
                    0.33462491824529816,
                    0.3152930923967666,
                ],
                Some(-0.7968879393529164),
            ),
            Method::KahanLi8 => (
                &[
                    0.13020248308889007,
                    0.5611629817751084,
                    -0.38947496264484727,
                    0.1588419065551556,
                    -0.39590389413323757,
                    0.1845396409783157,
                    0.25837438768632204,
                    0.2950117236093103,
                ],
                Some(-0.6055085338300346),
            ),
            // McLachlan (1995), SS17, order 8, as tabulated by Blanes & Casas (2016), p. 91 (the
            // composition of REBOUND's leapfrog with order = 8, whose 15-digit γ agree).
            Method::McLachlan8 => (
                &[
                    0.12886597938144329,
                    0.581514087105251,
                    -0.4101753714698501,
                    0.18514693571658775,
                    -0.4095523434208514,
                    0.14440594108001203,
                    0.27833550039367966,
                    0.31495668391629483,
                ],
                None,
            ),
            _ => return None,
        };
        // McLachlan's middle coefficients are defined by consistency, Σγᵢ = 1.
        let middle = middle.unwrap_or_else(|| 1.0 - 2.0 * half.iter().sum::<f64>());
        let gamma = half
            .iter()
            .copied()
            .chain([middle])
            .chain(half.iter().rev().copied())
            .collect();
        Some(Composition { gamma })
    }

    /// The step fractions γ₁, …, γₛ.
    pub fn gamma(&self) -> &[f64] {
        &self.gamma
    }
}
