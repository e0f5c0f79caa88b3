//! Meshes against oracles that are not the mesh code: brute force over every triangle for
//! the mesh BVH, the analytic sphere for a tessellated one (glass included), exact sphere
//! membership for a mesh subtracted in CSG, hand-worked barycentric normals, and counts
//! for instancing.

use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Color, CsgOp, Material, Mesh, Shape};

use super::PreparedMesh;
use crate::query::Scratch;
use crate::render::{render, Image, NoObserver};
use crate::scene::PreparedScene;
use crate::testing::{glass, matte, plane_y, sphere, tessellated_sphere, SceneBuilder};
use crate::tests::{options, prepare};
use whitted_bvh::Ray;

/// splitmix64, so that every generated ray is reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A mesh that is not a sphere: a jagged terrain of random heights over a grid (open),
/// with many triangles sharing edges and vertices.
fn terrain(n: u32, rng: &mut Rng) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            positions.push([i as f32, rng.range(-0.5, 0.5), j as f32]);
        }
    }
    let v = |i: u32, j: u32| i * (n + 1) + j;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            triangles.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
        }
    }
    Mesh::new("terrain.obj".into(), positions, Vec::new(), triangles)
}

/// Rays of the kinds that break traversals: random, axis-aligned, with ±0.0 components,
/// aimed at vertices and edge midpoints, and grazing along the surface.
fn awkward_rays(mesh: &Mesh, rng: &mut Rng, count: usize) -> Vec<Ray> {
    let (lo, hi) = mesh.bounds().unwrap_or_default();
    let (lo, hi) = (lo.as_vec3a(), hi.as_vec3a());
    let pad = (hi - lo).max_element();
    let mut rays = Vec::new();
    let point_in = |rng: &mut Rng, margin: f32| {
        Vec3A::new(
            rng.range(lo.x - margin, hi.x + margin),
            rng.range(lo.y - margin, hi.y + margin),
            rng.range(lo.z - margin, hi.z + margin),
        )
    };
    let vertex = |rng: &mut Rng| Vec3A::from(mesh.positions[rng.below(mesh.positions.len())]);
    for k in 0..count {
        let ray = match k % 6 {
            0 => {
                let from = point_in(rng, pad);
                Ray::new(from, (point_in(rng, 0.0) - from).normalize())
            }
            1 => {
                // Along an axis, in either direction, with the other components ±0.0.
                let axis = rng.below(3);
                let mut d = Vec3A::new(
                    if rng.below(2) == 0 { 0.0 } else { -0.0 },
                    if rng.below(2) == 0 { 0.0 } else { -0.0 },
                    if rng.below(2) == 0 { 0.0 } else { -0.0 },
                );
                d[axis] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                let mut from = point_in(rng, 0.0);
                from[axis] = if d[axis] > 0.0 {
                    lo[axis] - pad
                } else {
                    hi[axis] + pad
                };
                Ray::new(from, d)
            }
            2 => {
                // Straight at a vertex.
                let target = vertex(rng);
                let from = point_in(rng, pad) + Vec3A::splat(pad);
                Ray::new(from, (target - from).normalize())
            }
            3 => {
                // At the middle of an edge.
                let t = mesh.triangles[rng.below(mesh.triangles.len())];
                let a = Vec3A::from(mesh.positions[t[0] as usize]);
                let b = Vec3A::from(mesh.positions[t[1] as usize]);
                let target = (a + b) * 0.5;
                let from = point_in(rng, pad) - Vec3A::splat(pad);
                Ray::new(from, (target - from).normalize())
            }
            4 => {
                // Grazing: from a vertex along a direction nearly in the triangle's plane.
                let t = mesh.triangles[rng.below(mesh.triangles.len())];
                let a = Vec3A::from(mesh.positions[t[0] as usize]);
                let b = Vec3A::from(mesh.positions[t[1] as usize]);
                let c = Vec3A::from(mesh.positions[t[2] as usize]);
                let normal = (b - a).cross(c - a).normalize();
                let along = (c - b).normalize();
                let d = (along + normal * rng.range(-1e-4, 1e-4)).normalize();
                Ray::new(a - d * pad, d)
            }
            _ => {
                // Starting inside the box, in any direction (a secondary ray).
                let d = Vec3A::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), -0.0);
                Ray::new(point_in(rng, 0.0), d.normalize_or(Vec3A::X))
            }
        };
        rays.push(ray);
    }
    rays
}

