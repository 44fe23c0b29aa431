//! The position of mimalloc's purge-delay option that `fem_forms::allocator` sets is
//! the one mimalloc reads `MIMALLOC_PURGE_DELAY` into.

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[test]
fn purge_delay_position_is_the_one_the_environment_sets() {
    const CHILD: &str = "FEM_FORMS_ALLOCATOR_CHILD";
    if std::env::var_os(CHILD).is_some() {
        // the child: mimalloc read MIMALLOC_PURGE_DELAY=1234 at start-up
        let value = unsafe { libmimalloc_sys::mi_option_get(fem_forms::allocator::PURGE_DELAY) };
        assert_eq!(
            value,
            1234,
            "option {} is not the purge delay",
            fem_forms::allocator::PURGE_DELAY
        );
        fem_forms::allocator::retain_freed_memory();
        let value = unsafe { libmimalloc_sys::mi_option_get(fem_forms::allocator::PURGE_DELAY) };
        assert_eq!(value, -1, "retain_freed_memory did not disable purging");
        return;
    }
    let status = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "purge_delay_position_is_the_one_the_environment_sets",
            "--exact",
            "--nocapture",
        ])
        .env(CHILD, "1")
        .env("MIMALLOC_PURGE_DELAY", "1234")
        .status()
        .unwrap();
    assert!(status.success(), "the child test failed: {status}");
}
