#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = raylab_lab::rayfile::read(&raylab_fuzz::file("r.rays", data));
});
