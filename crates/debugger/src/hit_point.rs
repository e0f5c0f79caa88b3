//! Where the selected ray's hit point appears in the image: projected through the camera and
//! checked against what the camera actually sees at that pixel. For a blocked shadow ray the
//! point is where its blocker stopped it.

use whitted_ir::{DVec3, Handle};

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
            let object = Handle::from_index(object as usize);
            match sight(
                &app.loaded.prepared,
                &app.options,
                scene.camera.eye,
                (x, y),
                point,
                object,
            ) {
                Sight::Visible => HitPointView::Shown(x, y),
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
    fn the_far_side_of_the_glass_is_hidden_by_the_glass_itself_or_shown() {
        let mut app = picked();
        let tree = &mut app.picked.as_mut().unwrap().tree;
        // The transmitted ray inside the sphere hits the sphere's back: the camera sees the
        // front of the same sphere there, which counts as the same object.
        let inside = (0..tree.len())
            .find(|&id| tree.node(id).is_some_and(|n| n.kind == RayKind::Transmitted))
            .unwrap();
        tree.select(inside);
        let view = hit_point_view(&app).expect("the ray inside the glass hits its far side");
        assert!(matches!(view, HitPointView::Shown(..)), "{view:?}");
    }
}
