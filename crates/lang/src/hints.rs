//! Words people bring from elsewhere (POV-Ray above all) and the whitted way to say them: one
//! table that unknown-name, unknown-property, unknown-kind and syntax errors all consult, so a
//! foreign word gets the same advice wherever it turns up.

use crate::schema::Prop;

/// A foreign word and the advice for it. Syntax errors consult this table for every word on
/// the line, so words that are as likely to be a scene's own names (`text`, `right`,
/// `parallel`) are left out: their advice would mislead more often than help.
const FOREIGN: &[(&str, &str)] = &[
    (
        "color",
        "an object's colour comes from its material (`material { diffuse <1, 0, 0> }`); a colour is a vector of red, green and blue: `<0.9, 0.9, 0.9>`, `rgb(0.9, 0.9, 0.9)` or one number for a grey",
    ),
    (
        "colour",
        "an object's colour comes from its material (`material { diffuse <1, 0, 0> }`; a light's is its `color`, spelt so); a colour is a vector: `<0.9, 0.9, 0.9>`, `rgb(0.9, 0.9, 0.9)` or one number for a grey",
    ),
    (
        "rgb",
        "`rgb` is a function: write `rgb(0.9, 0.9, 0.9)`, with no space before the bracket, or `<0.9, 0.9, 0.9>`, or `0.9` alone for a grey",
    ),
    (
        "rgbf",
        "whitted has no filter channel: write the colour as `<r, g, b>` and the light that passes through as the material's `transmissive <r, g, b>`",
    ),
    (
        "rgbt",
        "whitted has no transmit channel: write the colour as `<r, g, b>` and the light that passes through as the material's `transmissive <r, g, b>`",
    ),
    (
        "filter",
        "light through a surface is the material's `transmissive` colour (with `ior` for refraction); whitted's `filter` is a setting, how samples make a pixel (`settings { filter tent }`)",
    ),
    (
        "transmit",
        "light through a surface is the material's `transmissive` colour (with `ior` for refraction)",
    ),
    (
        "phong",
        "the highlight's strength is the material's `specular`, its tightness `shininess` (POV-Ray's `phong_size`)",
    ),
    (
        "phong_size",
        "the highlight's tightness is the material's `shininess` (its strength is `specular`)",
    ),
    (
        "reflection",
        "mirror reflection is the material's `reflective` (a number or a colour)",
    ),
    (
        "refraction",
        "refraction is the material's `transmissive` (how much passes) and `ior`",
    ),
    (
        "pigment",
        "whitted has no pigment block: a material's colour is its `diffuse` (`material { diffuse <1, 0, 0> }`), or a pattern such as `diffuse checker(white, black, 1)`",
    ),
    (
        "finish",
        "whitted has no finish block: `ambient`, `diffuse`, `specular`, `shininess`, `reflective`, `transmissive` and `ior` all go in one `material { ... }`",
    ),
    (
        "texture",
        "whitted has no texture block: write `material { ... }` in the object (or `material name` for a named one)",
    ),
    (
        "interior",
        "whitted has no interior block: `ior` and `absorption` go in the material",
    ),
    (
        "location",
        "the camera's position is `eye` (POV-Ray's `location`)",
    ),
    (
        "angle",
        "the camera's field of view is `fov`, the vertical angle in degrees (POV-Ray's `angle` is horizontal)",
    ),
    (
        "sky",
        "the camera's up direction is `up`",
    ),
    (
        "light_source",
        "a light is `light point { position <0, 10, 0> color <1, 1, 1> }` (also `light directional` and `light spot`)",
    ),
    (
        "no_shadow",
        "whitted has no per-object `no_shadow`: every object casts shadows; `settings { shadows filtered }` lets transparent objects pass tinted light",
    ),
    (
        "mesh2",
        "whitted reads meshes from files: write the vertices and faces to an `.obj` file and use `mesh { file \"model.obj\" }`",
    ),
    ("merge", "whitted has no `merge`: use `union`"),
    (
        "object",
        "to reuse an object, write a function that makes it (`fn lamp(h) { sphere { ... } }`) and call it: `lamp(2) { translate <1, 0, 0> }`",
    ),
    (
        "global_settings",
        "scene-wide settings go in `settings { ... }` (`max_depth`, `ambient`, `background`, ...)",
    ),
    (
        "max_trace_level",
        "the recursion limit is `settings { max_depth 5 }`",
    ),
    (
        "background",
        "the background colour is a setting: `settings { background <0.1, 0.2, 0.6> }`",
    ),
    (
        "declare",
        "a name is defined with `let name = value;` (POV-Ray's `#declare`)",
    ),
    (
        "local",
        "a name is defined with `let name = value;`, local to its block (POV-Ray's `#local`)",
    ),
    (
        "include",
        "another scene file is read with `import \"file.scene\"`",
    ),
    (
        "macro",
        "functions are `fn name(a, b) { ... }` (POV-Ray's `#macro`)",
    ),
    // POV-Ray shapes whitted lacks, each with the nearest whitted construction.
    (
        "smooth_triangle",
        "a `triangle` is flat; for interpolated vertex normals, write the triangles with their normals to an `.obj` file and use `mesh { file \"model.obj\" }`",
    ),
    (
        "prism",
        "whitted has no prisms: a `difference` or `intersection` of `box`es, or `triangle`s in a `group`, makes one",
    ),
    (
        "height_field",
        "whitted has no height fields: write the surface as `triangle { vertices ... }` objects, in a `group`",
    ),
    (
        "lathe",
        "whitted has no surfaces of revolution: stack `cone`s and `cylinder`s in a `union`, or use a `quadric`",
    ),
    (
        "sor",
        "whitted has no surfaces of revolution: stack `cone`s and `cylinder`s in a `union`, or use a `quadric`",
    ),
    (
        "blob",
        "whitted has no blobs: overlapping `sphere`s in a `union` come nearest",
    ),
    (
        "superellipsoid",
        "whitted has no superellipsoids: the nearest shapes are `box`, `ellipsoid` and their `intersection`",
    ),
    (
        "isosurface",
        "whitted has no isosurfaces: an implicit surface of degree two is a `quadric { coefficients ... }`; a ring is a `torus`",
    ),
    // Object modifiers.
    (
        "clipped_by",
        "to cut an object by a shape, write `intersection { object shape }` (or `difference` to cut the shape away)",
    ),
    (
        "bounded_by",
        "whitted bounds every object itself (a bounding volume hierarchy): leave `bounded_by` out",
    ),
    (
        "hollow",
        "whitted has no media, so nothing is hollow or filled: leave `hollow` out",
    ),
    // Finish words.
    (
        "roughness",
        "the highlight's tightness is the material's `shininess`, a Phong exponent (about 1 / POV-Ray's `roughness`)",
    ),
    (
        "metallic",
        "for a metal's tinted highlight, give the material's `specular` the metal's colour (`specular <0.9, 0.7, 0.3>`)",
    ),
    (
        "brilliance",
        "whitted's diffuse shading is Lambert's, with no `brilliance`: leave it out",
    ),
    // Lights.
    (
        "area_light",
        "whitted's lights are `point`, `directional` and `spot`, with sharp shadows (Whitted's model): there are no area lights",
    ),
    (
        "spotlight",
        "a spot light is its own kind: `light spot { position <0, 5, 0> direction <0, -1, 0> inner 20 outer 30 }`",
    ),
    (
        "point_at",
        "a spot light aims along its `direction`, a vector: POV-Ray's `point_at` minus the light's `position`",
    ),
    (
        "falloff",
        "a spot light fades out at `outer`, in degrees from its axis like POV-Ray's `falloff` (POV-Ray's `radius` is `inner`)",
    ),
    (
        "fade_distance",
        "fall-off with distance is the light's `attenuation <constant, linear, quadratic>`",
    ),
    (
        "fade_power",
        "fall-off with distance is the light's `attenuation <constant, linear, quadratic>`",
    ),
    // Global illumination.
    (
        "radiosity",
        "whitted traces Whitted's model, without indirect diffuse light: `settings { ambient ... }` stands in for it",
    ),
    (
        "photons",
        "whitted traces Whitted's model, without caustics: light reaches a surface only straight from a light (through transparent objects with `settings { shadows filtered }`)",
    ),
];

