//! Where a setting was written: the IR keeps no span for settings, so the setting's name is
//! looked up as a word in the scene's sources (outside `//` comments). The last one wins,
//! as it does when the scene is compiled: `--set` pseudo-files come after the scene's own.

use whitted_ir::{Scene, Span};

/// `file:line:col` of the last place `name` is written in the scene's sources, if any.
pub fn setting_location(scene: &Scene, name: &str) -> Option<String> {
    setting_span(scene, name).map(|span| scene.sources.location(span))
}

/// The span of the last place `name` is written in the scene's sources, if any (the
/// linter's warnings underline it).
pub fn setting_span(scene: &Scene, name: &str) -> Option<Span> {
    let mut found = None;
    for (id, file) in scene.sources.files() {
        let mut line_start = 0;
        for line in file.text.split_inclusive('\n') {
            let this_line = line_start;
            line_start += line.len();
            let code = line.split("//").next().unwrap_or("");
            let mut from = 0;
            while let Some(at) = code[from..].find(name) {
                let start = from + at;
                let end = start + name.len();
                let word_char = |c: char| c.is_ascii_alphanumeric() || c == '_';
                let before = code[..start].chars().next_back().is_some_and(word_char);
                let after = code[end..].chars().next().is_some_and(word_char);
                if !before && !after {
                    found = Some(Span::new(id, this_line + start, this_line + end));
                }
                from = end;
            }
        }
    }
    found
}

/// Where a setting is, or else where it would go: the scene's `settings` block when it has
/// one, the start of the scene's first file otherwise (the default applies; the fix says
/// to add it there).
pub fn setting_or_scene(scene: &Scene, name: &str) -> (String, bool) {
    match setting_location(scene, name) {
        Some(location) => (location, true),
        None if setting_location(scene, "settings").is_some() => (
            setting_location(scene, "settings").unwrap_or_default(),
            false,
        ),
        None => {
            let file = scene
                .sources
                .files()
                .next()
                .map_or("<scene>".to_string(), |(_, f)| f.path.clone());
            (format!("{file}:1:1"), false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::SourceFile;

    #[test]
    fn finds_the_last_whole_word_outside_comments() {
        let mut scene = Scene::default();
        scene.sources.add(SourceFile::new(
            "a.scene",
            "// max_depth 3 in a comment\nsettings { my_max_depth 2 max_depth 4 }\n",
        ));
        scene
            .sources
            .add(SourceFile::new("--set max_depth", "max_depth=9"));
        assert_eq!(
            setting_location(&scene, "max_depth").as_deref(),
            Some("--set max_depth:1:1")
        );
        let mut only_scene = Scene::default();
        only_scene.sources.add(SourceFile::new(
            "a.scene",
            "// max_depth 3\nsettings { my_max_depth 2 max_depth 4 }\n",
        ));
        assert_eq!(
            setting_location(&only_scene, "max_depth").as_deref(),
            Some("a.scene:2:27")
        );
        assert_eq!(setting_location(&only_scene, "min_weight"), None);
        assert_eq!(
            setting_or_scene(&only_scene, "min_weight"),
            ("a.scene:2:1".to_string(), false)
        );
    }
}
