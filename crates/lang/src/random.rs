//! `rand(seed, i)`: a deterministic hash of two numbers to [0, 1). The same arguments give
//! the same result on every platform and every run: only integer arithmetic on the numbers'
//! bit patterns, no state and no floating-point operation that could round differently.

/// SplitMix64's finaliser (Steele, Lea and Flood, 2014): every input bit affects every
/// output bit.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The bits a number is hashed by; `-0` and `0` are the same number, so they hash alike.
fn bits(x: f64) -> u64 {
    if x == 0.0 {
        0
    } else {
        x.to_bits()
    }
}

/// A number in [0, 1) that depends only on `seed` and `i`: the top 53 bits of the hash,
/// scaled by 2^-53, so every result is exact in f64 and 1 is never reached.
pub(crate) fn rand(seed: f64, i: f64) -> f64 {
    let h = mix(mix(bits(seed).wrapping_add(0x9e37_79b9_7f4a_7c15)) ^ bits(i));
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
