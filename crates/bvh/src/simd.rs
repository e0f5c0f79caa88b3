//! The BVH walk's child test on AVX2 and AVX-512, chosen at run time so that one binary
//! runs on any x86-64 and uses what the CPU has.
//!
//! Each lane does exactly the baseline's arithmetic (subtract, multiply, max, min, compare,
//! in the same order, with the same operand first, so NaN and ±0 come out alike), so the
//! touched mask, and with it every visit and every hit, is bit for bit the baseline's. No
//! FMA: a fused `(p − o)·inv` would round once where the baseline rounds twice and could
//! move a box edge by an ulp. The rest of the walk is the baseline's code, compiled here
//! for the newer instruction sets, with the visitor (the shape tests) inlined into it.

// Intrinsics that read memory, and functions compiled for CPU features, are unsafe to call;
// each call below says why it is sound. Nothing else in the library crates is unsafe.
#![allow(unsafe_code)]

use glam::UVec2;

use crate::ray::Ray;
use crate::walk::{Bvh, PacketEntry, Step, TraversalPath, PACKET};

/// A SIMD child test this CPU was found to run: only [`SimdPath::detect`] makes one, so
/// holding one is the proof that its walk's instructions exist here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SimdPath(Isa);

/// The instruction sets of the SIMD walks (none off x86-64, where no `SimdPath` exists).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Isa {
    /// AVX2, with the bit instructions of its generation (`bmi1`, `lzcnt`, `popcnt`).
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// AVX2's, and AVX-512 F and VL.
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl SimdPath {
    /// `path` when this CPU, asked at run time, has every feature its walk is compiled
    /// for; `None` for the baseline, which needs no proof.
    pub(crate) fn detect(path: TraversalPath) -> Option<SimdPath> {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let avx2 = has!("avx2") && has!("bmi1") && has!("lzcnt") && has!("popcnt");
            match path {
                TraversalPath::Baseline => None,
                TraversalPath::Avx2 => avx2.then_some(SimdPath(Isa::Avx2)),
                TraversalPath::Avx512 => {
                    (avx2 && has!("avx512f") && has!("avx512vl")).then_some(SimdPath(Isa::Avx512))
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = path;
            None
        }
    }

    pub(crate) fn path(self) -> TraversalPath {
        match self.0 {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => TraversalPath::Avx2,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => TraversalPath::Avx512,
        }
    }
}

/// [`Bvh::traverse_groups`] with a SIMD child test.
#[inline]
pub(crate) fn traverse(
    simd: SimdPath,
    bvh: &Bvh,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    stack: &mut Vec<UVec2>,
    visit: impl FnMut(u32, u32, f32) -> Step,
) {
    // Off x86-64 no `SimdPath` exists, so there is nothing to call.
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (bvh, ray, tmin, tmax, stack, visit);
    // SAFETY (both calls): `simd` exists only once `SimdPath::detect` has seen every
    // feature the walk is compiled for.
    match simd.0 {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::walk_avx2(bvh, ray, tmin, tmax, stack, visit) },
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::walk_avx512(bvh, ray, tmin, tmax, stack, visit) },
    }
}

