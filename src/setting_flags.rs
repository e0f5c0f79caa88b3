//! Settings given on the command line, applied to the IR through the settings table
//! (`whitted_ir::setting_rows`) before the scene is prepared, so that the IR is the whole
//! truth of what is rendered: the render flags (`--width`, `--height`, `--spp`,
//! `--max-depth`) of every command, and `--set` for a 6.837 scene (a scene in the language
//! evaluates `--set` values as its own expressions while it compiles, through the same rows).
//!
//! Each setting is recorded in the scene's table of written settings, in a pseudo-file named
//! after the flag, so that explain and the lints say where the value came from.

use whitted_ir::setting_rows::{self, SettingRow, SettingValue};
use whitted_ir::{
    BlockKind, Diagnostic, Scene, SourceFile, SourceMap, Span, ValidScene, WrittenBlock,
    WrittenProperty,
};
use whitted_tracer::RenderOptions;

use crate::cli::RenderOverrides;
use crate::scene_input::Loaded;
use crate::Failure;

/// One setting to write: which row, the value, and the flag's text with the value's place
/// in it.
struct Assignment {
    row: &'static SettingRow,
    value: SettingValue,
    flag: String,
    value_at: std::ops::Range<usize>,
}

/// Applies the render flags to `loaded`'s scene and returns the options to render it with:
/// read from the scene's settings, which now hold the flags.
pub fn apply_render_flags(
    loaded: Loaded,
    overrides: &RenderOverrides,
) -> Result<(Loaded, RenderOptions), Failure> {
    let Loaded {
        scene,
        warnings,
        warned_at,
    } = loaded;
    let scene = apply_to_scene(scene, overrides)?;
    let options = RenderOptions::from_settings(&scene.settings);
    let loaded = Loaded {
        scene,
        warnings,
        warned_at,
    };
    Ok((loaded, options))
}

/// Applies the render flags to `scene`'s settings (the debugger does it again at each
/// reload, so that the scene keeps the size it was opened at).
pub fn apply_to_scene(
    scene: ValidScene,
    overrides: &RenderOverrides,
) -> Result<ValidScene, Failure> {
    let settings = &scene.settings;
    let (width, height) = image_size(
        (settings.width, settings.height),
        overrides.width,
        overrides.height,
    );
    crate::request::check_size(overrides, width, height)?;
    let mut assignments = Vec::new();
    // A side worked out from the other keeps the scene's aspect ratio; it is recorded under
    // the flag that decided it.
    let size_flag = match (overrides.width, overrides.height) {
        (Some(w), Some(h)) => Some(format!("--width {w} --height {h}")),
        (Some(w), None) => Some(format!("--width {w}")),
        (None, Some(h)) => Some(format!("--height {h}")),
        (None, None) => None,
    };
    if let Some(flag) = size_flag {
        for (row, side) in [
            (&setting_rows::WIDTH, width),
            (&setting_rows::HEIGHT, height),
        ] {
            assignments.push(Assignment {
                row,
                value: SettingValue::Whole(side),
                value_at: 0..flag.len(),
                flag: flag.clone(),
            });
        }
    }
    for (row, name, value) in [
        (&setting_rows::SAMPLES, "--spp", overrides.spp),
        (&setting_rows::MAX_DEPTH, "--max-depth", overrides.max_depth),
    ] {
        if let Some(value) = value {
            let flag = format!("{name} {value}");
            assignments.push(Assignment {
                row,
                value: SettingValue::Whole(value),
                value_at: name.len() + 1..flag.len(),
                flag,
            });
        }
    }
    if assignments.is_empty() {
        return Ok(scene);
    }
    assign(scene.into_inner(), assignments).map_err(|message| {
        Failure::Usage(format!("the command line's settings do not fit: {message}"))
    })
}

/// Writes `assignments` into the scene's settings and its table of written settings, then
/// validates the scene again (a setting can only make it invalid through a limit the flags
/// already check; the error is kept for safety, never a panic).
fn assign(mut scene: Scene, assignments: Vec<Assignment>) -> Result<ValidScene, String> {
    let mut files: Vec<(String, whitted_ir::FileId)> = Vec::new();
    for assignment in assignments {
        let value = assignment.row.check(assignment.value)?;
        (assignment.row.set)(&mut scene.settings, value);
        let file = match files.iter().find(|(flag, _)| *flag == assignment.flag) {
            Some(&(_, file)) => file,
            None => {
                let file = scene.sources.add(SourceFile::new(
                    format!("<{}>", assignment.flag),
                    assignment.flag.clone(),
                ));
                files.push((assignment.flag.clone(), file));
                file
            }
        };
        record(
            &mut scene,
            assignment.row.name,
            Span::new(file, 0, assignment.flag.len()),
            Span::new(file, assignment.value_at.start, assignment.value_at.end),
        );
    }
    whitted_ir::validate(scene).map_err(|invalid| {
        invalid
            .diagnostics
            .iter()
            .map(|d| d.message.clone())
            .collect::<Vec<_>>()
            .join("; ")
    })
}

/// Records a setting written on the command line, in a settings block of its own after the
/// scene's (so that it is the one that took effect).
fn record(scene: &mut Scene, name: &'static str, flag: Span, value: Span) {
    let block = scene.written.add_block(WrittenBlock {
        kind: BlockKind::Settings,
        header: flag,
        body: Span::detached(),
    });
    scene.written.add_property(WrittenProperty {
        block,
        name,
        name_span: Span::new(flag.file, flag.start as usize, value.start as usize),
        value_span: value,
    });
}

