//! Writing a what-if change back into the scene text (`W` in the what-if popup): the scene's
//! table of written properties (filled by the front end, `Scene::written`) gives the span of
//! the value to replace, or the block to add it to when it was not written (a default); a
//! setting not written anywhere creates a `settings` block. When the text cannot be changed
//! safely (a definition made many times by a loop or a function, a value set on the command
//! line, a 6.837 scene), say what to do instead. The file itself is written by the event loop.

use std::sync::Arc;

use whitted_ir::{BlockKind, Scene, SceneFormat, SourceFile, Span, WrittenBlock};

use crate::what_if::{Owner, Param};

/// What writing a change back comes to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WriteBack {
    /// Replace the file at `path` (whose text was `original` when compiled) by `contents`,
    /// which differs from it on line `line` only (or by that one line added).
    Edit {
        path: String,
        original: Arc<String>,
        contents: String,
        line: u32,
        new_line: String,
    },
    /// It cannot be written back safely: why.
    Refused(String),
}

use WriteBack::Refused;

/// Where `param` becomes `value_text` in the scene's files.
pub fn write_back(scene: &Scene, param: Param, value_text: &str) -> WriteBack {
    if scene.format == SceneFormat::Mit6837 {
        let file = scene
            .sources
            .files()
            .next()
            .map_or("the scene".to_string(), |(_, f)| f.path.clone());
        return Refused(format!(
            "{file} is a MIT 6.837 scene: only scene-language files are written back; change it by hand"
        ));
    }
    let property = param.property();
    let owner = param.owner(scene);
    let (kind, header) = match param.owner {
        Owner::Settings => return settings_write_back(scene, property, value_text),
        Owner::Material(h) => {
            let span = scene.materials.span(h);
            // A pattern's colour parts share their host's definition; any other material
            // with the same text was made by the same loop or function.
            let parts = scene
                .materials
                .get(h)
                .and_then(|m| m.pattern.as_ref())
                .map_or(Vec::new(), |p| vec![p.a, p.b]);
            let makes = scene
                .materials
                .iter_with_spans()
                .filter(|&(other, _, s)| s == span && other != h && !parts.contains(&other))
                .count();
            if makes > 0 {
                return Refused(format!(
                    "{owner} is made {} times by the same text (a loop or a function): change it by hand",
                    makes + 1
                ));
            }
            (BlockKind::Material, span)
        }
        Owner::Light(h) => {
            let span = scene.lights.span(h);
            let makes = scene
                .lights
                .iter_with_spans()
                .filter(|&(_, _, s)| s == span)
                .count();
            if makes > 1 {
                return Refused(format!(
                    "{owner} is made {makes} times by the same text (a loop or a function): change it by hand"
                ));
            }
            (BlockKind::Light, span)
        }
    };
    let written: Vec<_> = scene
        .written
        .properties_in(kind, header, property)
        .collect();
    match written.as_slice() {
        [] => match scene.written.block_at(kind, header) {
            Some(block) => add_to_block(scene, block, &owner, property, value_text),
            None => Refused(format!("{owner} was not written in a scene file")),
        },
        [written] => replace(scene, written.value_span, &owner, value_text),
        _ => Refused(format!(
            "{owner} writes {property} {} times: change it by hand",
            written.len()
        )),
    }
}

/// A setting: the one that took effect is replaced where it was written; one not written
/// goes into the scene's `settings` block, or a new block at the top of the scene's file.
fn settings_write_back(scene: &Scene, property: &str, value_text: &str) -> WriteBack {
    if let Some(written) = scene.written.setting(property) {
        if let Some(flag) = command_line(scene, written.value_span) {
            return Refused(format!(
                "{property} is set on the command line ({flag}), which overrides the scene file"
            ));
        }
        return replace(scene, written.value_span, "settings", value_text);
    }
    if let Some(block) = scene.written.settings_blocks().next() {
        return add_to_block(scene, block, "settings", property, value_text);
    }
    let Some((id, file)) = scene
        .sources
        .files()
        .find(|(_, f)| !f.path.starts_with('<'))
    else {
        return Refused("the scene has no file to write to".into());
    };
    let at = Span::new(id, 0, 0);
    insert(
        file,
        at,
        &format!("settings {{ {property} {value_text} }}\n"),
    )
}

/// The flag that wrote `span` (`--set max_depth=9`, `--max-depth 9`), when it was the
/// command line rather than a scene file.
fn command_line(scene: &Scene, span: Span) -> Option<String> {
    let file = scene.sources.get(span.file)?;
    file.path
        .strip_prefix('<')
        .and_then(|p| p.strip_suffix('>'))
        .map(str::to_string)
}

