//! Colour encodings shared by everything that shows pixels (image files, terminal swatches,
//! the debugger, the stats image): the sRGB transfer function and the heat-map ramp.

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1]: a display
/// cannot show more than white. NaN shows as black rather than poisoning anything.
pub fn linear_to_srgb(linear: f32) -> f32 {
    let v = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear channel as an 8-bit sRGB value, rounded to nearest.
pub fn linear_to_srgb8(linear: f32) -> u8 {
    (linear_to_srgb(linear) * 255.0 + 0.5) as u8
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
    let f = if fraction.is_nan() {
        0.0
    } else {
        fraction.clamp(0.0, 1.0)
    };
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
