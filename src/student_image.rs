//! A student's image for `diff --against-image`: PNG, TGA or PPM (8-bit values, as written)
//! or EXR (linear floats), and the 8-bit space the comparison is made in.

use std::path::Path;

use image::{DynamicImage, ImageFormat, ImageReader};

use crate::Failure;

/// What a student's image holds.
pub enum StudentPixels {
    /// 8-bit RGB as the file has it, three bytes a pixel: its space is the writer's.
    Bytes(Vec<u8>),
    /// Linear RGB floats (EXR): compared after encoding, like the reference.
    Linear(Vec<[f32; 3]>),
}

pub struct StudentImage {
    pub width: u32,
    pub height: u32,
    pub pixels: StudentPixels,
}

/// How 8-bit values encode light: the grader's encoding (colour times 255, as the MIT 6.837
/// course wrote images, or the sRGB curve, as `whitted render` writes PNG, TGA and PPM).
pub use whitted_explain::grade::Encoding as Space;

impl StudentImage {
    /// The student's pixels as 8-bit values in `space`.
    pub fn bytes_in(&self, space: Space) -> std::borrow::Cow<'_, [u8]> {
        match &self.pixels {
            StudentPixels::Bytes(bytes) => std::borrow::Cow::Borrowed(bytes),
            StudentPixels::Linear(pixels) => std::borrow::Cow::Owned(space.encode(pixels)),
        }
    }
}

/// Reads the student's image by its content (by its extension for TGA, which has no
/// signature). Every failure names the file.
pub fn read(path: &Path) -> Result<StudentImage, Failure> {
    let cannot = |e: &dyn std::fmt::Display| {
        Failure::Message(format!(
            "cannot read the student's image {}: {e}",
            path.display()
        ))
    };
    let reader = ImageReader::open(path)
        .map_err(|e| cannot(&e))?
        .with_guessed_format()
        .map_err(|e| cannot(&e))?;
    let format = reader.format();
    if !matches!(
        format,
        Some(ImageFormat::Png | ImageFormat::Tga | ImageFormat::Pnm | ImageFormat::OpenExr)
    ) {
        return Err(cannot(&"it is not a PNG, TGA, PPM or EXR image"));
    }
    let decoded = reader.decode().map_err(|e| cannot(&e))?;
    let (width, height) = (decoded.width(), decoded.height());
    let pixels = if format == Some(ImageFormat::OpenExr) {
        let floats = DynamicImage::to_rgb32f(&decoded).into_raw();
        StudentPixels::Linear(floats.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
    } else {
        StudentPixels::Bytes(decoded.to_rgb8().into_raw())
    };
    Ok(StudentImage {
        width,
        height,
        pixels,
    })
}
