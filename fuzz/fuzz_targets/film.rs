#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // Checkpoints and partial films share this format.
    let _ = raylab_render::film::Film::from_bytes(data);
});
