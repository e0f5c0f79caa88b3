//! What the command line asks of the image, checked before any work: the size that
//! `--width`/`--height` make, the pixel of `--pixel` and the sample of `--sample`. A refusal
//! is a usage error (exit 2) that quotes the flag, whichever command it came to.

use whitted_ir::limits;
use whitted_tracer::ray_tree::{check_request, SampleChoice, TraceError};
use whitted_tracer::RenderOptions;

use crate::cli::RenderOverrides;
use crate::Failure;

/// The size flags as the user gave them, e.g. "--width 30000 --height 30000"; `None` when
/// neither was given.
pub fn size_flags(overrides: &RenderOverrides) -> Option<String> {
    let flags: Vec<String> = [("--width", overrides.width), ("--height", overrides.height)]
        .into_iter()
        .filter_map(|(flag, value)| value.map(|v| format!("{flag} {v}")))
        .collect();
    (!flags.is_empty()).then(|| flags.join(" "))
}

/// Refuses a `width` x `height` image past the image side or pixels limit. The compiler
/// refuses such a size in the scene or a `--set` (with its own diagnostic), so a size past
/// them here was made by `--width`/`--height`: a usage error naming them.
pub fn check_size(overrides: &RenderOverrides, width: u32, height: u32) -> Result<(), Failure> {
    let Some(flags) = size_flags(overrides) else {
        // Not the command line's size: whatever made it answers for it.
        return crate::render_cmd::check_image_size(width, height);
    };
    let pixels = u64::from(width) * u64::from(height);
    // One flag alone keeps the scene's aspect ratio: say what size that made.
    let (asks, hint) = if overrides.width.is_some() && overrides.height.is_some() {
        ("asks for".to_string(), "")
    } else {
        (
            format!("makes a {width}x{height} image (the scene's aspect ratio) with"),
            ": give both --width and --height",
        )
    };
    if width.max(height) > limits::MAX_IMAGE_SIDE {
        return Err(Failure::Usage(format!(
            "`{flags}` {asks} a side over the image side limit ({}){hint}",
            limits::MAX_IMAGE_SIDE
        )));
    }
    if pixels > limits::MAX_PIXELS {
        return Err(Failure::Usage(format!(
            "`{flags}` {asks} {pixels} pixels, more than the pixels limit ({}, about \
             11585x11585)",
            limits::MAX_PIXELS
        )));
    }
    Ok(())
}

/// Checks that `--pixel x,y` (and `--sample`, if given) exist in the image of `options`.
pub fn check_pixel(
    options: &RenderOptions,
    [x, y]: [u32; 2],
    sample: Option<u32>,
) -> Result<(), Failure> {
    let which = sample.map_or(SampleChoice::All, SampleChoice::One);
    check_request(options, x, y, which).map_err(|error| trace_failure(&error))
}

/// A pixel or sample that does not exist is the command line's (exit 2), quoting the flag;
/// a cancelled trace is not.
pub fn trace_failure(error: &TraceError) -> Failure {
    match *error {
        TraceError::PixelOutOfRange {
            x,
            y,
            width,
            height,
        } => pixel_outside([x, y], width, height),
        TraceError::SampleOutOfRange {
            sample,
            samples_per_pixel,
        } => {
            let range = match samples_per_pixel {
                1 => "1 sample per pixel (sample 0)".to_string(),
                n => format!("{n} samples per pixel (0 to {})", n - 1),
            };
            Failure::Usage(format!(
                "`--sample {sample}` is not a sample of the pixel: the image has {range}"
            ))
        }
        TraceError::Cancelled => Failure::Message(error.to_string()),
    }
}

/// `--pixel x,y` outside a `width` x `height` image.
pub fn pixel_outside([x, y]: [u32; 2], width: u32, height: u32) -> Failure {
    Failure::Usage(format!(
        "`--pixel {x},{y}` is outside the {width}x{height} image (x must be 0 to {}, y 0 to {})",
        width.saturating_sub(1),
        height.saturating_sub(1)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sized(width: Option<u32>, height: Option<u32>) -> RenderOverrides {
        RenderOverrides {
            width,
            height,
            ..RenderOverrides::default()
        }
    }

    fn usage(result: Result<(), Failure>) -> String {
        match result {
            Err(Failure::Usage(message)) => message,
            Err(other) => panic!("not a usage error: exit {}", other.exit_code()),
            Ok(()) => panic!("accepted"),
        }
    }

    #[test]
    fn sizes_past_the_limits_quote_the_flags() {
        let message = usage(check_size(&sized(Some(30000), Some(30000)), 30000, 30000));
        assert!(
            message.starts_with("`--width 30000 --height 30000` asks for 900000000 pixels"),
            "{message}"
        );
        let message = usage(check_size(&sized(None, Some(32000)), 42667, 32000));
        assert!(
            message.starts_with("`--height 32000` makes a 42667x32000 image"),
            "{message}"
        );
        assert!(
            message.ends_with("give both --width and --height"),
            "{message}"
        );
        assert!(check_size(&sized(Some(640), None), 640, 480).is_ok());
    }

    #[test]
    fn a_missing_pixel_or_sample_quotes_its_flag() {
        let failure = trace_failure(&TraceError::PixelOutOfRange {
            x: 640,
            y: 10,
            width: 640,
            height: 480,
        });
        assert_eq!(failure.exit_code(), 2);
        assert_eq!(
            failure.message(),
            Some("`--pixel 640,10` is outside the 640x480 image (x must be 0 to 639, y 0 to 479)")
        );
        let failure = trace_failure(&TraceError::SampleOutOfRange {
            sample: 16,
            samples_per_pixel: 16,
        });
        assert_eq!(
            failure.message(),
            Some("`--sample 16` is not a sample of the pixel: the image has 16 samples per pixel (0 to 15)")
        );
        assert_eq!(trace_failure(&TraceError::Cancelled).exit_code(), 1);
    }
}
