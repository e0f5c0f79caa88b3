//! Writing a what-if change back into the scene text (`W` in the what-if popup): find the
//! property in the block of the material, light or settings that holds it (by the IR's
//! spans into the source map), and replace its value's text and nothing else. When the
//! property is not written (a default), or the text cannot be changed safely (a definition
//! made many times by a loop or a function, a value set on the command line), say what to
//! do instead of guessing. The file itself is written by the event loop.

use std::ops::Range;
use std::sync::Arc;

use whitted_ir::{Scene, SourceFile, Span};

use crate::what_if::Param;

/// What writing a change back comes to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WriteBack {
    /// Replace the file at `path` (whose text was `original` when compiled) by `contents`,
    /// which differs from it on line `line` only.
    Edit {
        path: String,
        original: Arc<String>,
        contents: String,
        line: u32,
        new_line: String,
    },
    /// The property is not written: `line_to_add` should go `place`.
    Add { line_to_add: String, place: String },
    /// It cannot be written back safely: why.
    Refused(String),
}

/// Where `param` becomes `value_text` in the scene's files.
pub fn write_back(scene: &Scene, param: Param, value_text: &str) -> WriteBack {
    let property = param.property();
    let owner = param.owner(scene);
    let block = match param {
        Param::MaxDepth | Param::MinWeight | Param::Epsilon => {
            return settings_write_back(scene, property, value_text)
        }
        Param::Ior(h) | Param::Reflective(h) | Param::Transmissive(h) => {
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
            span
        }
        Param::LightColor(h) => scene.lights.span(h),
    };
    let Some(file) = writable_file(scene, block) else {
        return Refused(format!("{owner} was not written in a scene file"));
    };
    if is_course_scene(file) {
        return Refused(course_scene(file));
    }
    let Some(body) = block_body(&file.text, block.start as usize) else {
        return Refused(format!(
            "cannot find the block of {owner} at {}",
            scene.sources.location(block)
        ));
    };
    let found = properties_in(&file.text, body.clone(), property);
    match found.as_slice() {
        [] => Add {
            line_to_add: format!("{property} {value_text}"),
            place: format!(
                "inside {owner} at {}",
                scene.sources.location(Span::new(
                    block.file,
                    block.start as usize,
                    block.start as usize
                ))
            ),
        },
        [value] => edit(file, value.clone(), value_text),
        _ => Refused(format!(
            "{owner} writes {property} {} times: change it by hand",
            found.len()
        )),
    }
}

use WriteBack::{Add, Refused};

/// The settings blocks of every file: the property in exactly one of them is replaced.
fn settings_write_back(scene: &Scene, property: &str, value_text: &str) -> WriteBack {
    let mut blocks = Vec::new();
    for (id, file) in scene.sources.files() {
        if file.path.starts_with("<--set") && set_on_command_line(file, property) {
            return Refused(format!(
                "{property} is set on the command line ({}), which overrides the scene file",
                file.path.trim_start_matches('<').trim_end_matches('>')
            ));
        }
        if file.path.starts_with('<') {
            continue;
        }
        if is_course_scene(file) {
            return Refused(course_scene(file));
        }
        for at in words_at_top_level(&file.text, "settings") {
            if let Some(body) = block_body(&file.text, at) {
                blocks.push((id, at, body));
            }
        }
    }
    let mut found = Vec::new();
    for (id, _, body) in &blocks {
        for value in properties_in(
            scene.sources.get(*id).map_or("", |f| f.text.as_str()),
            body.clone(),
            property,
        ) {
            found.push((*id, value));
        }
    }
    match found.as_slice() {
        [(id, value)] => match scene.sources.get(*id) {
            Some(file) => edit(file, value.clone(), value_text),
            None => Refused("the settings block's file is gone".into()),
        },
        [] => match blocks.first() {
            Some((id, at, _)) => Add {
                line_to_add: format!("{property} {value_text}"),
                place: format!(
                    "inside settings at {}",
                    scene.sources.location(Span::new(*id, *at, *at))
                ),
            },
            None => {
                let root = scene
                    .sources
                    .files()
                    .map(|(_, f)| f.path.clone())
                    .find(|p| !p.starts_with('<'))
                    .unwrap_or_else(|| "the scene file".into());
                Add {
                    line_to_add: format!("settings {{ {property} {value_text} }}"),
                    place: format!("at the top level of {root}"),
                }
            }
        },
        _ => Refused(format!(
            "{property} is written {} times in settings blocks: change it by hand",
            found.len()
        )),
    }
}

