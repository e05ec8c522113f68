//! Wisdom, Holman & Touma's symplectic correctors.

/// The symplectic corrector of order `order` (3, 5, 7, 11 or 17; 0 for none) as pairs (aₖ, bₖ)
/// of Wisdom, Holman & Touma (1996), with the values of WHFast (Rein & Tamayo 2015, Table 1;
/// REBOUND's `integrator_whfast.c`; copied with their source into
/// `reference/wisdom_holman.json`): the corrector is
///
///   C = Π_k Z(aₖh, bₖh),  Z(a, b) = K(a) I(−b) K(−2a) I(b) K(a),
///
/// K(t) the Kepler drift and I(t) the interaction kick over time t, taken in the order listed,
/// and C⁻¹ the same product with every bₖ negated (to the corrector's order). The kernel
/// K(h/2) I(h) K(h/2) conjugated by C, C⁻¹ ∘ kernelⁿ ∘ C, has the energy and state errors of
/// order ε hᵏ, k ≤ `order`, removed: what is left is O(εh^{order+1} + ε²h²), ε the ratio of the
/// interaction to the Kepler terms. None for an order without coefficients.
pub fn corrector(order: u32) -> Option<&'static [(f64, f64)]> {
    Some(match order {
        0 => &[],
        3 => &CORRECTOR_3,
        5 => &CORRECTOR_5,
        7 => &CORRECTOR_7,
        11 => &CORRECTOR_11,
        17 => &CORRECTOR_17,
        _ => return None,
    })
}

/// The orders with coefficients.
const ORDERS: [u32; 6] = [0, 3, 5, 7, 11, 17];

/// A corrector serialised by its order (serde's `with`): the coefficients are the library's.
pub(super) mod by_order {
    use serde::{de, ser, Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(pairs: &&'static [(f64, f64)], s: S) -> Result<S::Ok, S::Error> {
        let order = super::ORDERS.iter().find(|&&o| super::corrector(o) == Some(*pairs));
        s.serialize_u32(*order.ok_or_else(|| ser::Error::custom("a corrector not in the table"))?)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<&'static [(f64, f64)], D::Error> {
        let order = u32::deserialize(d)?;
        super::corrector(order).ok_or_else(|| de::Error::custom(format!("no corrector of order {order}")))
    }
}

/// aₖ = k·√(7/40).
const A: [f64; 9] = [
    0.0,
    0.4183300132670378,
    0.8366600265340756,
    1.2549900398011133,
    1.6733200530681511,
    2.091650066335189,
    2.5099800796022267,
    2.9283100928692645,
    3.3466401061363023,
];

const B31: f64 = -0.024900596027799867;
const B51: f64 = -0.008300198675933288;
const B52: f64 = 0.041500993379666444;
const B71: f64 = 0.0024926811426922105;
const B72: f64 = -0.018270923246702132;
const B73: f64 = 0.0539643990931275;
const B111: f64 = 0.0002036157964785465;
const B112: f64 = -0.0023487215292295354;
const B113: f64 = 0.012309078592019946;
const B114: f64 = -0.03812161368128865;
const B115: f64 = 0.07259339474884274;
const B171: f64 = -4.334741547337358e-06;
const B172: f64 = 7.643635522793574e-05;
const B173: f64 = -0.0006359998307581766;
const B174: f64 = 0.0033132577069380654;
const B175: f64 = -0.01207176082234229;
const B176: f64 = 0.03242219886471358;
const B177: f64 = -0.0651928635763779;
const B178: f64 = 0.09305610377142595;

const CORRECTOR_3: [(f64, f64); 2] = [(A[1], -B31), (-A[1], B31)];
const CORRECTOR_5: [(f64, f64); 4] = [(-A[2], -B51), (-A[1], -B52), (A[1], B52), (A[2], B51)];
const CORRECTOR_7: [(f64, f64); 6] = [
    (-A[3], -B71),
    (-A[2], -B72),
    (-A[1], -B73),
    (A[1], B73),
    (A[2], B72),
    (A[3], B71),
];
const CORRECTOR_11: [(f64, f64); 10] = [
    (-A[5], -B111),
    (-A[4], -B112),
    (-A[3], -B113),
    (-A[2], -B114),
    (-A[1], -B115),
    (A[1], B115),
    (A[2], B114),
    (A[3], B113),
    (A[4], B112),
    (A[5], B111),
];
const CORRECTOR_17: [(f64, f64); 16] = [
    (-A[8], -B171),
    (-A[7], -B172),
    (-A[6], -B173),
    (-A[5], -B174),
    (-A[4], -B175),
    (-A[3], -B176),
    (-A[2], -B177),
    (-A[1], -B178),
    (A[1], B178),
    (A[2], B177),
    (A[3], B176),
    (A[4], B175),
    (A[5], B174),
    (A[6], B173),
    (A[7], B172),
    (A[8], B171),
];
