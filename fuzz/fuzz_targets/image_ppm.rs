#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    raylab_fuzz::image("x.ppm", data);
});