/// Whether the file is a MIT 6.837 scene, which this edit cannot write: the scene language's
/// keywords are lower case, and a 6.837 file starts with a capitalised one (`Group`, ...).
fn is_course_scene(file: &SourceFile) -> bool {
    file.text
        .trim_start()
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_uppercase())
}

fn course_scene(file: &SourceFile) -> String {
    format!(
        "{} is a MIT 6.837 scene: only scene-language files are written back; change it by hand",
        file.path
    )
}

fn set_on_command_line(file: &SourceFile, property: &str) -> bool {
    file.text.split('=').next().map(str::trim) == Some(property)
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

/// The file's text with the value at `value` replaced.
fn edit(file: &SourceFile, value: Range<usize>, value_text: &str) -> WriteBack {
    let text = &file.text;
    let mut contents = String::with_capacity(text.len() + value_text.len());
    contents.push_str(&text[..value.start]);
    contents.push_str(value_text);
    contents.push_str(&text[value.end..]);
    let line = file.line_col(value.start as u32).line;
    let line_start = contents[..value.start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = contents[value.start..]
        .find('\n')
        .map_or(contents.len(), |i| value.start + i);
    let new_line = contents[line_start..line_end].trim().to_string();
    WriteBack::Edit {
        path: file.path.clone(),
        original: Arc::clone(&file.text),
        contents,
        line,
        new_line,
    }
}

/// What the scanner sees at a byte: code, or inside a comment or a string.
fn code_bytes(text: &str) -> Vec<bool> {
    let bytes = text.as_bytes();
    let mut code = vec![true; bytes.len()];
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        let end = match (bytes[i], bytes.get(i + 1)) {
            (b'/', Some(b'/')) => memchr_from(bytes, b'\n', i).unwrap_or(bytes.len()),
            (b'/', Some(b'*')) => text[i + 2..]
                .find("*/")
                .map_or(bytes.len(), |e| i + 2 + e + 2),
            (b'"', _) => {
                let mut j = i + 1;
                while j < bytes.len() && bytes[j] != b'"' {
                    j += if bytes[j] == b'\\' { 2 } else { 1 };
                }
                (j + 1).min(bytes.len())
            }
            _ => {
                i += 1;
                continue;
            }
        };
        code[start..end].iter_mut().for_each(|c| *c = false);
        i = end.max(start + 1);
    }
    code
}

fn memchr_from(bytes: &[u8], needle: u8, from: usize) -> Option<usize> {
    bytes[from..]
        .iter()
        .position(|&b| b == needle)
        .map(|i| from + i)
}

fn is_word(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The inside of the `{ ... }` block that opens at or after `from`.
fn block_body(text: &str, from: usize) -> Option<Range<usize>> {
    let code = code_bytes(text);
    let bytes = text.as_bytes();
    let open = (from..bytes.len()).find(|&i| code[i] && bytes[i] == b'{')?;
    let mut depth = 0usize;
    for i in open..bytes.len() {
        if !code[i] {
            continue;
        }
        match bytes[i] {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + 1..i);
                }
            }
            _ => {}
        }
    }
    None
}

