//! The light buffer against the BVH walk it stands in for: every shadow ray gets the same
//! answer (blocked or not) from both, in clouds of spheres, boxes, triangles and meshes at
//! unit scale, far from the origin, huge, tiny, with the light outside, inside and nearly
//! touching an item, for random origins, points on surfaces, and rays that graze a sphere's
//! silhouette or pass through a box's corner exactly as seen from the light.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Color, Light, LightKind, Shape};

use super::*;
use crate::query::Scratch;
use crate::scene::PreparedScene;
use crate::testing::{matte, sphere, tessellated_sphere, SceneBuilder};

/// A small deterministic generator (xorshift64*), so that every run checks the same rays.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn point(&mut self, center: DVec3, half: f64) -> DVec3 {
        DVec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        ) + center
    }

    fn direction(&mut self) -> DVec3 {
        loop {
            let d = self.point(DVec3::ZERO, 1.0);
            if d.length_squared() > 1e-3 && d.length_squared() <= 1.0 {
                return d.normalize();
            }
        }
    }
}

/// Where a cloud is, how big, and where its light is (relative to the centre, in units
/// of the scale).
#[derive(Clone)]
struct Cloud {
    name: &'static str,
    center: DVec3,
    scale: f64,
    light: DVec3,
    /// A small sphere this close to the light (in units of the scale), if any.
    touching_light: Option<f64>,
}

/// The cloud's prepared scene, its spheres (world centre and radius) and boxes.
struct Made {
    scene: PreparedScene,
    spheres: Vec<(DVec3, f64)>,
    boxes: Vec<(DVec3, DVec3)>,
    light: DVec3,
    /// For a directional light, the unit vector towards it.
    toward: Option<DVec3>,
}

/// The unit vector towards a cloud's directional light: towards where its point light
/// would be, or along an axis when that is at the centre.
fn toward(cloud: &Cloud) -> DVec3 {
    if cloud.light.length() > 0.5 {
        cloud.light.normalize()
    } else {
        DVec3::Y
    }
}

fn make(cloud: &Cloud, rng: &mut Rng, directional: bool) -> Made {
    let s = cloud.scale;
    let mut b = SceneBuilder::new();
    b.camera(cloud.center - DVec3::Z * 10.0 * s, cloud.center, 40.0);
    let light = cloud.center + cloud.light * s;
    if directional {
        b.light(Light {
            name: None,
            color: Color::gray(1.0),
            kind: LightKind::Directional {
                direction: -toward(cloud),
            },
        });
    } else {
        b.point_light(light, 1.0);
    }
    let m = b.material(matte(0.5, 0.5, 0.5));
    let mut spheres = Vec::new();
    let mut boxes = Vec::new();
    for _ in 0..120 {
        let c = rng.point(cloud.center, 2.0 * s);
        let r = rng.range(0.02, 0.3) * s;
        // Half of them placed by a transform, half in the shape itself.
        if rng.unit() < 0.5 {
            b.add(sphere(c.x, c.y, c.z, r), DMat4::IDENTITY, m);
        } else {
            b.add(sphere(0.0, 0.0, 0.0, r), DMat4::from_translation(c), m);
        }
        spheres.push((c, r));
    }
    for _ in 0..60 {
        let c = rng.point(cloud.center, 2.0 * s);
        let h = DVec3::new(
            rng.range(0.01, 0.3),
            rng.range(0.01, 0.3),
            rng.range(0.01, 0.3),
        ) * s;
        b.add(
            Shape::Box {
                min: c - h,
                max: c + h,
            },
            DMat4::IDENTITY,
            m,
        );
        boxes.push((c - h, c + h));
    }
    for _ in 0..40 {
        let a = rng.point(cloud.center, 2.0 * s);
        let edge = 0.3 * s;
        let shape = Shape::Triangle {
            a,
            b: a + rng.direction() * edge,
            c: a + rng.direction() * edge,
        };
        b.add(shape, DMat4::IDENTITY, m);
    }
    let mesh = b.mesh(tessellated_sphere(1.0, 6, 8, false));
    for _ in 0..4 {
        let at = DMat4::from_translation(rng.point(cloud.center, 2.0 * s))
            * DMat4::from_scale(DVec3::splat(0.25 * s));
        b.add(
            Shape::Mesh {
                mesh,
                smooth: false,
            },
            at,
            m,
        );
    }
    if let Some(gap) = cloud.touching_light {
        let r = 0.05 * s;
        let c = light + DVec3::new(1.0, 0.3, 0.2).normalize() * (r + gap * s);
        b.add(sphere(c.x, c.y, c.z, r), DMat4::IDENTITY, m);
        spheres.push((c, r));
    }
    let scene = b
        .prepare()
        .unwrap_or_else(|e| panic!("{}: {e}", cloud.name));
    Made {
        scene,
        spheres,
        boxes,
        light,
        toward: directional.then(|| toward(cloud)),
    }
}

