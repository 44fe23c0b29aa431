//! `fem_forms::allocator::keep_freed_memory`: a large block freed and allocated again
//! is served from memory the process keeps, without a new round of page faults (glibc's
//! default unmaps it on free and faults every page in again). Runs without the test
//! harness, on the main thread, as the CLI does.

/// Minor page faults of this process so far.
fn minor_faults() -> i64 {
    // SAFETY: getrusage writes the struct it is given.
    unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        assert_eq!(libc::getrusage(libc::RUSAGE_SELF, &mut usage), 0);
        usage.ru_minflt
    }
}

fn main() {
    if !cfg!(all(target_os = "linux", target_env = "gnu")) {
        println!("allocator: not glibc, keep_freed_memory does nothing; skipped");
        return;
    }
    assert!(
        fem_forms::allocator::keep_freed_memory(),
        "glibc refused the settings"
    );
    const BYTES: usize = 256 << 20;
    const PAGES: i64 = (BYTES / 4096) as i64;
    let touch = || {
        let mut block = vec![1u8; BYTES];
        for i in (0..BYTES).step_by(4096) {
            block[i] = 2;
        }
        std::hint::black_box(&block);
    };
    let before = minor_faults();
    touch();
    let first = minor_faults() - before;
    let before = minor_faults();
    touch();
    let second = minor_faults() - before;
    // the first touch faults every page in (huge pages: fewer faults, same test)
    assert!(first > 0, "no page faults on a fresh block");
    assert!(
        second * 20 <= first,
        "the freed block was not kept: {second} page faults on reuse, {first} on first use ({PAGES} pages)"
    );
    println!("allocator: {first} page faults on first use, {second} on reuse");
}
