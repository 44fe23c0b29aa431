//! Settings of the mimalloc allocator that the CLI and the benchmarks install.

/// mimalloc's `mi_option_purge_delay` (its position in `mi_option_e` of the vendored
/// v2 and v3 headers; the Rust bindings do not name it).
pub const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Keeps freed memory mapped instead of returning it to the kernel after 10 ms.
///
/// The nested solves free and reallocate vectors and factors of hundreds of megabytes
/// per level and Newton iteration; on these machines each return costs a round of page
/// faults and kernel page zeroing on the next use (measured: 0.8–1.3 s of system time
/// in a 2 s membrane solve at 524k triangles, 0.1 s with this setting). Only effective
/// when mimalloc is the global allocator. The option is set only if it holds a delay
/// (0 to 10⁵ ms), so an option table of another layout is most likely left untouched;
/// `tests/allocator.rs` checks the position against `MIMALLOC_PURGE_DELAY`.
pub fn retain_freed_memory() {
    // SAFETY: mi_option_get/mi_option_set only read and write mimalloc's option table.
    unsafe {
        if (0..=100_000).contains(&libmimalloc_sys::mi_option_get(PURGE_DELAY)) {
            libmimalloc_sys::mi_option_set(PURGE_DELAY, -1);
        }
    }
}

/// Asks the kernel not to back this process's memory with transparent huge pages.
///
/// These virtual machines run with transparent huge pages `always` and defragmentation
/// on `madvise`: a first touch of a 2 MiB page costs about 2 ms of system time here (a
/// zeroing, often a compaction), and the solves touch gigabytes at 1M unknowns. Measured
/// on `membrane-radial --mesh-size 1024` (2026-11-30): p1-nodal 3.4–5.1 s of system time
/// with huge pages against 1.6–1.7 s without, p1-p0 (direct) 7.2 s against 2.4 s; user
/// time unchanged. Returns whether the kernel accepted the request (`PR_SET_THP_DISABLE`,
/// Linux ≥ 3.15); elsewhere it does nothing and returns `false`.
pub fn small_pages() -> bool {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0) only sets a flag of this process.
        unsafe { libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0) == 0 }
    }
    #[cfg(not(target_os = "linux"))]
    {
        false
    }
}
