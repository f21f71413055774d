#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    raylab_fuzz::scene_with_file("p.txt", data, "type = \"bezier_patch\"\nmode = \"direct\"");
});
