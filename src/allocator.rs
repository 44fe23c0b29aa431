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
