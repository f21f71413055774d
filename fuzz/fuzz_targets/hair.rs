#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    raylab_fuzz::scene_with_file("c.hair", data, "type = \"curve\"");
});
