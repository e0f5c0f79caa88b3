//! Colour encodings shared by everything that shows pixels (image files, terminal swatches,
//! the debugger, the stats image): the sRGB transfer function (to 8 bits by a table) and
//! the heat-map ramp.

use std::sync::OnceLock;

/// A linear value as a display can show it: clamped to [0, 1] (no more than white), NaN as
/// black rather than poisoning anything. The formula and its table both start here.
fn displayable(linear: f32) -> f32 {
    if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1] (see
/// [`displayable`]).
pub fn linear_to_srgb(linear: f32) -> f32 {
    let v = displayable(linear);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear channel as an 8-bit sRGB value, rounded to nearest: exactly
/// [`linear_to_srgb`] times 255, plus a half, truncated, but looked up (see [`Srgb8Table`]).
pub fn linear_to_srgb8(linear: f32) -> u8 {
    static TABLE: OnceLock<Srgb8Table> = OnceLock::new();
    TABLE.get_or_init(Srgb8Table::new).encode(linear)
}

/// What [`linear_to_srgb8`] gives, computed: the table is made from it and tested against it.
fn linear_to_srgb8_computed(linear: f32) -> u8 {
    (linear_to_srgb(linear) * 255.0 + 0.5) as u8
}

/// Values in [0, 1] whose bits agree above this one share a bucket of the table: 16,257
/// buckets, each narrower than the gap between two codes' thresholds, so a lookup is one
/// bucket and at most one comparison.
const BUCKET_SHIFT: u32 = 16;

/// [`linear_to_srgb8_computed`] as a table. Writing an image took a `powf` for each channel
/// (3.7 million for 1280x960, about as long as the file's compression); the code rises with
/// the value, so it is the number of codes whose least value is at most the value, found
/// from a bucket of values and the thresholds beside it. Built once, from the function
/// itself, in well under a millisecond.
struct Srgb8Table {
    /// `thresholds[k]`: the least value in [0, 1] whose code is `k` or more (0 for `k = 0`).
    thresholds: [f32; 256],
    /// The code of each bucket's least value.
    first_codes: Vec<u8>,
}

impl Srgb8Table {
    fn new() -> Srgb8Table {
        let one = 1.0f32.to_bits();
        let code_of_bits = |bits: u32| linear_to_srgb8_computed(f32::from_bits(bits));
        let mut thresholds = [0.0f32; 256];
        for (k, threshold) in (0u8..=255).zip(thresholds.iter_mut()).skip(1) {
            // The code of 0 is 0 and that of 1 is 255: bisect between them, over the bit
            // patterns, which order non-negative floats as their values.
            let (mut below, mut at_least) = (0u32, one);
            while at_least - below > 1 {
                let middle = below + (at_least - below) / 2;
                if code_of_bits(middle) >= k {
                    at_least = middle;
                } else {
                    below = middle;
                }
            }
            *threshold = f32::from_bits(at_least);
        }
        let first_codes = (0..=one >> BUCKET_SHIFT)
            .map(|bucket| {
                let least = f32::from_bits(bucket << BUCKET_SHIFT);
                let codes_reached = thresholds.partition_point(|&t| t <= least);
                u8::try_from(codes_reached.saturating_sub(1)).unwrap_or(u8::MAX)
            })
            .collect();
        Srgb8Table {
            thresholds,
            first_codes,
        }
    }

    fn encode(&self, linear: f32) -> u8 {
        let v = displayable(linear);
        // -0.0 (which the clamp keeps) goes to the bucket of +0.0.
        let bucket = (v.to_bits() & 0x7fff_ffff) >> BUCKET_SHIFT;
        let mut code = self.first_codes.get(bucket as usize).copied().unwrap_or(0);
        while code < u8::MAX && v >= self.thresholds[usize::from(code) + 1] {
            code += 1;
        }
        code
    }
}

/// A linear RGB colour as 8-bit sRGB.
pub fn linear_to_srgb8_rgb(color: [f32; 3]) -> [u8; 3] {
    color.map(linear_to_srgb8)
}

/// The inverse of the sRGB transfer function, for an encoded value in [0, 1].
pub fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// The heat-map ramp's stops as 8-bit sRGB, darkest first, at equal steps: black, purple, red,
/// orange, pale yellow. Dark-to-light, so it still reads in 256 colours and in greyscale.
const HEAT_STOPS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [90.0, 20.0, 140.0],
    [200.0, 40.0, 60.0],
    [250.0, 150.0, 20.0],
    [255.0, 250.0, 180.0],
];

/// The heat-map colour (8-bit sRGB) of `fraction` from 0 (black) to 1 (pale yellow),
/// interpolated between the stops in sRGB.
pub fn heat_color(fraction: f32) -> [u8; 3] {
    let f = displayable(fraction);
    let position = f * (HEAT_STOPS.len() - 1) as f32;
    let index = (position.floor() as usize).min(HEAT_STOPS.len() - 2);
    let local = position - index as f32;
    let (a, b) = (HEAT_STOPS[index], HEAT_STOPS[index + 1]);
    [0, 1, 2].map(|c| (a[c] + (b[c] - a[c]) * local).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_matches_the_standard_at_known_points() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        // Mid grey: linear 0.2140 is sRGB 0.5 (127.5 / 255).
        assert!((linear_to_srgb(0.214_041) - 0.5).abs() < 1e-4);
        assert_eq!(linear_to_srgb(-3.0), 0.0);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
        assert_eq!(linear_to_srgb8_rgb([0.0, 1.0, 7.0]), [0, 255, 255]);
    }

    /// The table against the formula it stands in for, on every float in [0, 1] (about a
    /// billion: a few seconds), on a float in every thousand or so beyond, and on the
    /// special values.
    #[test]
    fn the_table_encodes_every_value_exactly_as_the_formula() {
        let table = Srgb8Table::new();
        let differs = |v: f32| table.encode(v) != linear_to_srgb8_computed(v);
        let one = 1.0f32.to_bits();
        let within = (0..=one).filter(|&bits| differs(f32::from_bits(bits)));
        let beyond = (one..0x7f80_0000)
            .step_by(991)
            .chain((0x8000_0000..=u32::MAX).step_by(997))
            .filter(|&bits| differs(f32::from_bits(bits)));
        let special = [
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            1.000_000_1,
            -f32::MIN_POSITIVE,
        ]
        .into_iter()
        .map(f32::to_bits)
        .filter(|&bits| differs(f32::from_bits(bits)));
        let wrong: Vec<u32> = within.chain(beyond).chain(special).take(5).collect();
        assert!(
            wrong.is_empty(),
            "the table differs at the floats of bits {wrong:#x?}"
        );
    }

    #[test]
    fn every_byte_survives_the_round_trip() {
        for byte in 0..=255u8 {
            let linear = srgb_to_linear(f32::from(byte) / 255.0);
            assert_eq!(linear_to_srgb8(linear), byte, "byte {byte}");
        }
    }

    #[test]
    fn the_heat_ramp_runs_from_black_to_pale_yellow_through_its_stops() {
        assert_eq!(heat_color(0.0), [0, 0, 0]);
        assert_eq!(heat_color(0.5), [200, 40, 60]);
        assert_eq!(heat_color(1.0), [255, 250, 180]);
        assert_eq!(heat_color(7.0), heat_color(1.0));
        assert_eq!(heat_color(f32::NAN), [0, 0, 0]);
    }
}
