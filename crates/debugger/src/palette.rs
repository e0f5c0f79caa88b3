//! The xterm 256-colour palette for terminals without 24-bit colour: the nearest palette
//! entry to an sRGB colour, judged in CIELAB so that hues survive (a cream wall stays cream,
//! not pink), over both the 6x6x6 cube and the 24-step grey ramp.

use std::sync::OnceLock;

/// The channel levels of the xterm 6x6x6 colour cube (indices 16 to 231).
const CUBE_LEVELS: [u8; 6] = [0, 95, 135, 175, 215, 255];

/// The sRGB colour of xterm palette entry `index` (16 to 255; the first 16 are the
/// terminal's own theme colours, which vary, so they are never chosen).
pub fn xterm_rgb(index: u8) -> [u8; 3] {
    match index {
        16..=231 => {
            let i = index - 16;
            [
                CUBE_LEVELS[usize::from(i / 36)],
                CUBE_LEVELS[usize::from(i / 6 % 6)],
                CUBE_LEVELS[usize::from(i % 6)],
            ]
        }
        232..=255 => [8 + (index - 232) * 10; 3],
        // The first 16 follow the terminal theme: no fixed colour, black stands in.
        _ => [0; 3],
    }
}

/// A colour in CIELAB (D65 white): L* lightness, a* green-red, b* blue-yellow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lab {
    pub l: f32,
    pub a: f32,
    pub b: f32,
}

impl Lab {
    pub fn from_srgb(rgb: [u8; 3]) -> Lab {
        let linear = rgb.map(|c| {
            let c = f32::from(c) / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        });
        let [r, g, b] = linear;
        // sRGB to XYZ, normalised by the D65 white point.
        let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
        let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
        let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
        let f = |t: f32| {
            if t > 216.0 / 24389.0 {
                t.cbrt()
            } else {
                (24389.0 / 27.0 * t + 16.0) / 116.0
            }
        };
        let (fx, fy, fz) = (f(x), f(y), f(z));
        Lab {
            l: 116.0 * fy - 16.0,
            a: 500.0 * (fx - fy),
            b: 200.0 * (fy - fz),
        }
    }

    /// Chroma: how far from grey.
    pub fn chroma(self) -> f32 {
        self.a.hypot(self.b)
    }

    /// Hue angle in degrees, 0 to 360.
    pub fn hue(self) -> f32 {
        self.b.atan2(self.a).to_degrees().rem_euclid(360.0)
    }

    /// CIE76 colour difference: plain distance in Lab.
    pub fn delta_e(self, other: Lab) -> f32 {
        let (dl, da, db) = (self.l - other.l, self.a - other.a, self.b - other.b);
        (dl * dl + da * da + db * db).sqrt()
    }

    /// The unit vector of the hue in the a*b* plane, `None` for (near) greys.
    fn hue_direction(self) -> Option<(f32, f32)> {
        let chroma = self.chroma();
        (chroma >= GREY_CHROMA).then(|| (self.a / chroma, self.b / chroma))
    }

    /// How far `shown` looks from `self` when it stands in for it: the plain Lab distance,
    /// plus a penalty for a shifted hue. The penalty is the hue chord at the target's
    /// chroma (`C · 2 sin(Δh/2)`), and a grey counts as the opposite hue: otherwise a grey
    /// costs only the lost chroma and wins for dark or muted colours (a dark red turns grey,
    /// a cream wall pinkish grey). Near-grey targets, whose hue is noise, pay no penalty;
    /// it grows to full strength from chroma 5 to 20.
    fn substitution_cost(self, shown: Lab) -> f32 {
        let distance = self.delta_e(shown);
        let chroma = self.chroma();
        let Some((ta, tb)) = self.hue_direction() else {
            return distance;
        };
        let strength = ((chroma - GREY_CHROMA) / 15.0).clamp(0.0, 1.0);
        let chord = match shown.hue_direction() {
            Some((sa, sb)) => (ta - sa).hypot(tb - sb),
            None => 2.0,
        };
        distance + strength * chroma * chord
    }
}

/// Below this chroma a colour reads as grey and its hue angle means nothing.
const GREY_CHROMA: f32 = 5.0;

/// The palette entries 16 to 255 with their Lab values, computed once.
fn palette() -> &'static [(u8, Lab)] {
    static PALETTE: OnceLock<Vec<(u8, Lab)>> = OnceLock::new();
    PALETTE.get_or_init(|| {
        (16..=255u8)
            .map(|index| (index, Lab::from_srgb(xterm_rgb(index))))
            .collect()
    })
}

