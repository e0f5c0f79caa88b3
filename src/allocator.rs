//! The program's memory allocator: mimalloc for small blocks, the system allocator for
//! large ones, set up for scenes written by programs.
//!
//! A million-statement scene allocates a syntax tree of hundreds of megabytes in small
//! pieces, then frees it while the scene it describes grows. On this project's machines
//! most of that run's time was the kernel handing out fresh pages; mimalloc reuses small
//! blocks better than the system allocator (1M literal spheres: 3.9 s -> 2.8 s). Large
//! blocks (the scene's arenas, the source text) stay with the system allocator: it maps
//! each on its own and grows it by remapping pages, where mimalloc copies, so a scene
//! made by a loop, whose object arena doubles its way to hundreds of megabytes, is not
//! slowed and its peak not raised by the copies (grid of 1M spheres: mimalloc alone 0.91 s
//! and 406 MB, the system allocator 0.75 s and 263 MB).
//!
//! Settings: mimalloc's transparent huge pages are off (the `no_thp` feature), because on
//! a machine whose memory is fragmented faulting them in stalls for seconds in compaction;
//! mimalloc returns freed memory after 10 ms rather than its default second, so that the
//! syntax tree dropped item by item during evaluation is not counted twice in the peak; and
//! the system allocator maps every large block rather than adapting its threshold, so that
//! growing one always remaps.
// A global allocator and the allocators' option setters are unsafe by nature.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};

use mimalloc::MiMalloc;

/// Blocks of at least this many bytes go to the system allocator.
const LARGE_BLOCK: usize = 1 << 20;

/// `mi_option_purge_delay` in mimalloc 3's `mi_option_e` (mimalloc.h): the Rust bindings
/// name only the options mimalloc 1 and 2 share.
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Milliseconds before mimalloc returns freed memory to the system.
const PURGE_DELAY_MS: std::ffi::c_long = 10;

/// Sends each block to one of two allocators by its size alone, so that `dealloc` and
/// `realloc`, which are given the block's layout, always find the allocator that made it.
struct BySize;

fn is_large(size: usize) -> bool {
    size >= LARGE_BLOCK
}

// SAFETY: every block is made and freed by the same allocator, chosen by the size in its
// layout (the same in `alloc` and `dealloc`, as GlobalAlloc's contract guarantees); a
// `realloc` across the threshold makes a new block with the other allocator, copies the
// smaller of the two sizes and frees the old block with its own.
unsafe impl GlobalAlloc for BySize {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if is_large(layout.size()) {
            unsafe { System.alloc(layout) }
        } else {
            unsafe { MiMalloc.alloc(layout) }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if is_large(layout.size()) {
            unsafe { System.alloc_zeroed(layout) }
        } else {
            unsafe { MiMalloc.alloc_zeroed(layout) }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if is_large(layout.size()) {
            unsafe { System.dealloc(ptr, layout) }
        } else {
            unsafe { MiMalloc.dealloc(ptr, layout) }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        match (is_large(layout.size()), is_large(new_size)) {
            (true, true) => unsafe { System.realloc(ptr, layout, new_size) },
            (false, false) => unsafe { MiMalloc.realloc(ptr, layout, new_size) },
            _ => {
                // SAFETY: the caller guarantees `new_size`, rounded up to the alignment, does
                // not overflow `isize`, which is all `from_size_align_unchecked` needs.
                let new_layout =
                    unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
                let new = unsafe { self.alloc(new_layout) };
                if !new.is_null() {
                    unsafe {
                        std::ptr::copy_nonoverlapping(ptr, new, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                }
                new
            }
        }
    }
}

#[global_allocator]
static GLOBAL: BySize = BySize;

/// Sets both allocators' options. Call first thing in `main`, before any other thread
/// starts (the option setters are not thread-safe).
pub fn configure() {
    // SAFETY: each call takes an option number and a value, touches only its allocator's
    // option table, and runs before any other thread exists.
    unsafe {
        libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, PURGE_DELAY_MS);
        libc::mallopt(libc::M_MMAP_THRESHOLD, LARGE_BLOCK as libc::c_int);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block keeps its bytes when `realloc` moves it across the threshold, both ways,
    /// and each allocator frees what it made (a mismatch aborts the test process).
    #[test]
    fn realloc_across_the_threshold_keeps_the_contents() {
        let small = Layout::from_size_align(1000, 8).unwrap();
        unsafe {
            let block = BySize.alloc(small);
            assert!(!block.is_null());
            for i in 0..1000 {
                *block.add(i) = (i % 251) as u8;
            }
            let large = BySize.realloc(block, small, 3 * LARGE_BLOCK);
            assert!(!large.is_null());
            for i in 0..1000 {
                assert_eq!(*large.add(i), (i % 251) as u8);
            }
            *large.add(3 * LARGE_BLOCK - 1) = 7;
            let grown = BySize.realloc(
                large,
                Layout::from_size_align(3 * LARGE_BLOCK, 8).unwrap(),
                5 * LARGE_BLOCK,
            );
            assert_eq!(*grown.add(3 * LARGE_BLOCK - 1), 7);
            assert_eq!(*grown.add(999), (999 % 251) as u8);
            let back = BySize.realloc(
                grown,
                Layout::from_size_align(5 * LARGE_BLOCK, 8).unwrap(),
                500,
            );
            for i in 0..500 {
                assert_eq!(*back.add(i), (i % 251) as u8);
            }
            BySize.dealloc(back, Layout::from_size_align(500, 8).unwrap());
        }
    }
}
