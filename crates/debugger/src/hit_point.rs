//! Where the selected ray's hit point appears in the image: projected through the camera and
//! checked against what the camera actually sees at that pixel. For a blocked shadow ray the
//! point is where its blocker stopped it.

use whitted_ir::{DVec3, Handle, Object};

use crate::app::App;
use crate::projection::{project, sight, Projected, Sight};

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum HitPointView {
    /// The camera sees the point at this pixel.
    Shown(u32, u32),
    OffScreen,
    BehindCamera,
    /// Something nearer covers the pixel the point projects to.
    HiddenBy(String),
}

impl HitPointView {
    pub fn describe(&self) -> String {
        match self {
            HitPointView::Shown(x, y) => format!("seen by the camera at ({x}, {y})"),
            HitPointView::OffScreen => "outside the picture".to_string(),
            HitPointView::BehindCamera => "behind the camera".to_string(),
            HitPointView::HiddenBy(label) => format!("hidden from the camera by {label}"),
        }
    }
}

/// The selected ray's hit point as the camera sees it; `None` when it hit nothing.
pub fn hit_point_view(app: &App) -> Option<HitPointView> {
    let node = app.picked.as_ref()?.tree.selected_node()?;
    let (point, object) = match (&node.hit, &node.shadow) {
        (Some(hit), _) => (hit.point, hit.object.handle),
        (None, Some(shadow)) => {
            let blocker = shadow.blocker.as_ref()?;
            let along = |i: usize| node.origin[i] + node.direction[i] * blocker.t;
            ([along(0), along(1), along(2)], blocker.object.handle)
        }
        (None, None) => return None,
    };
    let object = Handle::<Object>::from_index(object as usize);
    let point = DVec3::new(
        f64::from(point[0]),
        f64::from(point[1]),
        f64::from(point[2]),
    );
    let scene = &app.loaded.scene;
    let (width, height) = app.image_size();
    Some(match project(&scene.camera, width, height, point) {
        Projected::OffScreen => HitPointView::OffScreen,
        Projected::Behind => HitPointView::BehindCamera,
        Projected::Pixel(x, y) => {
            let seen = sight(
                &app.loaded.prepared,
                &app.options,
                scene.camera.eye,
                (x, y),
                point,
            );
            match seen {
                Sight::Visible => HitPointView::Shown(x, y),
                Sight::HiddenBy(blocker) if blocker == object => HitPointView::HiddenBy(format!(
                    "the near side of {}",
                    scene.object_label(blocker)
                )),
                Sight::HiddenBy(blocker) if scene.objects.contains(blocker) => {
                    HitPointView::HiddenBy(scene.object_label(blocker))
                }
                Sight::HiddenBy(_) => HitPointView::HiddenBy("another object".to_string()),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::LoadedScene;
    use crate::test_scene::{whitted_scene, GLASS_PIXEL};
    use ratatui::layout::Rect;
    use whitted_tracer::RayKind;

    fn picked() -> App {
        let mut app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        app.cursor = GLASS_PIXEL;
        app.trace_cursor();
        crate::test_scene::finish_trace(&mut app);
        app
    }

    #[test]
    fn the_camera_rays_hit_point_is_its_own_pixel() {
        let app = picked();
        assert_eq!(
            hit_point_view(&app),
            Some(HitPointView::Shown(GLASS_PIXEL.0, GLASS_PIXEL.1))
        );
    }

    #[test]
    fn the_far_side_of_the_glass_is_hidden_by_its_near_side() {
        let mut app = picked();
        let tree = &mut app.picked.as_mut().unwrap().tree;
        // The transmitted ray inside the sphere hits the sphere's back; the camera sees the
        // front of the same sphere at that pixel.
        let inside = (0..tree.len())
            .find(|&id| {
                tree.node(id)
                    .is_some_and(|n| n.kind == RayKind::Transmitted)
            })
            .unwrap();
        tree.select(inside);
        assert_eq!(
            hit_point_view(&app),
            Some(HitPointView::HiddenBy(
                "the near side of glass sphere".to_string()
            ))
        );
    }

    /// On the mirror sphere, some reflected rays hit things the camera also sees directly:
    /// their hit points are marked elsewhere in the picture.
    #[test]
    fn a_mirrored_hit_point_is_marked_where_the_camera_sees_it() {
        let mut app = picked();
        let mut found = None;
        'search: for y in (180..340).step_by(8) {
            for x in (150..330).step_by(8) {
                app.cursor = (x, y);
                app.trace_cursor();
                crate::test_scene::finish_trace(&mut app);
                let tree = &mut app.picked.as_mut().unwrap().tree;
                let root = tree.node(0).unwrap();
                let on_mirror = root
                    .hit
                    .as_ref()
                    .is_some_and(|h| h.object.label == "mirror sphere");
                let Some(reflected) = (0..tree.len())
                    .find(|&id| tree.node(id).is_some_and(|n| n.kind == RayKind::Reflected))
                else {
                    continue;
                };
                if !on_mirror {
                    continue;
                }
                tree.select(reflected);
                if let Some(HitPointView::Shown(hx, hy)) = hit_point_view(&app) {
                    found = Some(((x, y), (hx, hy)));
                    break 'search;
                }
            }
        }
        let (pixel, marked) = found.expect("a mirrored point the camera sees");
        assert_ne!(pixel, marked);
    }
}