/// What the shadow rays from `origins` found.
#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    blocked: usize,
    /// Answered from the buffer (the others started beyond its reach).
    answered: usize,
}

/// Checks each shadow ray from `origins` towards the scene's light: the buffer's answer is
/// the walk's.
fn check(made: &Made, name: &str, origins: impl IntoIterator<Item = DVec3>) -> Tally {
    let scene = &made.scene;
    let buffer = scene.light_buffers[0]
        .as_ref()
        .unwrap_or_else(|| panic!("{name}: the light has no buffer"));
    let mut scratch = Scratch::default();
    let mut tally = Tally::default();
    for origin in origins {
        let origin = origin.as_vec3a();
        let incidence = scene.lights[0].incidence(origin);
        let ray = Ray::new(origin, incidence.to_light);
        let distance = incidence.distance;
        let walked = scene.occluded(&ray, 0.0, distance, &mut scratch).is_some();
        let buffered = scene
            .occluded_towards(0, false, &ray, 0.0, distance, &mut scratch)
            .is_some();
        // A recorder's query names the walk's own blocker.
        assert_eq!(
            scene.occluded_towards(0, true, &ray, 0.0, distance, &mut scratch),
            scene.occluded(&ray, 0.0, distance, &mut scratch),
            "{name}: the blocker named from {origin:?}"
        );
        assert_eq!(
            buffered, walked,
            "{name}: a shadow ray from {origin:?} towards the light ({:?}, {distance}): the \
             buffer says blocked = {buffered}, the BVH walk {walked}",
            incidence.to_light
        );
        tally.rays += 1;
        tally.blocked += usize::from(walked);
        tally.answered += usize::from(matches!(
            buffer.lookup(&ray, distance),
            Lookup::Candidates(..)
        ));
    }
    tally
}

/// Origins whose rays to the light graze a sphere's silhouette as seen from the light, or
/// pass through a box's corner, from beyond them.
fn grazing(made: &Made, rng: &mut Rng, scale: f64) -> Vec<DVec3> {
    if let Some(w) = made.toward {
        return grazing_parallel(made, rng, w, scale);
    }
    let l = made.light;
    let mut origins = Vec::new();
    for &(c, r) in &made.spheres {
        let to_center = c - l;
        let d = to_center.length();
        if d <= r * 1.01 {
            continue;
        }
        let w = to_center / d;
        for _ in 0..8 {
            let e = rng
                .direction()
                .reject_from_normalized(w)
                .normalize_or_zero();
            let tangent = c + r * (-(r / d) * w + (1.0 - (r / d).powi(2)).sqrt() * e);
            origins.push(l + (tangent - l) * rng.range(1.001, 2.0));
        }
    }
    for &(lo, hi) in &made.boxes {
        for p in corners(lo, hi) {
            origins.push(l + (p - l) * rng.range(1.001, 2.0));
        }
    }
    origins
}

