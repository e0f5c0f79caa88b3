//! The public rendering API: determinism across thread counts, the one-code-path invariant
//! (`trace_pixel_with` reproduces rendered pixels bit for bit), per-pixel statistics, the
//! observer, and the depth limit.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use whitted_ir::{
    Attenuation, Color, CsgOp, DMat4, DVec3, Light, LightKind, Material, Quadric, QuadricForm,
    ShadowMode, Shape,
};
use whitted_tracer::testing::{
    glass, matte, mirror, plane_y, sphere, sphere_grid, whitted_classic, SceneBuilder,
};
use whitted_tracer::{
    render, render_with_pixel_stats, trace_pixel_with, LightSample, NoObserver, NoRecord,
    PixelAccumulator, PixelStats, PreparedScene, RayStart, Recorder, RenderObserver, RenderOptions,
    Termination, TileResult, Vec3A,
};

fn prepare(builder: SceneBuilder) -> PreparedScene {
    match builder.prepare() {
        Ok(scene) => scene,
        Err(message) => panic!("invalid test scene: {message}"),
    }
}

/// A scene that touches most features: CSG, a quadric, patterns, glass with absorption,
/// a mirror, a spot light and filtered shadows.
fn busy_scene() -> SceneBuilder {
    let mut b = whitted_classic();
    b.settings().shadows = ShadowMode::Filtered;
    b.light(Light {
        name: None,
        color: Color::gray(0.6),
        kind: LightKind::Spot {
            position: DVec3::new(2.0, 5.0, 3.0),
            direction: DVec3::new(-0.3, -1.0, -0.5),
            inner_angle_degrees: 15.0,
            outer_angle_degrees: 30.0,
            attenuation: Attenuation {
                constant: 1.0,
                linear: 0.05,
                quadratic: 0.01,
            },
        },
    });
    let blue = b.material(matte(0.2, 0.3, 0.9));
    let tinted = b.material(Material {
        absorption: Color::new(0.1, 0.5, 1.0),
        ..glass()
    });
    let shiny = b.material(mirror());
    let cube = b.part(
        Shape::Box {
            min: DVec3::splat(-0.5),
            max: DVec3::splat(0.5),
        },
        DMat4::from_translation(DVec3::new(-2.2, 0.5, 1.0)),
        blue,
    );
    let bite = b.part(sphere(-2.2, 0.9, 1.4, 0.45), DMat4::IDENTITY, shiny);
    b.csg(CsgOp::Difference, vec![cube, bite], blue);
    b.add(
        Shape::Quadric {
            form: QuadricForm::Ellipsoid,
            quadric: Quadric::from_coefficients([
                1.0, 4.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.16,
            ]),
        },
        DMat4::from_translation(DVec3::new(2.0, 0.3, 1.5)),
        tinted,
    );
    // A ring of small balls, so that the BVH (not the few-object loop) does the work.
    for i in 0..40 {
        let angle = f64::from(i) * std::f64::consts::TAU / 40.0;
        let material = if i % 3 == 0 { shiny } else { blue };
        b.add(
            sphere(3.0 * angle.cos(), 0.15, 3.0 * angle.sin() - 1.0, 0.15),
            DMat4::IDENTITY,
            material,
        );
    }
    b
}

fn options(width: u32, height: u32, samples: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        samples_per_pixel: samples,
        max_depth: 6,
        min_weight: 0.001,
    }
}

fn bits(pixels: &[[f32; 3]]) -> Vec<u32> {
    pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

fn render_on(threads: usize, scene: &PreparedScene, options: &RenderOptions) -> Vec<u32> {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool,
        Err(e) => panic!("no thread pool: {e}"),
    };
    let (image, _) = pool
        .install(|| render(scene, options, &NoObserver))
        .unwrap_or_else(|| panic!("not cancelled"));
    bits(&image.pixels)
}

#[test]
fn output_is_identical_on_any_thread_count_and_every_run() {
    let scene = prepare(busy_scene());
    // Not a multiple of the tile size, several samples per pixel.
    let opts = options(83, 61, 4);
    let one = render_on(1, &scene, &opts);
    let two = render_on(2, &scene, &opts);
    let three = render_on(3, &scene, &opts);
    let again = render_on(2, &scene, &opts);
    assert_eq!(one.len(), 83 * 61 * 3);
    assert!(one == two, "1 thread and 2 threads differ");
    assert!(one == three, "1 thread and 3 threads differ");
    assert!(two == again, "two runs differ");
    // And the picture is not trivially uniform.
    let distinct: std::collections::BTreeSet<u32> = one.iter().copied().collect();
    assert!(distinct.len() > 1000);
}