/// The advice for `word`, if it is a word people bring from elsewhere.
pub(crate) fn foreign(word: &str) -> Option<&'static str> {
    FOREIGN
        .iter()
        .find(|(foreign, _)| *foreign == word)
        .map(|(_, hint)| *hint)
}

/// The advice for an unknown name (a value): `x`, `y` and `z` are not predefined axis
/// vectors here, and POV-Ray's colour words are not values. Other foreign words are
/// properties or blocks, whose advice would mislead where a value was expected.
pub(crate) fn unknown_name(word: &str) -> Option<String> {
    const VALUE_WORDS: [&str; 7] = [
        "color", "colour", "rgb", "rgbf", "rgbt", "filter", "transmit",
    ];
    let axis = match word {
        "x" => "<1, 0, 0>",
        "y" => "<0, 1, 0>",
        "z" => "<0, 0, 1>",
        _ if VALUE_WORDS.contains(&word) => return foreign(word).map(str::to_string),
        _ => return None,
    };
    Some(format!(
        "whitted has no predefined axis vectors: write `{axis}` for {word} (`let {word} = {axis};` defines one)"
    ))
}

/// Advice for a syntax error at byte `pos` of `text`, from what is around it: POV-Ray
/// directives (`#declare`), values without names (`sphere { <0, 0, 0>, 1 }`), and foreign
/// words on the line (those that are not also whitted properties somewhere).
pub(crate) fn syntax(text: &str, pos: usize) -> Vec<String> {
    let mut hints = Vec::new();
    let before = text.get(..pos).unwrap_or("");
    let next = text.get(pos..).unwrap_or("");
    if let Some(directive) = next.strip_prefix('#') {
        let word: String = directive
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let advice = match word.as_str() {
            "declare" | "local" => Some("a name is defined with `let name = value;`"),
            "include" => Some("another scene file is read with `import \"file.scene\"`"),
            "for" | "while" | "if" | "else" => {
                Some("loops and conditions are statements: `for i in 0..10 { ... }`, `while c { ... }`, `if c { ... } else { ... }`")
            }
            "macro" => Some("functions are `fn name(a, b) { ... }`"),
            "version" | "end" => Some("whitted has no directives: leave it out"),
            _ => None,
        };
        if let Some(advice) = advice {
            hints.push(format!("`#{word}` is POV-Ray's; in whitted, {advice}"));
        }
    }
    if let Some(kind) = positional_object(before, next) {
        hints.push(format!(
            "whitted names each value of an object, where POV-Ray lists them in order: `{}`",
            named_example(kind)
        ));
    }
    for (_, word, advice) in foreign_words_on_line(text, pos) {
        if advice.starts_with(&format!("`{word}`")) {
            hints.push(advice.to_string());
        } else {
            hints.push(format!("`{word}`: {advice}"));
        }
    }
    hints
}

