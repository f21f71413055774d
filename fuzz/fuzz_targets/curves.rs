#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    raylab_fuzz::scene_with_file("c.curves", data, "type = \"curve\"\nmode = \"tube\"\nsegments = 2\nsides = 3");
});
