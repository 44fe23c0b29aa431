//! Settings of the system allocator (glibc's malloc) that the CLI and the benchmarks apply
//! at start-up.

/// Keeps freed memory in the process for the next allocation instead of returning it to
/// the kernel; returns whether the C library accepted the settings (glibc's `mallopt`;
/// elsewhere it does nothing and returns `false`).
///
/// The nested solves free and reallocate vectors and matrices of hundreds of megabytes
/// per level and Newton iteration. By default glibc serves each allocation above 32 MiB
/// (less before its threshold adapts) with a fresh `mmap` and unmaps it on free, so every
/// reuse costs a round of page faults and kernel page zeroing (measured: 0.8–1.3 s of
/// system time in a 2 s membrane solve at 524k triangles). Here every allocation comes
/// from the heap (`M_MMAP_MAX = 0`), the heap is never trimmed (`M_TRIM_THRESHOLD`), and
/// all threads share one arena (`M_ARENA_MAX = 1`: the finest level is built on a second
/// thread and freed on the first). Measured against mimalloc with its purging off (the
/// allocator before, 2026-12-01, `membrane-radial --mesh-size 1024`, runs interleaved):
/// p1-nodal peak 905–961 MB against 980–984 MB at the same speed; p1-p0 4.86 s and
/// 2.62 GB against 5.0 s and 3.0 GB; the default job 13.2 s and 710 MB against 13.8 s and
/// 910 MB. `tests/allocator.rs` checks that a freed block is reused without page faults.
pub fn keep_freed_memory() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only changes glibc's allocation parameters; called before the
        // program has threads that allocate concurrently.
        unsafe {
            libc::mallopt(libc::M_MMAP_MAX, 0) == 1
                && libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX) == 1
                && libc::mallopt(libc::M_ARENA_MAX, 1) == 1
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
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
