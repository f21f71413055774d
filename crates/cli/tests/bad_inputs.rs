//! The resource guard as a user meets it: a film larger than the memory this process may
//! use (here `RAYLAB_MEMORY_LIMIT`, so that the test does not depend on the machine) is
//! refused before anything is allocated, unless `--allow-large` says the user means it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn raylab(args: &[&str], dir: &Path, limit: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).env("RAYLAB_MEMORY_LIMIT", limit).current_dir(dir).output().expect("raylab runs")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-cli-bad-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_film_larger_than_memory_is_refused_unless_allowed() {
    let dir = scratch("guard");
    let args = ["render", "--width", "128", "--height", "128", "--spp", "1", "--threads", "1", "-o", "out.png"];
    // 128 × 128 pixels × (2 × 4 channels × 8 bytes + 16) = 1.25 MiB, over a 1 MiB limit.
    let o = raylab(&args, &dir, "1M");
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&o.stderr).trim_end(), "raylab: error: a 128×128 film would need 1.2 MiB of memory, more than the 1.0 MiB this process may use (pass --allow-large to try anyway)");
    assert!(!dir.join("out.png").exists());
    let allowed = [&args[..], &["--allow-large"]].concat();
    let o = raylab(&allowed, &dir, "1M");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("out.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
