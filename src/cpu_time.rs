//! CPU time for `render --stats`: each render thread's own CPU time, and the process's peak
//! memory, as the kernel counts them.
//!
//! Wall-clock time on a shared machine counts whatever else ran; a thread's CPU time counts
//! only the time it spent running (`CLOCK_THREAD_CPUTIME_ID`), so rays per CPU-second is the
//! figure that compares between runs and machines under load. Blocked time (a worker
//! waiting for the last tile) is not counted in either thread's CPU time.
// The clock and resource-usage calls are libc's.
#![allow(unsafe_code)]

/// The CPU seconds the calling thread has used so far (0 if the clock cannot be read).
pub fn thread_cpu_seconds() -> f64 {
    let mut now = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `now` is a valid, writable timespec; the call writes only to it.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut now) };
    if status != 0 {
        return 0.0;
    }
    now.tv_sec as f64 + now.tv_nsec as f64 * 1e-9
}

/// The CPU seconds every thread of `pool` has used so far, summed.
pub fn pool_cpu_seconds(pool: &rayon::ThreadPool) -> f64 {
    pool.broadcast(|_| thread_cpu_seconds()).into_iter().sum()
}

/// The CPU seconds every thread of the process has used so far, user and system (0 if
/// they cannot be read): `grade --class`'s figure, whose renders use every core.
pub fn process_cpu_seconds() -> f64 {
    // SAFETY: an all-zero rusage is a valid value of the plain C struct.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `usage` is a valid, writable rusage; the call writes only to it.
    let status = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    if status != 0 {
        return 0.0;
    }
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    seconds(usage.ru_utime) + seconds(usage.ru_stime)
}

/// The process's peak resident memory so far, in KiB (`None` if it cannot be read).
pub fn peak_memory_kib() -> Option<u64> {
    // SAFETY: an all-zero rusage is a valid value of the plain C struct.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `usage` is a valid, writable rusage; the call writes only to it.
    let status = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    // Linux reports ru_maxrss in KiB.
    (status == 0).then(|| u64::try_from(usage.ru_maxrss).unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_busy_thread_uses_cpu_time_and_a_sleeping_one_does_not() {
        // Spin until the thread's clock has counted 20 ms (on a loaded machine that takes
        // longer by the wall clock, never shorter), giving up after 20 s.
        let start = thread_cpu_seconds();
        let wall = std::time::Instant::now();
        let mut x = 0u64;
        while thread_cpu_seconds() - start < 0.02 && wall.elapsed().as_secs() < 20 {
            x = std::hint::black_box(x.wrapping_mul(31).wrapping_add(7));
        }
        let busy = thread_cpu_seconds() - start;
        assert!(busy >= 0.02, "spinning for 20 s counted {busy} s");
        let elapsed = wall.elapsed().as_secs_f64();
        assert!(
            busy <= elapsed + 0.005,
            "one thread counted {busy} s of CPU in {elapsed} s"
        );
        let start = thread_cpu_seconds();
        std::thread::sleep(std::time::Duration::from_millis(50));
        let asleep = thread_cpu_seconds() - start;
        assert!(asleep < 0.02, "50 ms of sleep counted {asleep} s");
    }

    #[test]
    fn peak_memory_is_reported() {
        assert!(peak_memory_kib().is_some_and(|k| k > 0));
    }
}