/// Where the first foreign word on the line of a syntax error at byte `pos` is (a byte range
/// of `text`), so the error can point at the word its advice is about.
pub(crate) fn first_foreign_word(text: &str, pos: usize) -> Option<(usize, usize)> {
    let (start, word, _) = *foreign_words_on_line(text, pos).first()?;
    Some((start, start + word.len()))
}

/// The foreign words on the line holding byte `pos`, each once, with its byte offset in
/// `text` and its advice; directives (`#declare`) and whitted's own property names are left
/// out.
fn foreign_words_on_line(text: &str, pos: usize) -> Vec<(usize, &str, &'static str)> {
    let before = text.get(..pos).unwrap_or("");
    let next = text.get(pos..).unwrap_or("");
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_end = next.find('\n').map_or(text.len(), |i| pos + i);
    let line = text.get(line_start..line_end).unwrap_or("");
    let mut found: Vec<(usize, &str, &'static str)> = Vec::new();
    let mut rest = line;
    while let Some(start) = rest.find(|c: char| c.is_ascii_alphabetic() || c == '_') {
        let directive = rest[..start].ends_with('#');
        let tail = &rest[start..];
        let end = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(tail.len());
        let word = &tail[..end];
        let offset = line_start + (line.len() - tail.len());
        rest = &tail[end..];
        // Directives get their own advice; whitted's own property names are not foreign.
        if directive
            || found.iter().any(|(_, seen, _)| *seen == word)
            || Prop::ALL.iter().any(|p| p.name() == word)
        {
            continue;
        }
        if let Some(advice) = foreign(word) {
            found.push((offset, word, advice));
        }
    }
    found
}

/// The property name before a comma that ends `before`, with the comma's byte offset
/// (`center <0, 0, 0>, radius` gives `radius` and 17): a comma put between two properties,
/// as in a list.
pub(crate) fn comma_before_property(before: &str) -> Option<(&str, usize)> {
    let trimmed = before.trim_end();
    let word_start = last_word_start(trimmed);
    let word = &trimmed[word_start..];
    let is_property = Prop::ALL.iter().any(|p| p.name() == word);
    let head = trimmed[..word_start].trim_end();
    let comma = head.strip_suffix(',').map(str::len);
    comma.filter(|_| is_property).map(|at| (word, at))
}

/// The object kind when `before` ends with `kind {` and a bare value follows.
fn positional_object<'t>(before: &'t str, next: &str) -> Option<&'t str> {
    if !next.starts_with(|c: char| c == '<' || c == '-' || c.is_ascii_digit()) {
        return None;
    }
    let head = before.trim_end().strip_suffix('{')?.trim_end();
    let kind = &head[last_word_start(head)..];
    [
        "sphere", "box", "cylinder", "cone", "plane", "triangle", "disk",
    ]
    .contains(&kind)
    .then_some(kind)
}

