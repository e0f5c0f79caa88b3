//! Rendering a region of the image: its pixels are the whole render's at the same places,
//! bit for bit, for every filter (a filter that reaches past the pixel takes its samples
//! from a margin around the region), for regions of any size and place, borders included.

use whitted_ir::Filter;
use whitted_tracer::testing::whitted_classic;
use whitted_tracer::{render, render_region, NoObserver, PixelRect, PreparedScene, RenderOptions};

const WIDTH: u32 = 37;
const HEIGHT: u32 = 29;

/// A small deterministic generator (xorshift), so the regions are the same on every run.
struct Regions(u64);

impl Regions {
    fn next(&mut self, below: u32) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % u64::from(below)) as u32
    }

    fn region(&mut self) -> PixelRect {
        let x = self.next(WIDTH);
        let y = self.next(HEIGHT);
        let width = 1 + self.next(WIDTH - x);
        let height = 1 + self.next(HEIGHT - y);
        PixelRect {
            x,
            y,
            width,
            height,
        }
    }
}

fn bits(pixel: [f32; 3]) -> [u32; 3] {
    pixel.map(f32::to_bits)
}

#[test]
fn region_pixels_are_the_whole_render_s_bit_for_bit_for_every_filter() {
    let filters = [
        (Filter::Box, 0.5),
        (Filter::Box, 1.2),
        (Filter::Tent, 1.0),
        (Filter::Tent, 2.5),
        (Filter::Gaussian, 0.5),
        (Filter::Gaussian, 1.1),
    ];
    for (filter, radius) in filters {
        let mut builder = whitted_classic();
        let settings = builder.settings();
        settings.width = WIDTH;
        settings.height = HEIGHT;
        settings.samples_per_pixel = 2;
        settings.filter = filter;
        settings.filter_radius = radius;
        let scene = builder.build().expect("a valid test scene");
        let prepared = PreparedScene::new(&scene);
        let options = RenderOptions::from_settings(&scene.settings);
        let (whole, _) = render(&prepared, &options, &NoObserver).expect("not cancelled");
        let mut regions = Regions(0x9e37_79b9_7f4a_7c15);
        let fixed = [
            PixelRect::whole(WIDTH, HEIGHT),
            PixelRect {
                x: 0,
                y: 0,
                width: 1,
                height: 1,
            },
            PixelRect {
                x: WIDTH - 1,
                y: HEIGHT - 1,
                width: 1,
                height: 1,
            },
            PixelRect {
                x: 5,
                y: 7,
                width: 1,
                height: 1,
            },
            PixelRect::rows(WIDTH, 0..3),
            PixelRect::rows(WIDTH, HEIGHT - 4..HEIGHT),
            PixelRect {
                x: WIDTH - 17,
                y: 3,
                width: 17,
                height: 20,
            },
            // Past the image: clipped to it.
            PixelRect {
                x: 30,
                y: 25,
                width: 100,
                height: 100,
            },
        ];
        let random: Vec<PixelRect> = (0..12).map(|_| regions.region()).collect();
        for region in fixed.into_iter().chain(random) {
            let (part, _) =
                render_region(&prepared, &options, region, &NoObserver).expect("not cancelled");
            let region = region.clipped(WIDTH, HEIGHT);
            assert_eq!((part.width, part.height), (region.width, region.height));
            for y in 0..region.height {
                for x in 0..region.width {
                    let (ix, iy) = (region.x + x, region.y + y);
                    let expected = whole.pixel(ix, iy).map(bits);
                    let got = part.pixel(x, y).map(bits);
                    assert_eq!(
                        got, expected,
                        "{filter:?} radius {radius}, region {region:?}: pixel ({ix}, {iy})"
                    );
                }
            }
        }
    }
}

#[test]
fn a_region_outside_the_image_is_empty() {
    let mut builder = whitted_classic();
    builder.settings().width = 8;
    builder.settings().height = 8;
    let scene = builder.build().expect("a valid test scene");
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions::from_settings(&scene.settings);
    let region = PixelRect {
        x: 9,
        y: 2,
        width: 4,
        height: 4,
    };
    let (part, stats) = render_region(&prepared, &options, region, &NoObserver).unwrap();
    assert_eq!((part.width, part.height, part.pixels.len()), (0, 4, 0));
    assert_eq!(stats.camera_rays, 0);
}

/// The task plan is the same on any thread count (every task works it out alone and all
/// must agree), and its bands cover the image's rows once, in order.
#[test]
fn the_task_plan_is_the_same_on_any_thread_count() {
    let mut builder = whitted_classic();
    builder.settings().width = 40;
    builder.settings().height = 30;
    let scene = builder.build().expect("a valid test scene");
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions::from_settings(&scene.settings);
    let plan_on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| whitted_tracer::task_plan::plan_regions(&prepared, &options, 7))
            .expect("7 tasks fit 30 rows")
    };
    let plan = plan_on(1);
    assert_eq!(plan, plan_on(2));
    assert_eq!(plan, plan_on(3));
    assert_eq!(plan.len(), 7);
    let mut next_row = 0;
    for band in &plan {
        assert_eq!((band.x, band.width, band.y), (0, 40, next_row));
        assert!(band.height > 0);
        next_row += band.height;
    }
    assert_eq!(next_row, 30);
}
