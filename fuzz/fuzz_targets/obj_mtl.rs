#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // The input up to its first NUL byte is the OBJ, the rest its MTL (`mtllib m.mtl`).
    let (obj, mtl) = data.split_at(data.iter().position(|&b| b == 0).unwrap_or(data.len()));
    raylab_fuzz::file("m.mtl", mtl.get(1..).unwrap_or(&[]));
    let path = raylab_fuzz::file("m.obj", obj);
    let _ = raylab_loader::obj::load_obj(&raylab_loader::files::Found::Disk(path), &raylab_core::Transform::IDENTITY);
});
