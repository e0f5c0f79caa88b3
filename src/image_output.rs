//! Encoding a linear-light image to PNG, EXR, HDR, PPM or TGA, written atomically.

use std::io::{BufWriter, Write};
use std::path::Path;

use whitted_tracer::display::{linear_to_srgb8_rgb, srgb_to_linear};

use crate::cli::ImageFormat;

/// 8-bit sRGB bytes, three per pixel, rounded to nearest.
pub fn to_srgb8(pixels: &[[f32; 3]]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|&p| linear_to_srgb8_rgb(p))
        .collect()
}

/// An image's pixels, row-major, top first.
pub enum Pixels<'a> {
    /// Linear RGB (a render).
    Linear(&'a [[f32; 3]]),
    /// 8-bit sRGB, three bytes per pixel (the heat maps), taken as they are by PNG and PPM.
    Srgb8(Vec<u8>),
    /// 8-bit linear values, three bytes per pixel (the MIT 6.837 course's images: colour
    /// times 255, no transfer curve), taken as they are by the 8-bit formats.
    Linear8(Vec<u8>),
}

/// Linear colours to 8-bit linear bytes as the 6.837 course wrote them: each channel clamped
/// to [0, 1], times 255, rounded to nearest.
pub fn to_linear8(pixels: &[[f32; 3]]) -> Vec<u8> {
    pixels
        .iter()
        .flatten()
        .map(|&c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// Writes `pixels` to `path` in `format`.
///
/// The bytes go to a temporary file beside the target, which is renamed over it only when
/// complete: a failed write never leaves half an image or clobbers the old one.
pub fn write_image(
    path: &Path,
    format: ImageFormat,
    width: u32,
    height: u32,
    pixels: Pixels<'_>,
) -> Result<(), String> {
    write_atomically(path, |file| encode(file, format, width, height, pixels))
}

/// Writes a file through `write`, atomically as [`write_image`] does: into a temporary file
/// beside `path`, renamed over it only when complete.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> Result<(), String>,
) -> Result<(), String> {
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let describe = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", path.display());
    let mut builder = tempfile::Builder::new();
    builder.prefix(".whitted-").suffix(".tmp");
    // Temporary files are private (0600) by default; an image is not, so ask for the usual
    // 0666 and let the umask decide, as for any file a program creates.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut temp = builder.tempfile_in(dir).map_err(|e| describe(&e))?;
    // Dropped after the rename or the temporary file's own removal, both below.
    let _registered = crate::interrupt::register(temp.path());
    write(temp.as_file_mut()).map_err(|e| describe(&e))?;
    temp.as_file().sync_all().map_err(|e| describe(&e))?;
    temp.persist(path).map_err(|e| describe(&e.error))?;
    Ok(())
}

fn encode(
    file: &mut std::fs::File,
    format: ImageFormat,
    width: u32,
    height: u32,
    pixels: Pixels<'_>,
) -> Result<(), String> {
    let mut writer = BufWriter::new(file);
    // Only the buffer the format needs is made, one at a time: at the largest image size
    // every copy costs gigabytes.
    let srgb8 = |pixels: Pixels<'_>| match pixels {
        Pixels::Linear(linear) => to_srgb8(linear),
        Pixels::Srgb8(bytes) | Pixels::Linear8(bytes) => bytes,
    };
    let floats = |pixels: Pixels<'_>| -> Vec<f32> {
        match pixels {
            Pixels::Linear(linear) => linear.iter().flatten().copied().collect(),
            Pixels::Srgb8(bytes) => bytes
                .iter()
                .map(|&b| srgb_to_linear(f32::from(b) / 255.0))
                .collect(),
            Pixels::Linear8(bytes) => bytes.iter().map(|&b| f32::from(b) / 255.0).collect(),
        }
    };
    match format {
        ImageFormat::Png => {
            let image = image::RgbImage::from_raw(width, height, srgb8(pixels))
                .ok_or("the image has the wrong number of pixels")?;
            image
                .write_to(&mut writer, image::ImageFormat::Png)
                .map_err(|e| e.to_string())?;
        }
        ImageFormat::Exr | ImageFormat::Hdr => {
            let image = image::Rgb32FImage::from_raw(width, height, floats(pixels))
                .ok_or("the image has the wrong number of pixels")?;
            let kind = if format == ImageFormat::Exr {
                image::ImageFormat::OpenExr
            } else {
                image::ImageFormat::Hdr
            };
            image::DynamicImage::ImageRgb32F(image)
                .write_to(&mut writer, kind)
                .map_err(|e| e.to_string())?;
        }
        ImageFormat::Ppm => {
            write!(writer, "P6\n{width} {height}\n255\n").map_err(|e| e.to_string())?;
            writer
                .write_all(&srgb8(pixels))
                .map_err(|e| e.to_string())?;
        }
        ImageFormat::Tga => write_tga(&mut writer, width, height, &srgb8(pixels))?,
    }
    writer.flush().map_err(|e| e.to_string())
}