/// Where `word` occurs as a whole word in code at bracket depth 0 of the file.
fn words_at_top_level(text: &str, word: &str) -> Vec<usize> {
    let code = code_bytes(text);
    let bytes = text.as_bytes();
    let mut depth = 0i64;
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if code[i] {
            match bytes[i] {
                b'{' | b'(' | b'[' => depth += 1,
                b'}' | b')' | b']' => depth -= 1,
                _ if depth == 0 && is_whole_word(bytes, &code, i, word) => {
                    found.push(i);
                    i += word.len();
                    continue;
                }
                _ => {}
            }
        }
        i += 1;
    }
    found
}

fn is_whole_word(bytes: &[u8], code: &[bool], at: usize, word: &str) -> bool {
    let end = at + word.len();
    bytes.get(at..end) == Some(word.as_bytes())
        && code[at..end].iter().all(|&c| c)
        && (at == 0 || !is_word(bytes[at - 1]))
        && bytes.get(end).is_none_or(|&b| !is_word(b))
}

/// The value ranges of every `property VALUE` at the top level of the block `body`.
fn properties_in(text: &str, body: Range<usize>, property: &str) -> Vec<Range<usize>> {
    let code = code_bytes(text);
    let bytes = text.as_bytes();
    let mut depth = 0i64;
    let mut found = Vec::new();
    let mut i = body.start;
    while i < body.end {
        if code[i] {
            match bytes[i] {
                b'{' | b'(' | b'[' | b'<' => depth += 1,
                b'}' | b')' | b']' | b'>' => depth -= 1,
                _ if depth == 0 && is_whole_word(bytes, &code, i, property) => {
                    let after = i + property.len();
                    if let Some(value) = value_extent(text, &code, after, body.end) {
                        found.push(value.clone());
                        i = value.end;
                        continue;
                    }
                }
                _ => {}
            }
        }
        i += 1;
    }
    found
}

/// The extent of the expression that starts after `from` (past spaces): operands (numbers,
/// names, calls, bracketed groups) joined by arithmetic operators. It ends where an operand
/// is not followed by an operator: the next property, a comment or the block's end.
fn value_extent(text: &str, code: &[bool], from: usize, end: usize) -> Option<Range<usize>> {
    let bytes = text.as_bytes();
    let skip_space = |mut i: usize| {
        while i < end && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        i
    };
    let start = skip_space(from);
    let mut i = start;
    loop {
        i = skip_space(i);
        // Signs and `not` before an operand.
        while i < end && matches!(bytes[i], b'-' | b'+' | b'!') {
            i = skip_space(i + 1);
        }
        i = operand_end(bytes, code, i, end)?;
        let next = skip_space(i);
        let is_operator = next < end
            && code[next]
            && matches!(bytes[next], b'+' | b'-' | b'*' | b'/' | b'%' | b'^')
            && !(bytes[next] == b'/' && matches!(bytes.get(next + 1), Some(b'/' | b'*')));
        if !is_operator {
            return (i > start).then_some(start..i);
        }
        i = next + 1;
    }
}

