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
// each call below says why it is sound. Nothing else in the tracer is unsafe.
#![allow(unsafe_code)]

use glam::UVec2;

use crate::bvh::{Bvh, PacketEntry, Step, PACKET};
use crate::ray::Ray;

/// An uninhabited type: off x86-64 no CPU-feature proof can exist.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Never {}

/// Proof that this CPU has the features the AVX2 walk is compiled for: only
/// [`Avx2::detect`] makes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Avx2 {
    #[cfg(target_arch = "x86_64")]
    _private: (),
    #[cfg(not(target_arch = "x86_64"))]
    never: Never,
}

/// Proof that this CPU has the features the AVX-512 walk is compiled for: only
/// [`Avx512::detect`] makes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Avx512 {
    #[cfg(target_arch = "x86_64")]
    _private: (),
    #[cfg(not(target_arch = "x86_64"))]
    never: Never,
}

impl Avx2 {
    /// `Some` when the CPU, asked at run time, has AVX2 and the bit instructions the walk
    /// is compiled with.
    pub(crate) fn detect() -> Option<Avx2> {
        #[cfg(target_arch = "x86_64")]
        {
            let present = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("bmi1")
                && std::arch::is_x86_feature_detected!("lzcnt")
                && std::arch::is_x86_feature_detected!("popcnt");
            present.then_some(Avx2 { _private: () })
        }
        #[cfg(not(target_arch = "x86_64"))]
        None
    }
}

impl Avx512 {
    /// `Some` when the CPU, asked at run time, has AVX-512 F and VL besides what the AVX2
    /// walk needs.
    pub(crate) fn detect() -> Option<Avx512> {
        #[cfg(target_arch = "x86_64")]
        {
            let present = Avx2::detect().is_some()
                && std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl");
            present.then_some(Avx512 { _private: () })
        }
        #[cfg(not(target_arch = "x86_64"))]
        None
    }
}

/// [`Bvh::traverse`] with the 8-lane child test.
#[inline]
pub(crate) fn traverse_avx2(
    avx2: Avx2,
    bvh: &Bvh,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    stack: &mut Vec<UVec2>,
    visit: impl FnMut(u32, f32) -> Step,
) {
    #[cfg(target_arch = "x86_64")]
    {
        let Avx2 { _private: () } = avx2;
        // SAFETY: an `Avx2` exists only once `Avx2::detect` has seen every feature that
        // `x86::walk_avx2` is compiled for.
        unsafe { x86::walk_avx2(bvh, ray, tmin, tmax, stack, visit) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (bvh, ray, tmin, tmax, stack, visit);
        match avx2.never {}
    }
}

/// [`Bvh::traverse`] with the AVX-512 child test.
#[inline]
pub(crate) fn traverse_avx512(
    avx512: Avx512,
    bvh: &Bvh,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    stack: &mut Vec<UVec2>,
    visit: impl FnMut(u32, f32) -> Step,
) {
    #[cfg(target_arch = "x86_64")]
    {
        let Avx512 { _private: () } = avx512;
        // SAFETY: an `Avx512` exists only once `Avx512::detect` has seen every feature
        // that `x86::walk_avx512` is compiled for.
        unsafe { x86::walk_avx512(bvh, ray, tmin, tmax, stack, visit) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (bvh, ray, tmin, tmax, stack, visit);
        match avx512.never {}
    }
}

/// [`Bvh::traverse_packet`] (after its checks) with the 8-lane child test.
#[inline]
pub(crate) fn traverse_packet_avx2(
    avx2: Avx2,
    bvh: &Bvh,
    rays: &[Ray],
    tmin: f32,
    tmax: &mut [f32; PACKET],
    stack: &mut Vec<PacketEntry>,
    visit: impl FnMut(usize, u32, f32) -> Step,
) {
    #[cfg(target_arch = "x86_64")]
    {
        let Avx2 { _private: () } = avx2;
        // SAFETY: as in `traverse_avx2`.
        unsafe { x86::walk_packet_avx2(bvh, rays, tmin, tmax, stack, visit) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (bvh, rays, tmin, tmax, stack, visit);
        match avx2.never {}
    }
}

/// [`Bvh::traverse_packet`] (after its checks) with the AVX-512 child test.
#[inline]
pub(crate) fn traverse_packet_avx512(
    avx512: Avx512,
    bvh: &Bvh,
    rays: &[Ray],
    tmin: f32,
    tmax: &mut [f32; PACKET],
    stack: &mut Vec<PacketEntry>,
    visit: impl FnMut(usize, u32, f32) -> Step,
) {
    #[cfg(target_arch = "x86_64")]
    {
        let Avx512 { _private: () } = avx512;
        // SAFETY: as in `traverse_avx512`.
        unsafe { x86::walk_packet_avx512(bvh, rays, tmin, tmax, stack, visit) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (bvh, rays, tmin, tmax, stack, visit);
        match avx512.never {}
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
    use crate::bvh::{Bvh, ChildTest, PacketEntry, PerRayTest, Step, WideNode, PACKET};
    use crate::ray::Ray;

    /// The features the AVX2 walk is compiled for (`bmi1` and `lzcnt` give the walk's bit
    /// scans one instruction each).
    #[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
    pub(super) fn walk_avx2(
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        visit: impl FnMut(u32, f32) -> Step,
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
        visit: impl FnMut(u32, f32) -> Step,
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
            // and AVX-512 walks, which run only where `Avx2::detect` found it.
            unsafe { self.touched8::<OCT>(node, tmax) }
        }
    }

    /// The AVX-512 walk's query: [`EightLanes`] whose compare writes a mask register.
    pub(super) struct MaskedLanes(EightLanes);

    impl ChildTest for MaskedLanes {
        #[inline(always)]
        fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
            // SAFETY: a `MaskedLanes` is made only in the AVX-512 walks, which run only
            // where `Avx512::detect` found AVX-512 F and VL.
            unsafe { self.0.touched8_mask::<OCT>(node, tmax) }
        }
    }
}