/// Whether the walk's answer is brute force's. Möller–Trumbore's `t` is only good to about
/// 40 ulps when the triangle is small and far (a ray through a vertex meets its triangles
/// at `t`s that differ by 2e-5 at distance 7), so two answers agree within that, and a hit
/// that only one of them has must lie that close to an end of the window.
fn agree(walked: Option<f32>, brute: Option<f32>, tmin: f32, tmax: f32) -> bool {
    let tolerance = |t: f32| 1e-5 * t.abs().max(1.0);
    let near_end = |t: f32| (t - tmin).abs() <= tolerance(t) || (t - tmax).abs() <= tolerance(t);
    match (walked, brute) {
        (None, None) => true,
        (Some(a), Some(b)) => (a - b).abs() <= tolerance(b),
        (Some(t), None) | (None, Some(t)) => near_end(t),
    }
}

/// Planted bug, seen failing: the walk stopped at the first triangle it found
/// (`Step::Stop` for `Step::Shrink` in `first_hit`) instead of the nearest: 737 of the
/// sphere's 18,000 queries disagreed.
#[test]
fn mesh_bvh_agrees_with_brute_force_on_awkward_rays() {
    let mut rng = Rng(7);
    let meshes = [
        tessellated_sphere(1.5, 24, 48, false),
        terrain(40, &mut rng),
    ];
    for mesh in &meshes {
        let prepared = PreparedMesh::new(mesh);
        assert!(prepared.bvh.is_some(), "{} has no BVH", mesh.file);
        let mut disagreements = Vec::new();
        let rays = awkward_rays(mesh, &mut rng, 6_000);
        for ray in &rays {
            for (tmin, tmax) in [(0.0, f32::INFINITY), (1e-3, 5.0), (f32::NEG_INFINITY, 2.0)] {
                let walked = prepared.first_hit(ray, tmin, tmax).map(|h| h.0);
                let brute = prepared.first_hit_brute_force(ray, tmin, tmax).map(|h| h.0);
                if !agree(walked, brute, tmin, tmax) {
                    disagreements.push((*ray, tmin, tmax, walked, brute));
                }
            }
        }
        assert!(
            disagreements.is_empty(),
            "{}: {} of {} queries disagree, first {:?}",
            mesh.file,
            disagreements.len(),
            rays.len() * 3,
            disagreements.first()
        );
    }
}

/// A scene of one object over a floor, lit from above and to the side.
fn ball_scene(shape_of: impl FnOnce(&mut SceneBuilder) -> Shape, material: Material) -> Image {
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 1.5, 6.0), DVec3::new(0.0, 0.3, 0.0), 40.0);
    b.point_light(DVec3::new(-4.0, 6.0, 5.0), 1.0);
    b.settings().background = Color::new(0.2, 0.3, 0.5);
    let floor = b.material(matte(0.9, 0.9, 0.9));
    b.add(plane_y(-1.0), DMat4::IDENTITY, floor);
    let material = b.material(material);
    let shape = shape_of(&mut b);
    b.add(
        shape,
        DMat4::from_translation(DVec3::new(0.0, 0.0, 0.0)),
        material,
    );
    let scene = prepare(b);
    render(&scene, &options(96, 72), &NoObserver)
        .map(|(image, _)| image)
        .expect("the render ran")
}

/// Mean absolute difference per channel, and the share of pixels differing by more than
/// `tolerance` on some channel.
fn difference(a: &Image, b: &Image, tolerance: f32) -> (f32, f32) {
    let mut sum = 0.0;
    let mut over = 0usize;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        let d = [0, 1, 2].map(|c| (p[c].min(1.0) - q[c].min(1.0)).abs());
        sum += d.iter().sum::<f32>() / 3.0;
        if d.iter().any(|&x| x > tolerance) {
            over += 1;
        }
    }
    let n = a.pixels.len() as f32;
    (sum / n, over as f32 / n)
}

/// Planted bug, seen failing: meshes reported as not solid (`is_solid` false), so the
/// glass ball was thin sheets that bend nothing, and the glass render differed from the
/// sphere's in 8.3% of pixels (mean difference 0.020).
#[test]
fn a_tessellated_sphere_renders_like_the_sphere_matte_and_glass() {
    for (material, name) in [(matte(0.8, 0.3, 0.2), "matte"), (glass(), "glass")] {
        let analytic = ball_scene(|_| sphere(0.0, 0.0, 0.0, 1.0), material.clone());
        let meshed = ball_scene(
            |b| Shape::Mesh {
                mesh: b.mesh(tessellated_sphere(1.0, 64, 128, true)),
                smooth: true,
            },
            material,
        );
        let (mean, share) = difference(&analytic, &meshed, 0.1);
        assert!(
            mean < 0.01 && share < 0.02,
            "{name}: mean difference {mean}, {share} of pixels off by more than 0.1"
        );
    }
}