/// Where the word that ends `text` starts (its length if `text` ends with no word); by
/// characters, so a wide character before the word cannot split a slice.
fn last_word_start(text: &str) -> usize {
    text.char_indices()
        .rev()
        .find(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |(i, c)| i + c.len_utf8())
}

fn named_example(kind: &str) -> &'static str {
    match kind {
        "sphere" => "sphere { center <0, 0, 0> radius 1 }",
        "box" => "box { min <-1, -1, -1> max <1, 1, 1> }",
        "cylinder" => "cylinder { base <0, 0, 0> apex <0, 1, 0> radius 0.5 }",
        "cone" => "cone { base <0, 0, 0> base_radius 1 apex <0, 1, 0> apex_radius 0 }",
        "plane" => "plane { normal <0, 1, 0> offset 0 }",
        "triangle" => "triangle { vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0> }",
        _ => "disk { center <0, 0, 0> normal <0, 1, 0> radius 1 }",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_comma_between_properties_is_found_only_before_a_property_name() {
        assert_eq!(
            comma_before_property("sphere { center <0,0,0>, radius"),
            Some(("radius", 23))
        );
        assert_eq!(
            comma_before_property("sphere { center <0,0,0> ,\n radius "),
            Some(("radius", 24))
        );
        assert_eq!(comma_before_property("vertices a, b"), None);
        assert_eq!(comma_before_property("sphere { radius"), None);
        assert_eq!(comma_before_property(""), None);
        // Found by the fast reader's generated texts: a byte-order mark before a word.
        assert_eq!(comma_before_property(" /**/ if\n[\u{feff}matrial"), None);
        assert_eq!(comma_before_property("a, \u{feff}radius"), None);
        assert_eq!(comma_before_property("a,\u{e9}radius"), None);
    }

    #[test]
    fn the_first_foreign_word_on_the_line_is_found_by_its_bytes() {
        let text = "let a = 1;\nsphere { radius 1 no_shadow }\n";
        let (start, end) = first_foreign_word(text, text.find('}').unwrap()).unwrap();
        assert_eq!(&text[start..end], "no_shadow");
        // Property names and words on other lines are not foreign words of this line.
        assert_eq!(first_foreign_word("mesh\ncolor 1 }", 13), None);
        let text = "material { diffuse rgb 1 }";
        let (start, end) = first_foreign_word(text, 23).unwrap();
        assert_eq!(&text[start..end], "rgb");
        assert_eq!(first_foreign_word("#declare R", 0), None);
    }

    #[test]
    fn positional_values_are_recognised_after_a_shape_and_its_brace() {
        assert_eq!(
            positional_object("sphere { ", "<0, 0, 0>, 1 }"),
            Some("sphere")
        );
        assert_eq!(positional_object("x = box {", "-1"), Some("box"));
        assert_eq!(positional_object("union { ", "<0"), None);
        assert_eq!(positional_object("sphere { radius ", "1"), None);
        assert_eq!(positional_object("\u{feff}{", "1"), None);
    }

    #[test]
    fn every_foreign_word_is_not_a_whitted_property() {
        // Advice for a word whitted itself uses would contradict the language.
        for (word, _) in FOREIGN {
            if *word == "color" || *word == "background" || *word == "filter" {
                // All are whitted properties in some blocks (a light's `color`, a setting);
                // their advice only appears where they are unknown or misused.
                continue;
            }
            assert!(
                !Prop::ALL.iter().any(|p| p.name() == *word),
                "`{word}` is a whitted property"
            );
        }
    }
}