/// [`grazing`] for a directional light towards `w`: rays along `w` from behind each
/// sphere's silhouette and each box's corner.
fn grazing_parallel(made: &Made, rng: &mut Rng, w: DVec3, scale: f64) -> Vec<DVec3> {
    let mut origins = Vec::new();
    for &(c, r) in &made.spheres {
        for _ in 0..8 {
            let e = rng
                .direction()
                .reject_from_normalized(w)
                .normalize_or_zero();
            let tangent = c + r * e;
            origins.push(tangent - w * rng.range(0.001, 3.0) * scale);
        }
    }
    for &(lo, hi) in &made.boxes {
        for p in corners(lo, hi) {
            origins.push(p - w * rng.range(0.001, 3.0) * scale);
        }
    }
    origins
}

/// Points on the scene's surfaces, found by rays from random points in random directions,
/// pushed off the surface as the tracer pushes shadow rays' origins.
fn on_surfaces(made: &Made, cloud: &Cloud, rng: &mut Rng, count: usize) -> Vec<DVec3> {
    let scene = &made.scene;
    let mut scratch = Scratch::default();
    let mut points = Vec::new();
    for _ in 0..count * 4 {
        let from = rng.point(cloud.center, 3.0 * cloud.scale).as_vec3a();
        let ray = Ray::new(from, rng.direction().as_vec3a());
        let Some(hit) = scene.intersect(&ray, 0.0, f32::INFINITY, &mut scratch) else {
            continue;
        };
        let surface = scene.surface(&ray, &hit);
        let n = surface.geometric_normal;
        let n = if n.dot(ray.direction) < 0.0 { n } else { -n };
        let offset = scene.offset_at(&surface);
        points.push((surface.point + offset * n).as_dvec3());
        if points.len() == count {
            break;
        }
    }
    points
}

fn clouds() -> Vec<Cloud> {
    let outside = DVec3::new(3.0, 5.0, -4.0);
    vec![
        Cloud {
            name: "unit scale, light outside",
            center: DVec3::ZERO,
            scale: 1.0,
            light: outside,
            touching_light: None,
        },
        Cloud {
            name: "far from the origin",
            center: DVec3::new(1.0e4, -2.0e4, 5.0e3),
            scale: 1.0,
            light: outside,
            touching_light: None,
        },
        Cloud {
            name: "huge",
            center: DVec3::ZERO,
            scale: 1.0e3,
            light: outside,
            touching_light: None,
        },
        Cloud {
            name: "tiny",
            center: DVec3::new(0.5, 0.0, 0.0),
            scale: 1.0e-3,
            light: outside,
            touching_light: None,
        },
        Cloud {
            name: "light inside the cloud",
            center: DVec3::ZERO,
            scale: 1.0,
            light: DVec3::new(0.01, -0.02, 0.03),
            touching_light: None,
        },
        Cloud {
            name: "light in the items' planes",
            center: DVec3::ZERO,
            scale: 1.0,
            light: DVec3::ZERO,
            touching_light: None,
        },
        Cloud {
            name: "a sphere nearly touching the light",
            center: DVec3::new(-300.0, 40.0, 7.0),
            scale: 2.0,
            light: DVec3::new(0.5, 2.5, -0.5),
            touching_light: Some(1e-4),
        },
    ]
}

#[test]
fn the_buffer_answers_every_shadow_ray_as_the_bvh_walk() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (cloud, directional) in clouds()
        .into_iter()
        .flat_map(|cloud| [false, true].map(|directional| (cloud.clone(), directional)))
    {
        let made = make(&cloud, &mut rng, directional);
        let random: Vec<DVec3> = (0..2000)
            .map(|_| rng.point(cloud.center, 3.0 * cloud.scale))
            .collect();
        let surfaces = on_surfaces(&made, &cloud, &mut rng, 2000);
        let grazing = grazing(&made, &mut rng, cloud.scale);
        let light = if directional { "directional" } else { "point" };
        let name = &format!("{}, {light} light", cloud.name);
        let random = check(&made, name, random);
        let surfaces = check(&made, name, surfaces);
        let grazing = check(&made, name, grazing);
        // The checks mean something only if the rays were answered by the buffer and
        // found both answers, the grazing ones included.
        for (kind, tally) in [
            ("random", &random),
            ("surface", &surfaces),
            ("grazing", &grazing),
        ] {
            assert!(
                tally.answered * 10 >= tally.rays * 9,
                "{name}: only {} of {} {kind} rays were answered by the buffer",
                tally.answered,
                tally.rays
            );
            assert!(
                tally.blocked > 0 && tally.blocked < tally.rays,
                "{name}: {kind} rays: {tally:?}"
            );
        }
    }
}

