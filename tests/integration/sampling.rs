//! `sampling grid` against another representation of the same image: a 2 x 2 grid of samples
//! per pixel is a render at twice the size, one sample per pixel at each cell's centre,
//! averaged in blocks of four. The rays are the same bit for bit (the grid's positions and
//! the larger image's pixel centres differ by a factor of 2, which is exact); only the order
//! of the four-term sums may differ.

use whitted_ir::Sampling;
use whitted_tracer::{render, NoObserver, PreparedScene, RenderOptions};

use crate::ray_trees::load;

#[test]
fn a_two_by_two_grid_is_the_double_size_render_averaged() {
    for path in [
        "scenes/whitted.scene",
        "scenes/glass.scene",
        "scenes/marble.scene",
    ] {
        let loaded = load(path);
        let mut scene = loaded.scene.into_inner();
        scene.settings.sampling = Sampling::Grid;
        scene.settings.samples_per_pixel = 4;
        let scene = whitted_ir::validate(scene).expect("valid");
        let prepared = PreparedScene::new(&scene);
        let (width, height) = (48, 36);
        let mut options = RenderOptions::from_settings(&scene.settings);
        (options.width, options.height) = (width, height);
        let (grid, _) = render(&prepared, &options, &NoObserver).expect("rendered");
        let mut single = options.clone();
        (single.width, single.height, single.samples_per_pixel) = (2 * width, 2 * height, 1);
        let (large, _) = render(&prepared, &single, &NoObserver).expect("rendered");
        let mut worst = 0.0f32;
        for y in 0..height {
            for x in 0..width {
                let mut mean = [0.0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let p = large.pixel(2 * x + dx, 2 * y + dy).expect("inside");
                    for c in 0..3 {
                        mean[c] += p[c] / 4.0;
                    }
                }
                let p = grid.pixel(x, y).expect("inside");
                for c in 0..3 {
                    worst = worst.max((p[c] - mean[c]).abs() / mean[c].abs().max(1.0));
                }
            }
        }
        assert!(
            worst < 1e-5,
            "{path}: a grid pixel differs by {worst} from its four"
        );

        // Jittered samples are not at those centres: the oracle can tell them apart.
        let jittered_scene = {
            let mut s = scene.scene().clone();
            s.settings.sampling = Sampling::Jittered;
            whitted_ir::validate(s).expect("valid")
        };
        let (jittered, _) =
            render(&PreparedScene::new(&jittered_scene), &options, &NoObserver).expect("rendered");
        assert_ne!(jittered.pixels, grid.pixels, "{path}");
    }
}