/// The nearest hit along a ray from outside, in a prepared scene.
fn hit_t(scene: &PreparedScene, origin: Vec3A, direction: Vec3A) -> Option<(f32, Vec3A)> {
    let ray = Ray::new(origin, direction.normalize());
    let mut scratch = Scratch::default();
    let hit = scene.intersect(&ray, 0.0, f32::INFINITY, &mut scratch)?;
    Some((hit.t, scene.surface(&ray, &hit).geometric_normal))
}

/// A box with a ball bitten out of its top: a mesh ball, as a CSG difference child, against
/// exact membership (inside the box and outside the sphere of the same radius).
/// Planted bug, seen failing: the mesh's crossings paired the wrong way round (a crossing
/// along the outward normal taken as entering), and rays straight down into the bite
/// stopped at the box's top face instead of the bite's floor.
#[test]
fn a_mesh_is_a_csg_difference_child() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let mesh = b.mesh(tessellated_sphere(0.6, 48, 96, false));
    let cube = b.part(
        Shape::Box {
            min: DVec3::splat(-1.0),
            max: DVec3::splat(1.0),
        },
        DMat4::IDENTITY,
        m,
    );
    let bite = b.part(
        Shape::Mesh {
            mesh,
            smooth: false,
        },
        DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0)),
        m,
    );
    b.csg(CsgOp::Difference, vec![cube, bite], m);
    let scene = prepare(b);
    // The faceted ball lies within r·(1 − cos(π/48)) of the true sphere, about 1.3e-3.
    let facet = 0.6 * (1.0 - (std::f32::consts::PI / 48.0).cos()) + 1e-4;
    let mut rng = Rng(11);
    for _ in 0..400 {
        let x = rng.range(-0.95, 0.95);
        let z = rng.range(-0.95, 0.95);
        let origin = Vec3A::new(x, 3.0, z);
        let (t, normal) = hit_t(&scene, origin, Vec3A::NEG_Y).expect("the box is below");
        let r2 = x * x + z * z;
        let expected = if r2 < 0.6 * 0.6 {
            // The bite's floor: the lower half of the sphere centred at y = 1.
            3.0 - (1.0 - (0.36 - r2).sqrt())
        } else {
            2.0
        };
        let edge = (r2.sqrt() - 0.6).abs() < 0.02;
        if !edge {
            assert!(
                (t - expected).abs() < facet * 3.0,
                "at ({x}, {z}): t {t}, expected {expected}"
            );
            if r2 < 0.6 * 0.6 {
                // The subtracted surface faces into the bite: up and inwards.
                assert!(normal.y > 0.0, "at ({x}, {z}): normal {normal}");
            }
        }
    }
}

/// Vertex normals interpolated by barycentrics on a smooth mesh; the face normal with
/// `smooth false`, and where the file has none. Worked by hand: the triangle (0,0,0),
/// (1,0,0), (0,1,0) facing +z, with vertex normals +z, +x and +y; the ray down -z through
/// (0.25, 0.5) has weights 0.25 (second corner) and 0.5 (third), so the normal is
/// normalize(0.25·z + 0.25·x + 0.5·y).
/// Planted bug, seen failing: the weights of the second and third corners swapped.
#[test]
fn smooth_meshes_interpolate_vertex_normals_and_others_use_the_face() {
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let normals = vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let triangles = vec![[0, 1, 2]];
    let cases = [
        (
            normals.clone(),
            true,
            Vec3A::new(0.25, 0.5, 0.25).normalize(),
        ),
        (normals, false, Vec3A::Z),
        (Vec::new(), true, Vec3A::Z),
    ];
    for (vertex_normals, smooth, expected) in cases {
        let mut b = SceneBuilder::new();
        let m = b.material(matte(0.5, 0.5, 0.5));
        let mesh = b.mesh(Mesh::new(
            "t.obj".into(),
            positions.clone(),
            vertex_normals.clone(),
            triangles.clone(),
        ));
        b.add(Shape::Mesh { mesh, smooth }, DMat4::IDENTITY, m);
        let scene = prepare(b);
        let ray = Ray::new(Vec3A::new(0.25, 0.5, 2.0), Vec3A::NEG_Z);
        let mut scratch = Scratch::default();
        let hit = scene
            .intersect(&ray, 0.0, f32::INFINITY, &mut scratch)
            .expect("the ray hits the triangle");
        let surface = scene.surface(&ray, &hit);
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert_eq!(surface.geometric_normal, Vec3A::Z);
        assert!(
            (surface.shading_normal - expected).length() < 1e-6,
            "smooth {smooth}, normals {}: {} instead of {expected}",
            !vertex_normals.is_empty(),
            surface.shading_normal
        );
    }
}

