//! A fixed stream of uniform numbers, for start vectors that no model's structure shares and
//! that are the same on every run and machine.

/// `count` numbers uniform in [0, 1) from SplitMix64 (Steele, Lea & Flood 2014) with a fixed
/// seed: 53-bit multiples of 2⁻⁵³.
pub(crate) fn uniform(count: usize) -> impl Iterator<Item = f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..count).map(move |_| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    })
}