/// The end of the operand at `i`: a number, a name (possibly called or indexed), or a
/// bracketed group.
fn operand_end(bytes: &[u8], code: &[bool], i: usize, end: usize) -> Option<usize> {
    if i >= end || !code[i] {
        return None;
    }
    let mut j = i;
    if bytes[j].is_ascii_digit() || bytes[j] == b'.' {
        while j < end
            && (bytes[j].is_ascii_alphanumeric()
                || bytes[j] == b'.'
                || (matches!(bytes[j], b'-' | b'+') && matches!(bytes[j - 1], b'e' | b'E')))
        {
            j += 1;
        }
        return Some(j);
    }
    if is_word(bytes[j]) {
        while j < end && is_word(bytes[j]) {
            j += 1;
        }
    } else if !matches!(bytes[j], b'(' | b'<' | b'[') {
        return None;
    }
    // Calls, indexing, vectors and groups: to the matching close.
    while j < end && matches!(bytes[j], b'(' | b'[' | b'<') {
        let mut depth = 0i64;
        loop {
            if j >= end {
                return None;
            }
            if code[j] {
                match bytes[j] {
                    b'(' | b'[' | b'<' => depth += 1,
                    b')' | b']' | b'>' => depth -= 1,
                    _ => {}
                }
            }
            j += 1;
            if depth == 0 {
                break;
            }
        }
    }
    Some(j)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{material_named, whitted_scene, SCENE_TEXT};
    use crate::what_if::{value_text, Param, Value};
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
        } = write_back(&scene, Param::Ior(glass), "1")
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
        let WriteBack::Edit { contents, line, .. } = write_back(&scene, Param::MaxDepth, "9")
        else {
            panic!("an edit");
        };
        assert_eq!(line, 6);
        assert_eq!(
            changed_lines(SCENE_TEXT, &contents),
            [(6, "    max_depth 5".into(), "    max_depth 9".into())]
        );
        let red = value_text(Value::Color(whitted_ir::Color::new(1.0, 0.0, 0.0)));
        let WriteBack::Edit { contents, .. } =
            write_back(&scene, Param::LightColor(Handle::from_index(0)), &red)
        else {
            panic!("an edit");
        };
        assert_eq!(
            changed_lines(SCENE_TEXT, &contents),
            [(
                10,
                r#"light point "sun" { position <-6, 10, -8> color white }"#.into(),
                r#"light point "sun" { position <-6, 10, -8> color rgb(1, 0, 0) }"#.into()
            )]
        );
    }

    #[test]
    fn a_default_property_yields_the_line_to_add_and_where() {
        let scene = whitted_scene();
        let mirror = material_named(&scene, "mirror");
        assert_eq!(
            write_back(&scene, Param::Ior(mirror), "1.3"),
            WriteBack::Add {
                line_to_add: "ior 1.3".into(),
                place: "inside material mirror at scenes/whitted.scene:17:1".into()
            }
        );
        assert_eq!(
            write_back(&scene, Param::MinWeight, "0.01"),
            WriteBack::Add {
                line_to_add: "min_weight 0.01".into(),
                place: "inside settings at scenes/whitted.scene:4:1".into()
            }
        );
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
        let glass = material_named(&scene, "glass");
        for param in [Param::Ior(glass), Param::MaxDepth] {
            let WriteBack::Refused(why) = write_back(&scene, param, "1") else {
                panic!("refused");
            };
            assert!(why.contains("spheres.txt is a MIT 6.837 scene"), "{why}");
        }
    }

    #[test]
    fn value_extents_cover_expressions_and_stop_at_the_next_property_or_comment() {
        let text = "m { ior 1.5 * k + f(2, 3) // note\n reflective rgb(0.1, 0.2, 0.3) kt -0.5e-3 }";
        let body = block_body(text, 0).unwrap();
        let value = |p: &str| {
            properties_in(text, body.clone(), p)
                .into_iter()
                .map(|r| &text[r])
                .collect::<Vec<_>>()
        };
        assert_eq!(value("ior"), ["1.5 * k + f(2, 3)"]);
        assert_eq!(value("reflective"), ["rgb(0.1, 0.2, 0.3)"]);
        assert_eq!(value("kt"), ["-0.5e-3"]);
        assert_eq!(value("note"), Vec::<&str>::new(), "comments are not code");
    }

    #[test]
    fn a_settings_block_in_a_comment_or_nested_block_is_not_the_settings() {
        let text = "// settings { max_depth 1 }\nsettings { max_depth 2 }\n";
        let at = words_at_top_level(text, "settings");
        assert_eq!(at, [28]);
        let body = block_body(text, at[0]).unwrap();
        let found = properties_in(text, body, "max_depth");
        assert_eq!(
            found.iter().map(|r| &text[r.clone()]).collect::<Vec<_>>(),
            ["2"]
        );
    }
}