/// The file a span points into, when it is a real file (not `--set` or `-D` text).
fn writable_file(scene: &Scene, span: Span) -> Option<&SourceFile> {
    if span.is_detached() {
        return None;
    }
    scene
        .sources
        .get(span.file)
        .filter(|f| !f.path.starts_with('<'))
}

fn replace(scene: &Scene, value: Span, owner: &str, value_text: &str) -> WriteBack {
    match writable_file(scene, value) {
        Some(file) => edit(file, value, value_text),
        None => Refused(format!("{owner} was not written in a scene file")),
    }
}

/// Adds `property value` to `block`, before its closing brace: on that line when the block
/// is on one line, or on a line of its own, indented like the block's first property.
fn add_to_block(
    scene: &Scene,
    block: &WrittenBlock,
    owner: &str,
    property: &str,
    value_text: &str,
) -> WriteBack {
    let Some(file) = writable_file(scene, block.body) else {
        return Refused(format!("{owner} was not written in a scene file"));
    };
    let text = file.text.as_str();
    let (open, close) = (
        block.body.start as usize,
        (block.body.end as usize).saturating_sub(1),
    );
    if text.as_bytes().get(close) != Some(&b'}') || open >= close {
        return Refused(format!(
            "cannot find the end of {owner}'s block at {}",
            scene.sources.location(block.header)
        ));
    }
    let line_start = text[..close].rfind('\n').map_or(0, |i| i + 1);
    let at = Span::new(block.body.file, close, close);
    if text[line_start..close].trim().is_empty() && line_start > open {
        // `}` on a line of its own: a new line above it.
        let indent = text[open + 1..close]
            .lines()
            .find(|l| !l.trim().is_empty())
            .map_or("    ".to_string(), |l| {
                l[..l.len() - l.trim_start().len()].to_string()
            });
        let at = Span::new(block.body.file, line_start, line_start);
        return insert(file, at, &format!("{indent}{property} {value_text}\n"));
    }
    let space = if text[..close].ends_with(' ') {
        ""
    } else {
        " "
    };
    insert(file, at, &format!("{space}{property} {value_text} "))
}

fn insert(file: &SourceFile, at: Span, text: &str) -> WriteBack {
    edit(file, at, text)
}

