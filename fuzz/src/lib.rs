//! What the fuzz targets share: readers that take a path get the input written to a file
//! in a folder of this process (names decide formats), re-used from one input to the next.

use std::path::PathBuf;

/// Writes `bytes` to `name` in this process's scratch folder and returns its path.
pub fn file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("scratch file");
    path
}

/// Parses a scene that names `file` (written from the input) in a shape table `shape`.
pub fn scene_with_file(name: &str, bytes: &[u8], shape: &str) {
    let path = file(name, bytes);
    let src = format!("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[shapes]]\n{shape}\nfile = \"{name}\"\n");
    let resolver = raylab_loader::files::Resolver::Disk { base: path.parent().unwrap().to_path_buf() };
    let _ = raylab_loader::parse_scene_str(&src, std::path::Path::new("fuzz.toml"), &resolver);
}

/// Decodes an image whose format the extension of `name` picks.
pub fn image(name: &str, bytes: &[u8]) {
    let _ = raylab_loader::image_io::decode_image(std::path::Path::new(name), bytes, true);
}