/// A thousand instances of one mesh hold one copy of its triangles and one BVH: the
/// prepared scene counts one mesh, and every instance shares it.
/// Planted bug, seen failing: each instance prepared its own copy of the mesh.
#[test]
fn a_thousand_instances_share_one_mesh() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let source = tessellated_sphere(0.4, 32, 64, false);
    let triangles = source.triangles.len();
    let mesh = b.mesh(source);
    for i in 0..1_000 {
        let at = DVec3::new(f64::from(i % 40), 0.0, f64::from(i / 40));
        b.add(
            Shape::Mesh { mesh, smooth: true },
            DMat4::from_translation(at),
            m,
        );
    }
    let scene = prepare(b);
    assert_eq!(scene.object_count(), 1_000);
    assert_eq!(scene.mesh_count(), 1);
    assert_eq!(scene.mesh_triangle_count(), triangles);
    let mut shared = None;
    for item in &scene.bounded {
        let crate::scene::Item::Shape(leaf) = item else {
            panic!("an instance is not a shape item");
        };
        let crate::shapes::Geometry::Mesh(instance) = &leaf.geometry else {
            panic!("an instance is not a mesh");
        };
        let mesh = instance.mesh();
        let first = shared.get_or_insert_with(|| Arc::clone(mesh));
        assert!(Arc::ptr_eq(first, mesh), "an instance has its own copy");
    }
    let shared = shared.expect("instances");
    // The scene's items hold 1,000 references and the local one is the last.
    assert_eq!(Arc::strong_count(&shared), 1_001);
    // Every instance is found by rays: the one at (13, 0, 7) is hit from above at 0.4 off
    // its centre's height.
    let origin = Vec3A::new(13.0, 5.0, 7.0);
    let (t, _) = hit_t(&scene, origin, Vec3A::NEG_Y).expect("an instance below");
    assert!((t - 4.6).abs() < 1e-3, "{t}");
}

/// Filtered shadows through a closed mesh filter at each surface it crosses, as through the
/// analytic solid of the same shape: a shadow ray through a tinted cube of twelve triangles
/// crosses two surfaces and keeps `kt²`, exactly as through `box`.
/// Planted bug, seen failing: the mesh walk stopped at the first triangle it found rather
/// than the nearest, so the shadow ray's first crossing was the cube's far face and the
/// near one was never counted (one blocker instead of two).
#[test]
fn filtered_shadows_cross_a_mesh_solid_at_each_surface() {
    let corners: Vec<[f32; 3]> = (0..8)
        .map(|i| {
            [
                (i & 1) as f32 * 2.0 - 1.0,
                ((i >> 1) & 1) as f32 * 2.0 - 1.0,
                ((i >> 2) & 1) as f32 * 2.0 - 1.0,
            ]
        })
        .collect();
    // Two triangles per face of the cube, wound so that their normals point out.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles: Vec<[u32; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let cube = Mesh::new("cube.obj".into(), corners, Vec::new(), triangles);
    assert!(cube.solid);
    let tint = Material {
        transmissive: Color::new(0.5, 0.8, 0.9),
        ..matte(0.1, 0.1, 0.1)
    };
    let mut results = Vec::new();
    for meshed in [false, true] {
        let mut b = SceneBuilder::new();
        let m = b.material(tint.clone());
        let shape = if meshed {
            Shape::Mesh {
                mesh: b.mesh(cube.clone()),
                smooth: false,
            }
        } else {
            Shape::Box {
                min: DVec3::splat(-1.0),
                max: DVec3::splat(1.0),
            }
        };
        b.add(shape, DMat4::from_translation(DVec3::new(0.0, 2.0, 0.0)), m);
        let scene = prepare(b);
        let ray = Ray::new(Vec3A::new(0.3, 0.0, -0.2), Vec3A::Y);
        let mut scratch = Scratch::default();
        results.push(scene.filter_shadow(&ray, 1e-4, 10.0, &mut scratch));
    }
    let expected = crate::query::Shadow::Filtered {
        transmittance: Vec3A::new(0.25, 0.64, 0.81),
        blockers: 2,
    };
    for (result, what) in results.iter().zip(["box", "mesh"]) {
        match (result, &expected) {
            (
                crate::query::Shadow::Filtered {
                    transmittance,
                    blockers,
                },
                crate::query::Shadow::Filtered {
                    transmittance: want,
                    blockers: want_blockers,
                },
            ) => {
                assert_eq!(blockers, want_blockers, "{what}");
                assert!(
                    (*transmittance - *want).abs().max_element() < 1e-6,
                    "{what}: {transmittance}"
                );
            }
            _ => panic!("{what}: {result:?}"),
        }
    }
}