/// An uncompressed 24-bit Targa image (type 2), rows bottom first and blue-green-red as the
/// format's origin in the lower left corner (descriptor 0) has them: what the 6.837 course's
/// images were, and what every reader of the format takes.
fn write_tga(writer: &mut impl Write, width: u32, height: u32, rgb: &[u8]) -> Result<(), String> {
    let (Ok(w), Ok(h)) = (u16::try_from(width), u16::try_from(height)) else {
        return Err(format!(
            "a TGA image is at most 65535 pixels wide and high, not {width}x{height}"
        ));
    };
    let row = width as usize * 3;
    if rgb.len() != row * height as usize {
        return Err("the image has the wrong number of pixels".into());
    }
    let mut header = [0u8; 18];
    header[2] = 2;
    header[12..14].copy_from_slice(&w.to_le_bytes());
    header[14..16].copy_from_slice(&h.to_le_bytes());
    header[16] = 24;
    writer.write_all(&header).map_err(|e| e.to_string())?;
    let mut bgr = Vec::with_capacity(row);
    for line in rgb.chunks_exact(row.max(1)).rev() {
        bgr.clear();
        bgr.extend(line.chunks_exact(3).flat_map(|p| [p[2], p[1], p[0]]));
        writer.write_all(&bgr).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_bytes_survive_the_linear_round_trip_of_the_float_formats() {
        for byte in 0..=255u8 {
            let linear = srgb_to_linear(f32::from(byte) / 255.0);
            assert_eq!(linear_to_srgb8_rgb([linear; 3]), [byte; 3]);
        }
    }

    #[test]
    fn pixels_become_three_srgb_bytes_each() {
        assert_eq!(
            to_srgb8(&[[0.0, 1.0, 7.0], [0.25; 3]]),
            vec![0, 255, 255, 137, 137, 137]
        );
    }

    #[test]
    fn every_format_round_trips_its_size_and_a_failed_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let pixels = vec![[0.25f32, 0.5, 1.0]; 6];
        for (name, format) in [
            ("a.png", ImageFormat::Png),
            ("a.exr", ImageFormat::Exr),
            ("a.hdr", ImageFormat::Hdr),
        ] {
            let path = dir.path().join(name);
            write_image(&path, format, 3, 2, Pixels::Linear(&pixels)).unwrap();
            let decoded = image::open(&path).unwrap();
            assert_eq!((decoded.width(), decoded.height()), (3, 2), "{name}");
        }
        let ppm = dir.path().join("a.ppm");
        write_image(&ppm, ImageFormat::Ppm, 3, 2, Pixels::Linear(&pixels)).unwrap();
        let bytes = std::fs::read(&ppm).unwrap();
        assert!(bytes.starts_with(b"P6\n3 2\n255\n"));
        assert_eq!(bytes.len(), 11 + 18);

        // A wrong pixel count fails before the rename: the old image stays intact.
        let png = dir.path().join("a.png");
        let before = std::fs::read(&png).unwrap();
        assert!(write_image(&png, ImageFormat::Png, 4, 4, Pixels::Linear(&pixels)).is_err());
        assert_eq!(std::fs::read(&png).unwrap(), before);
        let leftovers = std::fs::read_dir(dir.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".tmp")
            })
            .count();
        assert_eq!(leftovers, 0, "the temporary file must be removed");
    }

    #[test]
    fn linear_bytes_are_the_colour_times_255_clamped() {
        assert_eq!(
            to_linear8(&[[0.0, 0.5, 1.0], [-1.0, 2.0, 0.25]]),
            vec![0, 128, 255, 0, 255, 64]
        );
    }

    #[test]
    fn a_tga_is_bottom_up_bgr_after_its_header_and_image_reads_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.tga");
        // Top row red, bottom row blue, two pixels each.
        let bytes = vec![255, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0, 255];
        write_image(&path, ImageFormat::Tga, 2, 2, Pixels::Linear8(bytes)).unwrap();
        let file = std::fs::read(&path).unwrap();
        assert_eq!(
            &file[..18],
            &[0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 24, 0]
        );
        // The first row in the file is the bottom (blue) one, in BGR order.
        assert_eq!(&file[18..24], &[255, 0, 0, 255, 0, 0]);
        assert_eq!(&file[24..30], &[0, 0, 255, 0, 0, 255]);
        assert_eq!(file.len(), 18 + 12);
        // A standard decoder reads it the right way up.
        let decoded = image::open(&path).unwrap().into_rgb8();
        assert_eq!(decoded.dimensions(), (2, 2));
        assert_eq!(decoded.get_pixel(0, 0).0, [255, 0, 0]);
        assert_eq!(decoded.get_pixel(1, 1).0, [0, 0, 255]);
    }

    #[cfg(unix)]
    #[test]
    fn images_get_ordinary_permissions_not_the_temporary_files_private_ones() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.png");
        write_image(
            &path,
            ImageFormat::Png,
            1,
            1,
            Pixels::Linear(&[[0.5, 0.5, 0.5]]),
        )
        .unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_ne!(
            mode & 0o044,
            0,
            "others cannot read the image: mode {mode:o}"
        );
    }
}