#[test]
fn a_ray_from_beyond_the_buffer_s_reach_walks_the_bvh() {
    let mut rng = Rng(7);
    let cloud = &clouds()[0];
    let made = make(cloud, &mut rng, false);
    let Some(buffer) = made.scene.light_buffers[0].as_ref() else {
        panic!("no buffer");
    };
    let far = Vec3A::new(1.0e7, 0.0, 0.0);
    let incidence = made.scene.lights[0].incidence(far);
    let ray = Ray::new(far, incidence.to_light);
    assert!(matches!(
        buffer.lookup(&ray, incidence.distance),
        Lookup::Unanswered
    ));
    // And the scene still answers it, as the walk does.
    check(&made, "far origin", [far.as_dvec3()]);
}

#[test]
fn a_buffer_over_its_budget_is_not_made() {
    let boxes: Vec<Aabb> = (0..100)
        .map(|i| {
            let c = Vec3A::new(i as f32, 0.0, 5.0);
            Aabb::new(c - 0.4, c + 0.4)
        })
        .collect();
    let made = LightBuffer::new(Vec3A::ZERO, &boxes, usize::MAX).map(|b| b.budget_used());
    let Some(needed) = made else {
        panic!("no buffer without a budget");
    };
    assert!(needed >= boxes.len());
    assert!(LightBuffer::new(Vec3A::ZERO, &boxes, needed).is_some());
    assert!(LightBuffer::new(Vec3A::ZERO, &boxes, needed - 1).is_none());
}