/// A recorder that checks the hooks nest properly and remembers the camera ray's colour.
#[derive(Default)]
struct Nesting {
    depth: Vec<u32>,
    rays: u32,
    shadow_rays: u32,
    root_color: Option<Vec3A>,
}

impl Recorder for Nesting {
    fn ray_started(&mut self, ray: &RayStart) {
        let expected = self.depth.last().map_or(0, |d| d + 1);
        assert_eq!(ray.depth, expected, "depth must grow by one per level");
        self.depth.push(ray.depth);
        self.rays += 1;
    }
    fn light_sampled(&mut self, sample: &LightSample) {
        self.shadow_rays += u32::from(sample.shadow_ray.is_some());
    }
    fn ray_finished(&mut self, color: Vec3A, _termination: Termination) {
        self.depth.pop();
        if self.depth.is_empty() {
            self.root_color = Some(color);
        }
    }
}

#[test]
fn tracing_a_pixel_reproduces_the_rendered_pixel_bit_for_bit() {
    let scene = prepare(busy_scene());
    let opts = options(40, 30, 1);
    let (image, stats) = render(&scene, &opts, &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    let mut rays = 0u64;
    for y in 0..opts.height {
        for x in 0..opts.width {
            let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
            let plain = trace_pixel_with(&scene, &opts, x, y, 0, &mut NoRecord);
            let mut nesting = Nesting::default();
            let recorded = trace_pixel_with(&scene, &opts, x, y, 0, &mut nesting);
            assert_eq!(bits(&[plain]), bits(&[rendered]), "pixel {x},{y}");
            assert_eq!(
                bits(&[recorded]),
                bits(&[rendered]),
                "pixel {x},{y} recorded"
            );
            assert!(nesting.depth.is_empty());
            let root = nesting.root_color.unwrap_or(Vec3A::NAN).to_array();
            assert_eq!(
                bits(&[root]),
                bits(&[rendered]),
                "pixel {x},{y} root colour"
            );
            rays += u64::from(nesting.rays + nesting.shadow_rays);
        }
    }
    // The recorder saw every ray the renderer counted.
    assert_eq!(rays, stats.total_rays());
}

/// Camera rays walked in packets (neighbouring rays sharing one BVH walk) give every pixel
/// exactly the colour of its rays traced alone, with one sample or several; a packet whose
/// rays point into different octants (across the middle column here) is walked ray by ray.
#[test]
fn camera_rays_in_packets_give_the_pixels_of_rays_traced_alone() {
    let scene = prepare(sphere_grid(9));
    for samples in [1, 3] {
        let opts = options(40, 30, samples);
        let (image, stats) =
            render(&scene, &opts, &NoObserver).unwrap_or_else(|| panic!("cancelled"));
        for y in 0..opts.height {
            for x in 0..opts.width {
                let mut alone = PixelAccumulator::new();
                for k in 0..samples {
                    alone.add(trace_pixel_with(&scene, &opts, x, y, k, &mut NoRecord));
                }
                let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
                assert_eq!(
                    bits(&[alone.mean()]),
                    bits(&[rendered]),
                    "pixel {x},{y}, {samples} samples"
                );
            }
        }
        let (packed, all) = (stats.camera_rays_in_packets, stats.camera_rays);
        assert!(packed > all / 2, "{packed} of {all} camera rays in packets");
        assert!(packed < all, "the middle column's packets point two ways");
    }
}

#[test]
fn pixels_with_several_samples_are_the_mean_of_traced_samples() {
    let scene = prepare(busy_scene());
    let opts = options(24, 18, 5);
    let (image, _) = render(&scene, &opts, &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    let mut differing_samples = 0;
    for y in 0..opts.height {
        for x in 0..opts.width {
            let mut accumulator = PixelAccumulator::new();
            let mut samples = Vec::new();
            for k in 0..opts.samples_per_pixel {
                let c = trace_pixel_with(&scene, &opts, x, y, k, &mut NoRecord);
                samples.push(c);
                accumulator.add(c);
            }
            if samples.iter().any(|c| c != &samples[0]) {
                differing_samples += 1;
            }
            let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
            assert_eq!(
                bits(&[accumulator.mean()]),
                bits(&[rendered]),
                "pixel {x},{y}"
            );
        }
    }
    // Samples really fall at different places (edges get different colours).
    assert!(differing_samples > 20, "{differing_samples}");
}

#[test]
fn pixel_statistics_match_the_render() {
    let scene = prepare(busy_scene());
    let opts = options(32, 24, 2);
    let (image, stats, pixel_stats) =
        render_with_pixel_stats(&scene, &opts, &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    let (plain, _) = render(&scene, &opts, &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    assert_eq!(bits(&image.pixels), bits(&plain.pixels));
    assert_eq!(pixel_stats.len(), 32 * 24);
    let total: u64 = pixel_stats.iter().map(|p| u64::from(p.rays)).sum();
    assert_eq!(total, stats.total_rays());
    let deepest = pixel_stats.iter().map(|p| p.deepest).max().unwrap_or(0);
    assert_eq!(deepest, stats.deepest_ray);
    // Each pixel's statistics equal what tracing its samples with the recorder gives.
    for (i, expected) in pixel_stats.iter().enumerate() {
        let (x, y) = ((i % 32) as u32, (i / 32) as u32);
        let mut mine = PixelStats::default();
        for k in 0..2 {
            trace_pixel_with(&scene, &opts, x, y, k, &mut mine);
        }
        assert_eq!(&mine, expected, "pixel {x},{y}");
    }
    let misses = pixel_stats
        .iter()
        .filter(|p| p.terminations.contains(Termination::Miss))
        .count();
    assert!(misses > 0 && misses < pixel_stats.len());
}

struct Watcher {
    covered: Mutex<Vec<u32>>,
    width: u32,
    tiles: AtomicUsize,
    stop_after: Option<usize>,
}

impl RenderObserver for Watcher {
    fn tile_done(&self, tile: &TileResult) {
        assert_eq!(tile.pixels.len(), (tile.width * tile.height) as usize);
        if let Ok(mut covered) = self.covered.lock() {
            for y in tile.y..tile.y + tile.height {
                for x in tile.x..tile.x + tile.width {
                    covered[(y * self.width + x) as usize] += 1;
                }
            }
        }
        self.tiles.fetch_add(1, Ordering::SeqCst);
    }
    fn should_stop(&self) -> bool {
        self.stop_after
            .is_some_and(|n| self.tiles.load(Ordering::SeqCst) >= n)
    }
}

#[test]
fn observer_sees_every_tile_once_and_can_cancel() {
    let scene = prepare(whitted_classic());
    let opts = options(50, 37, 1);
    let watcher = Watcher {
        covered: Mutex::new(vec![0; 50 * 37]),
        width: 50,
        tiles: AtomicUsize::new(0),
        stop_after: None,
    };
    let (image, _) = render(&scene, &opts, &watcher).unwrap_or_else(|| panic!("cancelled"));
    assert_eq!(image.pixels.len(), 50 * 37);
    let covered = watcher
        .covered
        .lock()
        .map(|c| c.clone())
        .unwrap_or_default();
    assert!(
        covered.iter().all(|&n| n == 1),
        "every pixel in exactly one tile"
    );
    let cancelling = Watcher {
        covered: Mutex::new(vec![0; 50 * 37]),
        width: 50,
        tiles: AtomicUsize::new(0),
        stop_after: Some(1),
    };
    assert!(render(&scene, &opts, &cancelling).is_none());
}

#[test]
fn excessive_depth_is_clamped_not_a_stack_overflow() {
    // Two perfect mirrors facing each other with no weight cut-off: only the depth limit
    // ends the path.
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 0.3), 40.0);
    b.point_light(DVec3::new(0.0, 1.0, 0.0), 1.0);
    let perfect = b.material(Material {
        reflective: Color::WHITE,
        ..matte(0.1, 0.1, 0.1)
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, perfect);
    b.add(
        Shape::Plane {
            normal: -DVec3::Y,
            offset: -2.0,
        },
        DMat4::IDENTITY,
        perfect,
    );
    let scene = prepare(b);
    let opts = RenderOptions {
        width: 8,
        height: 8,
        samples_per_pixel: 1,
        max_depth: u32::MAX,
        min_weight: 0.0,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap_or_else(|e| panic!("no pool: {e}"));
    let (_, stats) = pool
        .install(|| render(&scene, &opts, &NoObserver))
        .unwrap_or_else(|| panic!("cancelled"));
    assert_eq!(stats.deepest_ray, whitted_ir::limits::MAX_DEPTH);
}

#[test]
fn an_empty_scene_renders_its_background() {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::new(0.25, 0.5, 0.75);
    let scene = prepare(b);
    assert_eq!(scene.object_count(), 0);
    let (image, stats) =
        render(&scene, &options(7, 5, 2), &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    assert!(image.pixels.iter().all(|p| *p == [0.25, 0.5, 0.75]));
    assert_eq!(stats.total_rays(), 7 * 5 * 2);
    // A zero-sized image is empty, not an error.
    let (empty, _) =
        render(&scene, &options(0, 0, 1), &NoObserver).unwrap_or_else(|| panic!("cancelled"));
    assert!(empty.pixels.is_empty());
}
