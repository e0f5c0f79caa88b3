//! The scene shows nothing, or nothing lit: no objects, no lights, or no camera ray meets
//! anything (every object behind or beside the camera). The render still runs, and its
//! image is the background (or black surfaces); a user deserves a word before staring at it.

use whitted_ir::{Diagnostic, Scene};

use super::sampled::Samples;
use super::{Lint, LintKind};

pub(super) fn nothing_to_see(scene: &Scene, samples: &Samples, lints: &mut Vec<Lint>) {
    let camera = scene.camera_span;
    let emits = scene
        .materials
        .iter()
        .any(|(_, m)| m.emission.components().into_iter().any(|c| c > 0.0));
    if scene.roots.is_empty() {
        // No camera, light or object written: a library that scenes import (materials,
        // functions: scenes/lang-materials.scene), not a scene to render.
        if scene.lights.is_empty() && camera.is_detached() {
            return;
        }
        lints.push(Lint::new(
            LintKind::NothingToSee,
            Diagnostic::warning(
                "the scene has no objects: the image is the background colour alone",
                camera,
            )
            .with_label("this camera sees only the background")
            .with_hint(
                "add an object in front of the camera, for example `sphere { }` at the origin",
            ),
        ));
        return;
    }
    if scene.lights.is_empty() && !emits {
        lints.push(Lint::new(
            LintKind::NothingToSee,
            Diagnostic::warning(
                "the scene has no lights: surfaces show only their ambient colour",
                camera,
            )
            .with_hint("add a light, for example `light point { position <0, 10, -10> }`"),
        ));
    }
    if samples.hits.is_empty() && samples.met.iter().all(|m| !m) {
        lints.push(Lint::new(
            LintKind::NothingToSee,
            Diagnostic::warning(
                "no camera ray meets an object: every object is behind the camera, beside \
                 its view or too small to see, so the image is the background",
                camera,
            )
            .with_label("looks at nothing")
            .with_hint(
                "point `look_at` at the objects, or move `eye` back so that they are in view",
            ),
        ));
    }
}