#[test]
fn a_scene_renders_the_same_with_and_without_light_buffers() {
    use crate::render::{render, NoObserver, RenderOptions};
    for (name, builder) in [
        ("sphere grid", crate::testing::sphere_grid(24)),
        ("reflective spheres", crate::testing::reflective_spheres()),
        ("classic", crate::testing::whitted_classic()),
    ] {
        let valid = builder.build().unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let with = PreparedScene::new(&valid);
        let options = RenderOptions {
            width: 64,
            height: 48,
            ..RenderOptions::from_settings(&valid.settings)
        };
        let bits = |scene: &PreparedScene| {
            let (image, _) = render(scene, &options, &NoObserver).unwrap_or_else(|| panic!());
            image
                .pixels
                .iter()
                .map(|p| p.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        let buffered = bits(&with);
        assert!(
            with.light_buffer_sizes().0 > 0 || name == "classic",
            "{name}"
        );
        let walked = bits(&with.without_light_buffers());
        assert!(buffered == walked, "{name}: the images differ");
        // Prepared for ray trees (`trace`, `explain`): no buffers built, the same image.
        let for_trees = PreparedScene::for_ray_trees(&valid);
        assert_eq!(for_trees.light_buffer_sizes(), (0, 0, 0), "{name}");
        assert!(bits(&for_trees) == buffered, "{name}: the images differ");
    }
}

/// Boxes around a light, apart as seen from it, so that each box's corners are the edges
/// of its footprint and of the face's window: rays through a corner (moved inwards by
/// a few roundings of a coordinate, so that the walk finds them blocked as often as
/// not) and from the point of a box nearest the light are answered at the very edge of
/// the buffer's widening, where a buffer without it answers differently.
#[test]
fn rays_at_the_edges_of_a_footprint_are_answered_as_the_walk() {
    let mut rng = Rng(0x5eed);
    let light_far = DVec3::new(3.0e3, 5.0e3, -4.0e3);
    for (name, center, scale, light) in [
        ("unit scale", DVec3::ZERO, 1.0, DVec3::ZERO),
        (
            "far from the origin",
            DVec3::new(-3.0e3, 1.0e3, 2.5e3),
            1.0,
            DVec3::ZERO,
        ),
        ("huge", DVec3::new(1.0e3, 0.0, 0.0), 50.0, DVec3::ZERO),
        ("tiny", DVec3::new(0.25, 0.0, 0.0), 1.0e-3, DVec3::ZERO),
        // The items' own padding is relative to their coordinates; the light's and the
        // origins' rounding to theirs: only the buffer's widening covers a ray from far
        // away past a small item near the origin.
        ("light far from small items", DVec3::ZERO, 1.0e-2, light_far),
        ("light far from tiny items", DVec3::ZERO, 1.0e-4, light_far),
    ] {
        let light = center + light;
        let mut b = SceneBuilder::new();
        b.camera(center - DVec3::Z * 10.0 * scale, center, 40.0);
        b.point_light(light, 1.0);
        let m = b.material(matte(0.5, 0.5, 0.5));
        let mut boxes = Vec::new();
        for i in 0..16 {
            let angle = f64::from(i) * std::f64::consts::TAU / 16.0;
            let toward = DVec3::new(angle.cos(), 0.3 * (3.0 * angle).sin(), angle.sin());
            let c = center + toward * rng.range(2.0, 5.0) * scale;
            let h = DVec3::new(
                rng.range(0.1, 0.3),
                rng.range(0.1, 0.3),
                rng.range(0.1, 0.3),
            );
            let (lo, hi) = (c - h * scale, c + h * scale);
            b.add(Shape::Box { min: lo, max: hi }, DMat4::IDENTITY, m);
            boxes.push((lo, hi));
        }
        let made = Made {
            scene: b.prepare().unwrap_or_else(|e| panic!("{name}: {e}")),
            spheres: Vec::new(),
            boxes: boxes.clone(),
            light,
            toward: None,
        };
        let mut origins = Vec::new();
        for &(lo, hi) in &boxes {
            let middle = (lo + hi) / 2.0;
            for p in corners(lo, hi) {
                // Inwards by a few roundings of the corner's coordinates.
                let size = p.abs().max_element().max(scale);
                for inwards in [0.0, 3e-8, 6e-8, 1.2e-7, 2.4e-7, 4.8e-7, 1e-6, 2e-6, 4e-6] {
                    let p = p + (middle - p).normalize() * inwards * size;
                    for k in [1.000_001, 1.001, 1.5, 3.0] {
                        origins.push(light + (p - light) * k);
                    }
                }
            }
            // The box's point nearest the light, and points about a rounding away.
            let nearest = light.clamp(lo, hi);
            origins.push(nearest);
            for _ in 0..16 {
                origins.push(nearest + rng.direction() * 1e-7 * (nearest.abs().max_element()));
            }
        }
        let tally = check(&made, name, origins);
        assert!(
            tally.answered == tally.rays && tally.blocked > 0 && tally.blocked < tally.rays,
            "{name}: {tally:?}"
        );
    }
}

/// Small objects scattered all round a light would ask, at cells of their own size, for
/// millions of cells per face: the grid stays within a few cells an object.
#[test]
fn objects_all_round_a_light_get_a_few_cells_each() {
    let mut rng = Rng(11);
    let boxes: Vec<Aabb> = (0..2000)
        .map(|_| {
            let c = (rng.direction() * rng.range(5.0, 50.0)).as_vec3a();
            Aabb::new(c - 0.01, c + 0.01)
        })
        .collect();
    let Some(buffer) = LightBuffer::new(Vec3A::ZERO, &boxes, usize::MAX) else {
        panic!("no buffer");
    };
    let cells = buffer.cell_starts.len();
    assert!(
        cells < 6 * boxes.len(),
        "{cells} cells for {} objects",
        boxes.len()
    );
}
