//! The reconstruction filters (the `filter` setting) against weighted means worked out here
//! from the filters' definitions: a flat-coloured corner whose edges fall on known pixel
//! lines, sampled on the course's uniform grid, so every sample's colour is known without
//! the tracer; and the default box, which keeps the renderer's plain per-pixel mean.

use whitted_ir::{Camera, Color, DMat4, DVec3, Filter, Material, Projection, Sampling, Shape};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::testing::SceneBuilder;
use whitted_tracer::{
    render, render_film, render_with_pixel_stats, NoObserver, PixelAccumulator, PreparedScene,
    RenderObserver, RenderOptions, TileResult,
};

const SIZE: u32 = 8;
const INSIDE: [f32; 3] = [1.0, 0.5, 0.25];
const OUTSIDE: [f32; 3] = [0.0, 0.0, 1.0];

/// An 8x8 image, one world unit per pixel: a self-lit box covers the top-left quadrant
/// (image x < 4 and y < 4) in `INSIDE`, the rest is the `OUTSIDE` background. No lights,
/// no ambient: every sample is exactly one of the two colours.
fn corner(filter: Filter, radius: f64, samples: u32) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    let s = b.settings();
    s.width = SIZE;
    s.height = SIZE;
    s.samples_per_pixel = samples;
    s.sampling = Sampling::Grid;
    s.filter = filter;
    s.filter_radius = radius;
    s.ambient = Color::BLACK;
    s.background = Color::new(0.0, 0.0, 1.0);
    b.set_camera(Camera {
        eye: DVec3::new(0.0, 0.0, 5.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: Projection::Orthographic {
            view_height: f64::from(SIZE),
        },
    });
    let glow = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        emission: Color::new(1.0, 0.5, 0.25),
        ..Material::default()
    });
    b.add(
        Shape::Box {
            min: DVec3::new(-100.0, 0.0, -1.0),
            max: DVec3::new(0.0, 100.0, 0.0),
        },
        DMat4::IDENTITY,
        glow,
    );
    b
}

fn prepare(builder: SceneBuilder) -> (PreparedScene, RenderOptions) {
    let scene = builder.build().expect("a valid test scene");
    let options = RenderOptions::from_settings(&scene.settings);
    (PreparedScene::new(&scene), options)
}

/// The oracle: sample `k` of a 2 x 2 grid in pixel (px, py) sits at (px + 0.25 or 0.75,
/// py + 0.25 or 0.75) and is `INSIDE` left of x = 4 and above y = 4; the pixel is the
/// weighted mean, over every pixel of the image, of `weight(dx, dy)` from its centre.
fn expected(x: u32, y: u32, weight: impl Fn(f64, f64) -> f64) -> [f32; 3] {
    let (mut sum, mut total) = ([0.0f64; 3], 0.0f64);
    for py in 0..SIZE {
        for px in 0..SIZE {
            for (ox, oy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                let (sx, sy) = (f64::from(px) + ox, f64::from(py) + oy);
                let color = if sx < 4.0 && sy < 4.0 {
                    INSIDE
                } else {
                    OUTSIDE
                };
                let w = weight(sx - (f64::from(x) + 0.5), sy - (f64::from(y) + 0.5));
                for c in 0..3 {
                    sum[c] += w * f64::from(color[c]);
                }
                total += w;
            }
        }
    }
    sum.map(|s| (s / total) as f32)
}

fn assert_close(got: [f32; 3], want: [f32; 3], what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() < 1e-5,
            "{what}: got {got:?}, want {want:?}"
        );
    }
}

#[test]
fn each_filter_is_the_weighted_mean_of_the_samples_around_the_pixel() {
    type Weight = Box<dyn Fn(f64, f64) -> f64>;
    let cases: [(Filter, f64, Weight); 4] = [
        (
            Filter::Box,
            1.0,
            Box::new(|dx: f64, dy: f64| {
                f64::from(u8::from(
                    (-1.0..1.0).contains(&dx) && (-1.0..1.0).contains(&dy),
                ))
            }),
        ),
        (
            Filter::Tent,
            1.5,
            Box::new(|dx: f64, dy: f64| (1.0 - dx.hypot(dy) / 1.5).max(0.0)),
        ),
        (
            Filter::Gaussian,
            0.5,
            Box::new(|dx: f64, dy: f64| {
                let d2 = dx * dx + dy * dy;
                if d2 < 1.0 {
                    (-d2 / 0.5).exp()
                } else {
                    0.0
                }
            }),
        ),
        (
            Filter::Gaussian,
            1.0,
            Box::new(|dx: f64, dy: f64| {
                let d2 = dx * dx + dy * dy;
                if d2 < 4.0 {
                    (-d2 / 2.0).exp()
                } else {
                    0.0
                }
            }),
        ),
    ];
    for (filter, radius, weight) in cases {
        let (prepared, options) = prepare(corner(filter, radius, 4));
        let (image, _) = render(&prepared, &options, &NoObserver).expect("not cancelled");
        for (x, y) in [(3, 3), (4, 3), (3, 1), (4, 4), (0, 0), (7, 7), (3, 6)] {
            let got = image.pixel(x, y).expect("in the image");
            let want = expected(x, y, &weight);
            assert_close(got, want, &format!("{filter:?} {radius} at ({x}, {y})"));
        }
        // The edge is blurred: the pixel just left of it is no longer pure `INSIDE`, and
        // far from the edge it is.
        assert_ne!(image.pixel(3, 2), Some(INSIDE), "{filter:?}");
        assert_eq!(image.pixel(0, 0), Some(INSIDE), "{filter:?}");
    }
}