/// `--set NAME=VALUE` for a 6.837 scene: each read by its row's plain-value reader (a
/// number, a word, a grey or `rgb(r, g, b)`) and applied to the scene's settings. Returns
/// the diagnostics, located in the `--set` pseudo-files (which `load_scene` turns into a
/// command-line error), with the sources they point into.
pub fn apply_course_sets(
    scene: ValidScene,
    sets: &[(String, String)],
) -> Result<ValidScene, (SourceMap, Vec<Diagnostic>)> {
    let mut scene = scene.into_inner();
    let mut diagnostics = Vec::new();
    let mut settings = scene.settings.clone();
    let mut recorded = Vec::new();
    for (name, value) in sets {
        let text = format!("{name}={value}");
        let file = scene
            .sources
            .add(SourceFile::new(format!("<--set {text}>"), text.clone()));
        let name_span = Span::new(file, 0, name.len());
        let value_span = Span::new(file, name.len() + 1, text.len());
        let Some(row) = setting_rows::setting(name) else {
            let names: Vec<String> = setting_rows::setting_names()
                .map(|n| format!("`{n}`"))
                .collect();
            let (last, rest) = names
                .split_last()
                .map_or(("", &[][..]), |(l, r)| (l.as_str(), r));
            diagnostics.push(
                Diagnostic::error(format!("there is no setting `{name}`"), name_span)
                    .with_label("not a setting")
                    .with_hint(format!("the settings are {} and {last}", rest.join(", "))),
            );
            continue;
        };
        match row.parse(value) {
            Ok(parsed) => {
                (row.set)(&mut settings, parsed);
                recorded.push((row.name, name_span, value_span));
            }
            Err(message) => diagnostics.push(
                Diagnostic::error(message, value_span)
                    .with_label(format!("`{}` here", value.trim())),
            ),
        }
    }
    if !diagnostics.is_empty() {
        return Err((scene.sources, diagnostics));
    }
    scene.settings = settings;
    for (name, name_span, value_span) in recorded {
        let header = Span::new(name_span.file, 0, value_span.end as usize);
        let block = scene.written.add_block(WrittenBlock {
            kind: BlockKind::Settings,
            header,
            body: Span::detached(),
        });
        scene.written.add_property(WrittenProperty {
            block,
            name,
            name_span,
            value_span,
        });
    }
    whitted_ir::validate(scene).map_err(|invalid| {
        let invalid = *invalid;
        (invalid.scene.sources, invalid.diagnostics)
    })
}

/// The size of the image to make: both flags give exactly that size; one alone keeps the
/// scene's aspect ratio, as every image tool does (`--width 320` of a 640x480 scene is
/// 320x240, not a 320x480 crop), the other side rounded and at least 1.
pub fn image_size(scene: (u32, u32), width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let (scene_width, scene_height) = (f64::from(scene.0.max(1)), f64::from(scene.1.max(1)));
    let side = |value: f64| value.round().clamp(1.0, f64::from(u32::MAX)) as u32;
    match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, side(f64::from(w) * scene_height / scene_width)),
        (None, Some(h)) => (side(f64::from(h) * scene_width / scene_height), h),
        (None, None) => scene,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_side_keeps_the_aspect_ratio_and_both_give_the_size() {
        assert_eq!(image_size((640, 480), Some(320), None), (320, 240));
        assert_eq!(image_size((640, 480), None, Some(60)), (80, 60));
        assert_eq!(image_size((640, 480), Some(100), Some(100)), (100, 100));
        assert_eq!(image_size((640, 480), None, None), (640, 480));
        // Rounded, never 0.
        assert_eq!(image_size((1000, 1), Some(10), None), (10, 1));
        assert_eq!(image_size((160, 75), Some(33), None), (33, 15));
    }

    fn loaded(text: &str) -> Loaded {
        let compilation = whitted_lang::compile_source(
            "flags.scene",
            text,
            &mut crate::front_end::DiskLoader,
            &whitted_lang::CompileOptions::default(),
        );
        Loaded {
            scene: compilation.scene.expect("compiles"),
            warnings: 0,
            warned_at: Vec::new(),
        }
    }

    /// The flags are IR data: the prepared scene's settings are what is traced, and the
    /// table of written settings says which flag set each.
    #[test]
    fn render_flags_become_the_scenes_settings() {
        let scene = "settings { width 640 height 480 max_depth 8 }\nsphere { }\n";
        let overrides = RenderOverrides {
            width: Some(320),
            height: None,
            spp: Some(4),
            max_depth: Some(2),
        };
        let Ok((loaded, options)) = apply_render_flags(loaded(scene), &overrides) else {
            panic!("refused");
        };
        let prepared = whitted_tracer::PreparedScene::new(&loaded.scene);
        let settings = prepared.settings();
        assert_eq!((settings.width, settings.height), (320, 240));
        assert_eq!((settings.max_depth, settings.samples_per_pixel), (2, 4));
        assert_eq!(options, RenderOptions::from_settings(settings));
        let scene = &loaded.scene;
        let location = |name: &str| {
            let written = scene.written.setting(name).expect("written");
            scene.sources.location(written.value_span)
        };
        assert_eq!(location("max_depth"), "<--max-depth 2>:1:13");
        assert_eq!(location("height"), "<--width 320>:1:1");
        assert_eq!(location("samples"), "<--spp 4>:1:7");
    }

    #[test]
    fn no_flags_leave_the_scene_as_it_was() {
        let scene = "settings { max_depth 8 }\nsphere { }\n";
        let Ok((loaded, options)) = apply_render_flags(loaded(scene), &RenderOverrides::default())
        else {
            panic!("refused");
        };
        assert_eq!(options.max_depth, 8);
        let written = loaded.scene.written.setting("max_depth").expect("written");
        assert_eq!(
            loaded.scene.sources.location(written.value_span),
            "flags.scene:1:22"
        );
    }
}