/// The file's text with `span` replaced by `new_text`.
fn edit(file: &SourceFile, span: Span, new_text: &str) -> WriteBack {
    let (start, end) = (span.start as usize, span.end as usize);
    let text = &file.text;
    let mut contents = String::with_capacity(text.len() + new_text.len());
    contents.push_str(&text[..start]);
    contents.push_str(new_text);
    contents.push_str(&text[end..]);
    let line = file.line_col(span.start).line;
    let line_start = contents[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = contents[start..]
        .find('\n')
        .map_or(contents.len(), |i| start + i);
    let new_line = contents[line_start..line_end].trim().to_string();
    WriteBack::Edit {
        path: file.path.clone(),
        original: Arc::clone(&file.text),
        contents,
        line,
        new_line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{material_named, whitted_scene, SCENE_TEXT};
    use crate::what_if::{value_text, Value};
    use whitted_ir::properties::IOR;
    use whitted_ir::setting_rows::{MAX_DEPTH, MIN_WEIGHT};
    use whitted_ir::Handle;

    /// The lines of `a` and `b` that differ, as (line number, a's, b's).
    fn changed_lines(a: &str, b: &str) -> Vec<(usize, String, String)> {
        assert_eq!(a.lines().count(), b.lines().count());
        a.lines()
            .zip(b.lines())
            .enumerate()
            .filter(|(_, (x, y))| x != y)
            .map(|(i, (x, y))| (i + 1, x.to_string(), y.to_string()))
            .collect()
    }

    fn edited(outcome: WriteBack) -> (String, u32, String) {
        match outcome {
            WriteBack::Edit {
                contents,
                line,
                new_line,
                ..
            } => (contents, line, new_line),
            WriteBack::Refused(why) => panic!("refused: {why}"),
        }
    }

    #[test]
    fn the_glass_ior_is_replaced_on_its_line_and_nothing_else_changes() {
        let scene = whitted_scene();
        let glass = material_named(&scene, "glass");
        let WriteBack::Edit {
            path,
            contents,
            line,
            new_line,
            original,
        } = write_back(&scene, Param::material_number(glass, &IOR), "1")
        else {
            panic!("an edit");
        };
        assert_eq!(path, "scenes/whitted.scene");
        assert_eq!(original.as_str(), SCENE_TEXT);
        assert_eq!(line, 15);
        assert_eq!(new_line, "reflective 0.1 transmissive 0.9 ior 1");
        assert_eq!(
            changed_lines(SCENE_TEXT, &contents),
            [(
                15,
                "    reflective 0.1 transmissive 0.9 ior 1.5".into(),
                "    reflective 0.1 transmissive 0.9 ior 1".into()
            )]
        );
    }

    #[test]
    fn settings_and_light_colours_are_replaced_whole_even_when_the_value_is_a_word() {
        let scene = whitted_scene();
        let (contents, line, _) = edited(write_back(&scene, Param::setting(&MAX_DEPTH), "9"));
        assert_eq!(line, 6);
        assert_eq!(
            changed_lines(SCENE_TEXT, &contents),
            [(6, "    max_depth 5".into(), "    max_depth 9".into())]
        );
        let red = value_text(Value::Color(whitted_ir::Color::new(1.0, 0.0, 0.0)));
        let (contents, _, _) = edited(write_back(
            &scene,
            Param::light_color(Handle::from_index(0)),
            &red,
        ));
        assert_eq!(
            changed_lines(SCENE_TEXT, &contents),
            [(
                10,
                r#"light point "sun" { position <-6, 10, -8> color white }"#.into(),
                r#"light point "sun" { position <-6, 10, -8> color rgb(1, 0, 0) }"#.into()
            )]
        );
    }

    /// A default is written into its block: on the block's line, or on a line of its own
    /// above the closing brace.
    #[test]
    fn a_default_property_is_added_to_its_block() {
        let scene = whitted_scene();
        let mirror = material_named(&scene, "mirror");
        let (contents, line, new_line) = edited(write_back(
            &scene,
            Param::material_number(mirror, &IOR),
            "1.3",
        ));
        assert_eq!(line, 17);
        assert_eq!(
            new_line,
            "material mirror { ambient 0.05 diffuse 0.1 specular 0.8 shininess 120 reflective 0.8 ior 1.3 }"
        );
        assert_eq!(contents.lines().count(), SCENE_TEXT.lines().count());

        let (contents, line, new_line) =
            edited(write_back(&scene, Param::setting(&MIN_WEIGHT), "0.01"));
        assert_eq!((line, new_line.as_str()), (8, "min_weight 0.01"));
        assert_eq!(
            contents.lines().nth(7),
            Some("    min_weight 0.01"),
            "indented like the block's first property, above its closing brace"
        );
        assert_eq!(contents.lines().count(), SCENE_TEXT.lines().count() + 1);
    }

    /// A setting that the command line set is refused (the flag would override the edit),
    /// as is a light made many times by one text.
    #[test]
    fn a_setting_from_the_command_line_or_a_loop_is_not_written() {
        let mut scene = whitted_scene().into_inner();
        let flag = scene
            .sources
            .add(SourceFile::new("<--set max_depth=7>", "max_depth=7"));
        let block = scene.written.add_block(whitted_ir::WrittenBlock {
            kind: BlockKind::Settings,
            header: Span::new(flag, 0, 11),
            body: Span::detached(),
        });
        scene.written.add_property(whitted_ir::WrittenProperty {
            block,
            name: "max_depth",
            name_span: Span::new(flag, 0, 9),
            value_span: Span::new(flag, 10, 11),
        });
        let WriteBack::Refused(why) = write_back(&scene, Param::setting(&MAX_DEPTH), "3") else {
            panic!("refused");
        };
        assert!(why.contains("(--set max_depth=7)"), "{why}");

        let (sun, light, span) = scene
            .lights
            .iter_with_spans()
            .next()
            .map(|(h, l, s)| (h, l.clone(), s))
            .expect("a light");
        scene.lights.append(light, span);
        let WriteBack::Refused(why) = write_back(&scene, Param::light_color(sun), "0.5") else {
            panic!("refused");
        };
        assert!(why.contains("made 2 times"), "{why}");
    }

    #[test]
    fn a_course_scene_is_never_written_with_scene_language_words() {
        let mut scene = whitted_scene().into_inner();
        let mut sources = whitted_ir::SourceMap::new();
        sources.add(SourceFile::new(
            "spheres.txt",
            "OrthographicCamera { center 0 0 10 }\nMaterials { numMaterials 1 }\n",
        ));
        scene.sources = sources;
        scene.format = SceneFormat::Mit6837;
        let glass = material_named(&scene, "glass");
        for param in [
            Param::material_number(glass, &IOR),
            Param::setting(&MAX_DEPTH),
        ] {
            let WriteBack::Refused(why) = write_back(&scene, param, "1") else {
                panic!("refused");
            };
            assert!(why.contains("spheres.txt is a MIT 6.837 scene"), "{why}");
        }
    }
}