/// [`Bvh::traverse_packet`], after its checks, with a SIMD child test.
#[inline]
pub(crate) fn traverse_packet(
    simd: SimdPath,
    bvh: &Bvh,
    rays: &[Ray],
    tmin: f32,
    tmax: &mut [f32; PACKET],
    stack: &mut Vec<PacketEntry>,
    visit: impl FnMut(usize, u32, f32) -> Step,
) {
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (bvh, rays, tmin, tmax, stack, visit);
    // SAFETY (both calls): as in `traverse`.
    match simd.0 {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::walk_packet_avx2(bvh, rays, tmin, tmax, stack, visit) },
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::walk_packet_avx512(bvh, rays, tmin, tmax, stack, visit) },
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::{
        __m256, _mm256_cmp_ps, _mm256_cmp_ps_mask, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_sub_ps, _CMP_LE_OS,
    };

    use glam::UVec2;

    use crate::bounds::inverse_direction;
    use crate::ray::Ray;
    use crate::walk::{Bvh, ChildTest, PacketEntry, PerRayTest, Step, WideNode, PACKET};

    /// The features the AVX2 walk is compiled for (`bmi1` and `lzcnt` give the walk's bit
    /// scans one instruction each).
    #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
    pub(super) fn walk_avx2(
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        visit: impl FnMut(u32, u32, f32) -> Step,
    ) {
        bvh.traverse_with(&EightLanes::new(ray, tmin), ray, tmax, stack, visit);
    }

    #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
    pub(super) fn walk_packet_avx2(
        bvh: &Bvh,
        rays: &[Ray],
        tmin: f32,
        tmax: &mut [f32; PACKET],
        stack: &mut Vec<PacketEntry>,
        visit: impl FnMut(usize, u32, f32) -> Step,
    ) {
        let test = PerRayTest::new(rays, |ray| EightLanes::new(ray, tmin));
        bvh.traverse_packet_with(&test, rays, tmax, stack, visit);
    }

    #[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,lzcnt,popcnt")]
    pub(super) fn walk_avx512(
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        visit: impl FnMut(u32, u32, f32) -> Step,
    ) {
        let query = MaskedLanes(EightLanes::new(ray, tmin));
        bvh.traverse_with(&query, ray, tmax, stack, visit);
    }

    #[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,lzcnt,popcnt")]
    pub(super) fn walk_packet_avx512(
        bvh: &Bvh,
        rays: &[Ray],
        tmin: f32,
        tmax: &mut [f32; PACKET],
        stack: &mut Vec<PacketEntry>,
        visit: impl FnMut(usize, u32, f32) -> Step,
    ) {
        let test = PerRayTest::new(rays, |ray| MaskedLanes(EightLanes::new(ray, tmin)));
        bvh.traverse_packet_with(&test, rays, tmax, stack, visit);
    }

    /// The ray broadcast to eight lanes once per query.
    pub(super) struct EightLanes {
        origin: [__m256; 3],
        inv_direction: [__m256; 3],
        tmin: __m256,
    }

    impl EightLanes {
        #[target_feature(enable = "avx2")]
        #[inline]
        fn new(ray: &Ray, tmin: f32) -> EightLanes {
            let inv = inverse_direction(ray.direction);
            EightLanes {
                origin: [
                    _mm256_set1_ps(ray.origin.x),
                    _mm256_set1_ps(ray.origin.y),
                    _mm256_set1_ps(ray.origin.z),
                ],
                inv_direction: [
                    _mm256_set1_ps(inv.x),
                    _mm256_set1_ps(inv.y),
                    _mm256_set1_ps(inv.z),
                ],
                tmin: _mm256_set1_ps(tmin),
            }
        }

        /// The baseline's `NodeQuery::touched` up to the compare, eight lanes at a time:
        /// where the segment enters and leaves each child's box.
        #[target_feature(enable = "avx2")]
        #[inline]
        fn enter_exit<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> (__m256, __m256) {
            let rows = &node.planes.rows;
            let mut enter = self.tmin;
            let mut exit = _mm256_set1_ps(tmax);
            for axis in 0..3 {
                let backwards = usize::from(OCT & (4 >> axis) == 0);
                let near = &rows[axis * 2 + backwards];
                let far = &rows[axis * 2 + 1 - backwards];
                // SAFETY: each row is eight readable f32s; the load needs no alignment.
                let (near, far) = unsafe {
                    (
                        _mm256_loadu_ps(near.as_ptr()),
                        _mm256_loadu_ps(far.as_ptr()),
                    )
                };
                let t_near = _mm256_mul_ps(
                    _mm256_sub_ps(near, self.origin[axis]),
                    self.inv_direction[axis],
                );
                let t_far = _mm256_mul_ps(
                    _mm256_sub_ps(far, self.origin[axis]),
                    self.inv_direction[axis],
                );
                // Operands in glam's order (`enter.max(t_near)` is `maxps enter, t_near`).
                enter = _mm256_max_ps(enter, t_near);
                exit = _mm256_min_ps(exit, t_far);
            }
            (enter, exit)
        }

        /// The touched children: glam's `cmple` is `cmpleps`, predicate LE_OS, so a NaN
        /// lane is not touched.
        #[target_feature(enable = "avx2")]
        #[inline]
        fn touched8<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
            let (enter, exit) = self.enter_exit::<OCT>(node, tmax);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(enter, exit)) as u32
        }

        /// [`EightLanes::touched8`] with AVX-512's compare straight into a mask register.
        #[target_feature(enable = "avx512f,avx512vl")]
        #[inline]
        fn touched8_mask<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
            let (enter, exit) = self.enter_exit::<OCT>(node, tmax);
            u32::from(_mm256_cmp_ps_mask::<_CMP_LE_OS>(enter, exit))
        }
    }

    impl ChildTest for EightLanes {
        #[inline(always)]
        fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
            // SAFETY: `EightLanes::new` is compiled for AVX2 and only called from the AVX2
            // and AVX-512 walks, which run only where `SimdPath::detect` found AVX2.
            unsafe { self.touched8::<OCT>(node, tmax) }
        }
    }

    /// The AVX-512 walk's query: [`EightLanes`] whose compare writes a mask register.
    pub(super) struct MaskedLanes(EightLanes);

    impl ChildTest for MaskedLanes {
        #[inline(always)]
        fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
            // SAFETY: a `MaskedLanes` is made only in the AVX-512 walks, which run only
            // where `SimdPath::detect` found AVX-512 F and VL.
            unsafe { self.0.touched8_mask::<OCT>(node, tmax) }
        }
    }
}
