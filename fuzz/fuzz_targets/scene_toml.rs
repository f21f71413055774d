#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(src) = std::str::from_utf8(data) {
        let _ = raylab_loader::parse_scene_str(src, std::path::Path::new("fuzz.toml"), &raylab_loader::files::Resolver::Embedded);
    }
});
