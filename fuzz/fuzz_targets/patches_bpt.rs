#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    raylab_fuzz::scene_with_file("p.bpt", data, "type = \"bezier_patch\"\nsubdivisions = 2");
});
