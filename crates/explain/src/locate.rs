//! Where a setting was written: the scene's table of written settings (filled by the front
//! end that read it, `--set` and the command line's flags included) gives the span of the one
//! that took effect; nothing here reads the scene's text.

use whitted_ir::{Scene, Span};

/// `file:line:col` of the setting `name` that took effect, if it was written anywhere.
pub fn setting_location(scene: &Scene, name: &str) -> Option<String> {
    setting_span(scene, name).map(|span| scene.sources.location(span))
}

/// The span of the name of the setting `name` that took effect, if it was written (the
/// linter's warnings underline it).
pub fn setting_span(scene: &Scene, name: &str) -> Option<Span> {
    scene.written.setting(name).map(|written| written.name_span)
}

/// Where a setting is, or else where it would go: the scene's `settings` block when it has
/// one, the start of the scene's first file otherwise (the default applies; the fix says
/// to add it there).
pub fn setting_or_scene(scene: &Scene, name: &str) -> (String, bool) {
    if let Some(location) = setting_location(scene, name) {
        return (location, true);
    }
    if let Some(block) = scene.written.settings_blocks().next() {
        return (scene.sources.location(block.header), false);
    }
    let file = scene
        .sources
        .files()
        .next()
        .map_or("<scene>".to_string(), |(_, f)| f.path.clone());
    (format!("{file}:1:1"), false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{BlockKind, SourceFile, WrittenBlock, WrittenProperty};

    fn settings_block(scene: &mut Scene, header: Span, body: Span) -> whitted_ir::BlockId {
        scene.written.add_block(WrittenBlock {
            kind: BlockKind::Settings,
            header,
            body,
        })
    }

    /// The table, not the text: a setting named in a comment or inside another name is not
    /// found, and the command line's setting (recorded last) is the one that took effect.
    #[test]
    fn finds_the_setting_that_took_effect_from_the_table() {
        let mut scene = Scene::default();
        let text = "/* max_depth 3 */\nsettings { my_max_depth 2 max_depth 4 }\n";
        let file = scene.sources.add(SourceFile::new("a.scene", text));
        let at = |word: &str, from: usize| {
            let start = from + text[from..].find(word).expect("in the text");
            Span::new(file, start, start + word.len())
        };
        let body_start = text.find('{').expect("a brace");
        let block = settings_block(
            &mut scene,
            at("settings", 0),
            Span::new(file, body_start, text.len() - 1),
        );
        assert_eq!(setting_location(&scene, "max_depth"), None);
        assert_eq!(
            setting_or_scene(&scene, "max_depth"),
            ("a.scene:2:1".to_string(), false)
        );
        scene.written.add_property(WrittenProperty {
            block,
            name: "max_depth",
            name_span: at("max_depth", text.rfind("max_depth").expect("written")),
            value_span: at("4", body_start),
        });
        assert_eq!(
            setting_location(&scene, "max_depth").as_deref(),
            Some("a.scene:2:27")
        );
        let flag = scene.sources.add(SourceFile::new("<--max-depth 9>", "9"));
        let flag_span = Span::new(flag, 0, 1);
        let block = settings_block(&mut scene, flag_span, Span::detached());
        scene.written.add_property(WrittenProperty {
            block,
            name: "max_depth",
            name_span: flag_span,
            value_span: flag_span,
        });
        assert_eq!(
            setting_location(&scene, "max_depth").as_deref(),
            Some("<--max-depth 9>:1:1")
        );
        assert_eq!(
            setting_or_scene(&Scene::default(), "min_weight"),
            ("<scene>:1:1".to_string(), false)
        );
    }
}
