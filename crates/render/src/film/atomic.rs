//! Atomic file output: write a temporary file in the destination's folder, sync it, rename
//! it over the destination, sync the folder. A crash or SIGKILL at any moment leaves either
//! the old file or the new one, never a truncated one; a failed write (disk full, folder
//! not writable) removes the temporary file and leaves the old output untouched.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A temporary name beside `path`, unique to this process and call, hidden (dot prefix).
fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// The folder `path` will be written in (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Writes `bytes` to `path` atomically (see the module documentation).
pub fn write_atomic(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_atomic_with(path.as_ref(), |f| f.write_all(bytes.as_ref()))
}

/// Like [`write_atomic`], the content produced by `fill` into the temporary file.
pub fn write_atomic_with(path: &Path, fill: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>) -> std::io::Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp)?;
        fill(&mut f)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        return result;
    }
    // Make the rename itself durable; not every platform lets a folder be opened and synced.
    if let Ok(dir) = std::fs::File::open(parent_dir(path)) {
        let _ = dir.sync_all();
    }
    Ok(())
}

/// Checks, before any long work, that `path` can be written: its folder exists and accepts
/// a new file, and `path` itself is not a folder. Errors read "cannot write PATH: why".
pub fn check_writable(path: &Path) -> Result<(), String> {
    let dir = parent_dir(path);
    if path.is_dir() {
        return Err(format!("cannot write {}: it is a folder", path.display()));
    }
    if !dir.is_dir() {
        return Err(format!("cannot write {}: the folder {} does not exist", path.display(), dir.display()));
    }
    let tmp = temp_path(path);
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp) {
        Ok(_) => {
            let _ = std::fs::remove_file(&tmp);
            Ok(())
        }
        Err(e) => Err(format!("cannot write {}: {e}", path.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("raylab-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("out.bin");
        write_atomic(&p, b"old").unwrap();
        write_atomic(&p, b"new contents").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new contents");
        // A failing writer leaves the old file and no temporary behind.
        let e = write_atomic_with(&p, |_| Err(std::io::Error::other("disk full"))).unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(std::fs::read(&p).unwrap(), b"new contents");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.bin")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_folder_of_a_bare_name_is_the_current_one() {
        assert_eq!(parent_dir(Path::new("x.png")), Path::new("."));
        assert_eq!(parent_dir(Path::new("out/x.png")), Path::new("out"));
        assert_eq!(parent_dir(Path::new("/x.png")), Path::new("/"));
        assert_eq!(parent_dir(Path::new("/")), Path::new("."));
        // A bare name is writable when the current folder is (the tests run in the crate's).
        assert_eq!(check_writable(Path::new(&format!("raylab-bare-{}.png", std::process::id()))), Ok(()));
        // Temporary names are hidden, beside the file, and differ from call to call.
        let (a, b) = (temp_path(Path::new("dir/out.png")), temp_path(Path::new("dir/out.png")));
        assert_ne!(a, b);
        for t in [a, b] {
            assert_eq!(t.parent(), Some(Path::new("dir")));
            assert!(t.file_name().unwrap().to_str().unwrap().starts_with(".out.png.tmp-"), "{}", t.display());
        }
    }

    #[test]
    fn unwritable_destinations_are_named() {
        let missing = std::env::temp_dir().join(format!("raylab-no-such-{}", std::process::id())).join("x.png");
        let e = check_writable(&missing).unwrap_err();
        assert_eq!(e, format!("cannot write {}: the folder {} does not exist", missing.display(), missing.parent().unwrap().display()));
        let dir = std::env::temp_dir();
        assert_eq!(check_writable(&dir).unwrap_err(), format!("cannot write {}: it is a folder", dir.display()));
        assert!(check_writable(&dir.join(format!("raylab-ok-{}.png", std::process::id()))).is_ok());
    }
}
