//! The program's memory allocator: mimalloc, set up for scenes written by programs.
//!
//! A million-statement scene allocates a syntax tree of hundreds of megabytes in small
//! pieces, then frees it while the scene it describes grows. On this project's machines
//! most of that run's time was the kernel handing out fresh pages; mimalloc reuses memory
//! better than the system allocator (1M literal spheres: 3.9 s -> 2.9 s). Two settings:
//! transparent huge pages are off (the `no_thp` feature), because on a machine whose memory
//! is fragmented faulting them in stalls for seconds in compaction; and freed memory goes
//! back to the system after 10 ms rather than mimalloc's default second, so that the syntax
//! tree dropped item by item during evaluation is not counted twice in the peak (1M
//! spheres: 990 MB -> 730 MB).
// The one setter mimalloc has is a C function.
#![allow(unsafe_code)]

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// `mi_option_purge_delay` in mimalloc 3's `mi_option_e` (mimalloc.h): the Rust bindings
/// name only the options mimalloc 1 and 2 share.
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Milliseconds before freed memory is returned to the system.
const PURGE_DELAY_MS: std::ffi::c_long = 10;

/// Sets the allocator's options. Call first thing in `main`, before any other thread
/// starts (mimalloc's option setters are not thread-safe).
pub fn configure() {
    // SAFETY: `mi_option_set` takes an option number and a value, touches only mimalloc's
    // option table, and is called before any other thread exists.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, PURGE_DELAY_MS) };
}
