//! Test helpers: seeded box sets for the BVH's own tests, and a switch that lets the tests
//! of crates built on the BVH (the tracer's) reach the Morton-topped build with small scenes.
//!
//! Only compiled for this crate's tests or with the `testing` feature, which other crates
//! enable in their dev-dependencies, so none of it is in a release build.

use std::cell::Cell;

use glam::Vec3A;
use obvhs::aabb::Aabb;

use crate::binary::MORTON_MIN_PRIMITIVES;

thread_local! {
    /// What the builds on this thread take for [`MORTON_MIN_PRIMITIVES`]: lowered by
    /// [`with_morton_top`], read through `binary::morton_min_primitives`.
    pub(crate) static MORTON_MIN: Cell<usize> = const { Cell::new(MORTON_MIN_PRIMITIVES) };
}

/// Runs `f` with every BVH built on this thread given a Morton-ordered top (scenes in tests
/// are far below the size that gets one), so tests can walk, render and compare such trees.
pub fn with_morton_top<R>(f: impl FnOnce() -> R) -> R {
    MORTON_MIN.set(2);
    let result = f();
    MORTON_MIN.set(MORTON_MIN_PRIMITIVES);
    result
}

/// A small xorshift generator, so the inputs are the same on every run (the BVH tests
/// of `walk` and `binary` use it too).
pub struct Random(pub u32);

impl Random {
    pub fn next_u32(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        self.0
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }

    pub fn vec(&mut self) -> Vec3A {
        Vec3A::new(self.unit(), self.unit(), self.unit())
    }

    /// `n` boxes of random sizes in a 40-unit cube, overlapping.
    pub fn cloud(&mut self, n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = self.vec() * 40.0;
                let half = self.vec() * 1.5 + 0.05;
                Aabb::new(c - half, c + half)
            })
            .collect()
    }
}

fn boxes_at(centers: impl Iterator<Item = Vec3A>, half: f32) -> Vec<Aabb> {
    centers.map(|c| Aabb::new(c - half, c + half)).collect()
}

/// Box sets of every kind the scenes make: random clouds of several sizes, coincident
/// boxes, regular grids and rows, a handful of boxes, huge and tiny coordinates, and
/// flat boxes.
pub fn inputs() -> Vec<(String, Vec<Aabb>)> {
    let mut random = Random(0x2545_f491);
    let mut out = Vec::new();
    for n in [1usize, 2, 3, 4, 5, 7, 8, 9, 17, 100, 1000, 5000] {
        let cloud = (0..n)
            .map(|_| {
                let c = random.vec() * 40.0;
                let half = random.vec() * 1.5 + 0.05;
                Aabb::new(c - half, c + half)
            })
            .collect();
        out.push((format!("cloud of {n}"), cloud));
    }
    for n in [2usize, 3, 9, 50, 2000] {
        out.push((
            format!("{n} coincident"),
            boxes_at((0..n).map(|_| Vec3A::ONE), 0.5),
        ));
    }
    let grid = boxes_at(
        (0..40 * 40).map(|i| Vec3A::new((i % 40) as f32, 0.0, (i / 40) as f32)),
        0.4,
    );
    out.push(("grid 40x40".into(), grid));
    let cube = boxes_at(
        (0..12 * 12 * 12)
            .map(|i| Vec3A::new((i % 12) as f32, (i / 12 % 12) as f32, (i / 144) as f32) * 2.0),
        1.0,
    );
    out.push(("touching cubes".into(), cube));
    let row = boxes_at((0..777).map(|i| Vec3A::new(i as f32 * 3.0, 0.0, 0.0)), 1.0);
    out.push(("row".into(), row));
    for (name, scale) in [
        ("huge", 1e30f32),
        ("large", 1e15),
        ("tiny", 1e-30),
        ("small", 1e-12),
    ] {
        let scattered = (0..600)
            .map(|_| {
                let c = (random.vec() - 0.5) * scale;
                Aabb::new(
                    c - random.vec() * scale * 0.01,
                    c + random.vec() * scale * 0.01,
                )
            })
            .collect();
        out.push((format!("{name} coordinates"), scattered));
    }
    let mixed = vec![
        Aabb::new(Vec3A::splat(-1e30), Vec3A::splat(1e30)),
        Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
        Aabb::new(Vec3A::splat(1e-20), Vec3A::splat(2e-20)),
        Aabb::new(Vec3A::new(5.0, 0.0, 0.0), Vec3A::new(6.0, 0.0, 0.0)),
    ];
    out.push(("huge and tiny together".into(), mixed));
    let flat = (0..300)
        .map(|_| {
            let c = random.vec() * 10.0;
            Aabb::new(
                Vec3A::new(c.x, 0.0, c.z),
                Vec3A::new(c.x + 0.5, 0.0, c.z + 0.5),
            )
        })
        .collect();
    out.push(("flat".into(), flat));
    let nested = (1..200)
        .map(|i| Aabb::new(Vec3A::splat(-(i as f32)), Vec3A::splat(i as f32)))
        .collect();
    out.push(("nested".into(), nested));
    out
}