/// The tent by hand at the pixel left of the vertical edge, (3, 1), radius 1: its own four
/// samples (d = 0.35, weight 0.65) and the nearer two samples of each of its four side
/// neighbours (d = 0.79, weight 0.21); the diagonal neighbours' samples are past 1.
#[test]
fn the_tent_across_the_edge_worked_by_hand() {
    let (prepared, options) = prepare(corner(Filter::Tent, 1.0, 4));
    let (image, _) = render(&prepared, &options, &NoObserver).expect("not cancelled");
    let near = 1.0 - (0.25f64.hypot(0.25)); // own samples: d = 0.354
    let side = 1.0 - (0.75f64.hypot(0.25)); // right neighbour's left column, above/below
                                            // Own 4 samples INSIDE; right neighbour (4, 1): 2 OUTSIDE; left (2, 1), above (3, 0)
                                            // and below (3, 2): 2 each INSIDE.
    let (w_in, w_out) = (4.0 * near + 6.0 * side, 2.0 * side);
    let want = [0, 1, 2].map(|c| {
        ((w_in * f64::from(INSIDE[c]) + w_out * f64::from(OUTSIDE[c])) / (w_in + w_out)) as f32
    });
    assert_close(
        image.pixel(3, 1).expect("in the image"),
        want,
        "tent 1 at (3, 1)",
    );
}

/// The default box (radius 0.5) keeps no film and makes each pixel the plain mean of its
/// own samples, as the renderer always has; the same box through the film's filtering
/// pass gives the same bits.
#[test]
fn the_default_box_is_each_pixel_s_own_mean_bit_for_bit() {
    let (prepared, options) = prepare(corner(Filter::Box, 0.5, 4));
    let (image, _) = render(&prepared, &options, &NoObserver).expect("not cancelled");
    let (film, film_image, _) = render_film(&prepared, &options, &NoObserver).expect("rendered");
    assert_eq!(film_image, image);
    let filter = whitted_tracer::PixelFilter {
        filter: Filter::Box,
        radius: 0.5,
    };
    for y in 0..SIZE {
        for x in 0..SIZE {
            let mut own = PixelAccumulator::new();
            for k in 0..4 {
                own.add(film.color(x, y, k));
            }
            assert_eq!(image.pixel(x, y), Some(own.mean()));
            assert_eq!(image.pixel(x, y), Some(film.filter_pixel(&filter, x, y)));
        }
    }
    assert_eq!(film.offset(2, 5, 3), (0.75, 0.75));
}

/// A filtered render is the same on any thread count, `render_film` gives the same image,
/// and a ray tree's colour is the filtered pixel bit for bit.
#[test]
fn filtered_renders_are_deterministic_and_ray_trees_agree() {
    let builder = corner(Filter::Gaussian, 0.7, 5);
    let scene = builder.build().expect("valid");
    let options = RenderOptions::from_settings(&scene.settings);
    let prepared = PreparedScene::new(&scene);
    let in_pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| render(&prepared, &options, &NoObserver).expect("rendered"))
            .0
    };
    let one = in_pool(1);
    assert_eq!(one, in_pool(3));
    let (_, film_image, _) = render_film(&prepared, &options, &NoObserver).expect("rendered");
    assert_eq!(film_image, one);
    let (stats_image, _, _) =
        render_with_pixel_stats(&prepared, &options, &NoObserver).expect("rendered");
    assert_eq!(stats_image, one);
    for (x, y) in [(3, 3), (4, 4), (0, 7)] {
        let tree =
            trace_pixel(&prepared, &scene, &options, x, y, SampleChoice::All).expect("in range");
        assert_eq!(Some(tree.color), one.pixel(x, y), "({x}, {y})");
        assert_eq!(
            tree.samples.len(),
            5,
            "the tree holds the pixel's own samples"
        );
    }
}

/// The observer sees the tiles (previews of each pixel's own samples) and then the
/// filtered image once.
#[test]
fn the_observer_gets_the_filtered_image_after_the_tiles() {
    #[derive(Default)]
    struct Watch(std::sync::Mutex<Vec<String>>);
    impl RenderObserver for Watch {
        fn tile_done(&self, _tile: &TileResult) {
            self.0.lock().unwrap().push("tile".into());
        }
        fn image_filtered(&self, image: &TileResult) {
            self.0
                .lock()
                .unwrap()
                .push(format!("image {}x{}", image.width, image.height));
        }
    }
    let (prepared, options) = prepare(corner(Filter::Tent, 1.0, 1));
    let watch = Watch::default();
    render(&prepared, &options, &watch).expect("rendered");
    let seen = watch.0.into_inner().unwrap();
    assert_eq!(seen, ["tile", "image 8x8"]);
    let (prepared, options) = prepare(corner(Filter::Box, 0.5, 1));
    let watch = Watch::default();
    render(&prepared, &options, &watch).expect("rendered");
    assert_eq!(watch.0.into_inner().unwrap(), ["tile"]);
}
