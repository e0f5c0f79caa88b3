//! A material's thumbnail for the language server's hover: a small ball of it on a grey
//! floor, rendered by the tracer (the same code path as `whitted render`), as a PNG
//! `data:` URI that a client showing Markdown images displays without any file written.
//! The binary hands it to `whitted-lsp`, which never renders itself.

use std::io::Cursor;

use whitted_ir::{Arena, Color, DMat4, DVec3, Handle, Material};
use whitted_tracer::display::linear_to_srgb8;
use whitted_tracer::testing::{matte, plane_y, sphere, SceneBuilder};
use whitted_tracer::{NoObserver, RenderOptions};

/// The thumbnail's side in pixels: big enough to see a highlight and a reflection.
pub const SIDE: u32 = 64;

/// The renderer `whitted lsp` is given.
pub struct Balls;

impl whitted_lsp::Thumbnails for Balls {
    fn material(&self, materials: &Arena<Material>, material: Handle<Material>) -> Option<String> {
        ball(materials, material)
    }
}

/// The ball of `target` (a handle into `materials`, which patterns may refer to), or `None`
/// when the material cannot be rendered on its own.
pub fn ball(materials: &Arena<Material>, target: Handle<Material>) -> Option<String> {
    let mut b = SceneBuilder::new();
    // The same order, so that handles (the ball's, and a pattern's two materials) hold.
    for (_, material) in materials.iter() {
        b.material(material.clone());
    }
    // A handle from another scene would render the wrong ball, or none.
    materials.get(target)?;
    let floor = b.material(Material {
        ambient: Color::gray(0.2),
        ..matte(0.55, 0.55, 0.55)
    });
    let settings = b.settings();
    settings.width = SIDE;
    settings.height = SIDE;
    settings.max_depth = 4;
    settings.background = Color::new(0.25, 0.3, 0.4);
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, target);
    b.add(plane_y(-1.0), DMat4::IDENTITY, floor);
    b.camera(DVec3::new(0.0, 0.8, -3.6), DVec3::new(0.0, -0.1, 0.0), 40.0);
    b.point_light(DVec3::new(-3.0, 4.0, -4.0), 1.0);
    let scene = b.prepare().ok()?;
    let options = RenderOptions::from_settings(scene.settings());
    let (image, _) = whitted_tracer::render(&scene, &options, &NoObserver)?;
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| p.map(linear_to_srgb8))
        .collect();
    let mut png = Vec::new();
    image::write_buffer_with_format(
        &mut Cursor::new(&mut png),
        &bytes,
        SIDE,
        SIDE,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .ok()?;
    Some(format!("data:image/png;base64,{}", base64(&png)))
}

/// Standard base64 (RFC 4648, with padding).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * k) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_s_examples() {
        // RFC 4648, section 10.
        for (text, expected) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(text.as_bytes()), expected);
        }
    }

    #[test]
    fn a_red_ball_is_red_in_the_middle() {
        let mut materials = Arena::new();
        let red = materials.append(matte(0.9, 0.05, 0.05), whitted_ir::Span::detached());
        let uri = ball(&materials, red).expect("a thumbnail");
        let encoded = uri
            .strip_prefix("data:image/png;base64,")
            .expect("a PNG data URI");
        // Decode with a second, independent reading: the image crate on the bytes.
        let png = decode(encoded);
        let image = image::load_from_memory(&png).expect("a PNG").to_rgb8();
        assert_eq!((image.width(), image.height()), (SIDE, SIDE));
        let centre = image.get_pixel(SIDE / 2, SIDE / 2 - 4).0;
        assert!(centre[0] > 2 * centre[1] && centre[0] > 60, "{centre:?}");
    }

    fn decode(text: &str) -> Vec<u8> {
        let value = |c: u8| {
            b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
                .iter()
                .position(|&a| a == c)
                .expect("a base64 digit") as u32
        };
        let mut out = Vec::new();
        for chunk in text.as_bytes().chunks(4) {
            let digits: Vec<u32> = chunk
                .iter()
                .filter(|&&c| c != b'=')
                .map(|&c| value(c))
                .collect();
            let n = digits
                .iter()
                .enumerate()
                .fold(0u32, |n, (i, d)| n | d << (18 - 6 * i));
            for k in 0..digits.len().saturating_sub(1) {
                out.push((n >> (16 - 8 * k)) as u8);
            }
        }
        out
    }
}