/// The xterm palette index (16 to 255) that looks nearest to `rgb`: the smallest
/// [`Lab::substitution_cost`] over the whole cube and grey ramp (not the nearest level per
/// channel, which rounds each channel on its own and shifts hues).
pub fn nearest_xterm_index(rgb: [u8; 3]) -> u8 {
    let target = Lab::from_srgb(rgb);
    palette()
        .iter()
        .map(|&(index, lab)| (index, target.substitution_cost(lab)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(16, |(index, _)| index)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_tracer::display::linear_to_srgb8_rgb;
    use whitted_tracer::{render_with_pixel_stats, NoObserver, RenderOptions};

    /// The difference of two hue angles, 0 to 180 degrees.
    fn hue_difference(a: f32, b: f32) -> f32 {
        let d = (a - b).rem_euclid(360.0);
        d.min(360.0 - d)
    }

    /// How a mapping does on a set of colours: the mean CIE76 ΔE, and the largest hue shift
    /// among saturated colours (chroma above `SATURATED`), where a hue is well defined.
    struct Fidelity {
        mean_delta_e: f32,
        worst_hue_shift: f32,
        worst_colour: [u8; 3],
    }

    const SATURATED: f32 = 20.0;

    fn fidelity(colours: &[[u8; 3]], map: impl Fn([u8; 3]) -> u8) -> Fidelity {
        let mut total = 0.0f64;
        let mut worst_hue_shift = 0.0f32;
        let mut worst_colour = [0; 3];
        for &rgb in colours {
            let truth = Lab::from_srgb(rgb);
            let shown = Lab::from_srgb(xterm_rgb(map(rgb)));
            total += f64::from(truth.delta_e(shown));
            if truth.chroma() > SATURATED {
                // A saturated colour shown as grey has lost its hue altogether.
                let shift = if shown.chroma() < GREY_CHROMA {
                    180.0
                } else {
                    hue_difference(truth.hue(), shown.hue())
                };
                if shift > worst_hue_shift {
                    worst_hue_shift = shift;
                    worst_colour = rgb;
                }
            }
        }
        Fidelity {
            mean_delta_e: (total / colours.len().max(1) as f64) as f32,
            worst_hue_shift,
            worst_colour,
        }
    }

    /// Every pixel of scenes/whitted.scene, rendered (8-bit sRGB, as the pane shows it).
    fn whitted_pixels() -> Vec<[u8; 3]> {
        let scene = crate::test_scene::whitted_scene();
        let loaded = crate::app::LoadedScene::new(scene);
        let options = RenderOptions::from_settings(&loaded.scene.settings);
        let (image, _, _) = render_with_pixel_stats(&loaded.prepared, &options, &NoObserver)
            .expect("not cancelled");
        image
            .pixels
            .iter()
            .map(|&c| linear_to_srgb8_rgb(c))
            .collect()
    }

    /// Colours that a per-channel rounding gets wrong: creams, skin tones, near-greys with
    /// a tint, pastels, plus a coarse sweep of the whole RGB cube.
    fn generated_colours() -> Vec<[u8; 3]> {
        let mut colours = vec![
            [255, 253, 208], // cream
            [245, 235, 200], // cream wall
            [240, 225, 190],
            [230, 210, 170],
            [255, 224, 189], // skin tones
            [234, 192, 134],
            [198, 134, 66],
            [141, 85, 36],
            [224, 172, 105],
            [200, 200, 190], // near-greys with a tint
            [128, 130, 140],
            [90, 92, 85],
            [60, 55, 50],
            [250, 200, 210], // pastels
            [200, 230, 250],
            [210, 250, 200],
        ];
        for r in (0..=255u16).step_by(17) {
            for g in (0..=255u16).step_by(17) {
                for b in (0..=255u16).step_by(17) {
                    colours.push([r as u8, g as u8, b as u8]);
                }
            }
        }
        colours
    }

    /// Measured 2026-11-25 with this mapping: whitted.scene's 307,200 pixels have a mean
    /// ΔE76 of 8.59 (8.47 is the floor: the nearest entry by ΔE76 alone, which turns some
    /// dark reds grey) and no saturated pixel's hue moves more than 24.7°; the generated
    /// colours: mean ΔE76 9.80, worst hue shift 33.0°. The old per-channel rounding (with
    /// a grey-ramp check by RGB distance) measured mean ΔE76 10.56 and 12.13 and turned
    /// saturated colours grey (hue lost, counted as 180°); it drew the cream (245, 235, 200)
    /// as (255, 215, 215), pink.
    #[test]
    fn the_256_colour_mapping_keeps_hues_and_stays_close() {
        let scene = fidelity(&whitted_pixels(), nearest_xterm_index);
        let generated = fidelity(&generated_colours(), nearest_xterm_index);
        for (name, f, mean_bound, hue_bound) in [
            ("whitted.scene", &scene, 9.0, 30.0),
            ("generated colours", &generated, 10.5, 40.0),
        ] {
            assert!(
                f.mean_delta_e < mean_bound,
                "{name}: mean ΔE {}",
                f.mean_delta_e
            );
            assert!(
                f.worst_hue_shift < hue_bound,
                "{name}: hue moved {}° at {:?}",
                f.worst_hue_shift,
                f.worst_colour
            );
        }
        let cream = [245, 235, 200];
        let shown = xterm_rgb(nearest_xterm_index(cream));
        let shift = hue_difference(Lab::from_srgb(cream).hue(), Lab::from_srgb(shown).hue());
        assert!(
            shift < 20.0,
            "the cream wall shows as {shown:?}, hue moved {shift}°"
        );
    }

    #[test]
    fn palette_entries_map_to_themselves_and_lab_is_right() {
        for index in 16..=255u8 {
            let rgb = xterm_rgb(index);
            assert_eq!(xterm_rgb(nearest_xterm_index(rgb)), rgb, "entry {index}");
        }
        let white = Lab::from_srgb([255, 255, 255]);
        assert!(
            (white.l - 100.0).abs() < 0.01 && white.chroma() < 0.01,
            "{white:?}"
        );
        let red = Lab::from_srgb([255, 0, 0]);
        // The textbook values for sRGB red: L 53.24, a 80.09, b 67.20.
        assert!((red.l - 53.24).abs() < 0.05, "{red:?}");
        assert!(
            (red.a - 80.09).abs() < 0.05 && (red.b - 67.20).abs() < 0.05,
            "{red:?}"
        );
        assert_eq!(nearest_xterm_index([255, 0, 0]), 196);
        assert_eq!(nearest_xterm_index([0, 0, 0]), 16);
    }
}