/// A mesh keeps the binned SAH's tree at any size (its triangles render faster through it):
/// with the Morton top forced on for every build on this thread, a mesh's triangles still
/// come in the binned SAH's order, while a scene-level BVH over the same boxes changes.
#[test]
fn meshes_keep_the_binned_sah_tree() {
    use whitted_bvh::testing::with_morton_top;
    use whitted_bvh::Bvh;
    let mesh = terrain(40, &mut Rng(17));
    let sah = PreparedMesh::new(&mesh);
    let forced = with_morton_top(|| PreparedMesh::new(&mesh));
    let corners: Vec<Vec3A> = (0..sah.triangles.len())
        .filter_map(|i| sah.triangles.get(i))
        .map(|t| Vec3A::from(t.a))
        .collect();
    let aabbs: Vec<obvhs::aabb::Aabb> = corners
        .iter()
        .map(|&a| obvhs::aabb::Aabb::new(a, a + 1.0))
        .collect();
    let (_, morton_order) = with_morton_top(|| Bvh::build(&aabbs));
    let (_, sah_order) = Bvh::build(&aabbs);
    assert_eq!(forced.triangles, sah.triangles);
    assert_ne!(morton_order, sah_order, "the Morton top was not forced");
}

/// Leaves tested four triangles at a time (`four.rs`) against the walk that shows them one
/// by one: the same triangle and the same `t`, bit for bit, for awkward rays on two meshes
/// (a sphere, a jagged terrain), at the origin and far from it, huge and tiny.
/// Planted bugs, seen failing: a cross product with its terms swapped
/// (`self.z * b.y - self.y * b.z`), and the hits taken lowest bit first.
#[test]
fn four_triangles_at_a_time_find_what_one_at_a_time_finds() {
    let mut rng = Rng(31);
    let mut meshes = vec![
        tessellated_sphere(1.5, 24, 48, false),
        terrain(40, &mut rng),
    ];
    // Where rounding is coarse: the terrain far away, and scaled huge and tiny.
    for (offset, scale) in [(1e5f32, 1.0f32), (0.0, 1e4), (0.0, 1e-4)] {
        let mut far = terrain(20, &mut rng);
        for p in &mut far.positions {
            *p = p.map(|c| c * scale + offset);
        }
        meshes.push(far);
    }
    let mut compared = 0;
    let mut hits = 0;
    for mesh in &meshes {
        let prepared = PreparedMesh::new(mesh);
        assert!(prepared.bvh.is_some(), "{} has no BVH", mesh.file);
        for ray in &awkward_rays(mesh, &mut rng, 3_000) {
            for (tmin, tmax) in [(0.0, f32::INFINITY), (1e-3, 5.0), (f32::NEG_INFINITY, 2.0)] {
                let grouped = prepared.first_hit(ray, tmin, tmax);
                let single = prepared.first_hit_one_at_a_time(ray, tmin, tmax);
                let bits = |h: Option<(f32, u32)>| h.map(|(t, part)| (t.to_bits(), part));
                assert_eq!(
                    bits(grouped),
                    bits(single),
                    "{}: ray {ray:?} in ({tmin}, {tmax})",
                    mesh.file
                );
                compared += 1;
                hits += usize::from(single.is_some());
            }
        }
    }
    // The comparison means something only if many queries hit.
    assert!(hits * 4 > compared, "{hits} hits in {compared} queries");
}
