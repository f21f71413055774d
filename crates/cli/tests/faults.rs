//! Faults, as a user meets them: signals and SIGKILL at a random pass, resumes compared
//! byte for byte with uninterrupted renders, a kill during a write, checkpoints of another
//! scene, and tiles merged into the same bytes as a single render. These spawn the built
//! binary and send real signals (with `kill`, as a shell or Slurm would).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn spawn(args: &[&str], dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().expect("raylab starts")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-faults-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill").args([&format!("-{name}"), &child.id().to_string()]).status().unwrap().success();
    assert!(ok, "kill -{name}");
}

/// A seed from the clock, printed so a failure can be replayed with RAYLAB_FAULT_SEED.
fn seed() -> u64 {
    let s = std::env::var("RAYLAB_FAULT_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or_else(|| SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).unwrap().as_nanos() as u64);
    eprintln!("RAYLAB_FAULT_SEED={s}");
    s
}

fn random_ms(seed: &mut u64, max: u64) -> u64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*seed >> 33) % max
}

/// The path-traced Cornell box with the random sampler: 64 passes of 16 samples (a few
/// seconds).
const SCENE: &[&str] = &["--width", "32", "--height", "24", "--spp", "1024", "--pass-spp", "16", "--sampler", "random", "--threads", "2", "--quiet"];

fn cornell() -> String {
    repo().join("scenes/cornell_path.toml").display().to_string()
}

fn args<'a>(scene: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    ["render", scene].into_iter().chain(SCENE.iter().copied()).chain(extra.iter().copied()).collect()
}

fn wait_for(path: &Path, child: &mut Child) {
    let start = Instant::now();
    while !path.exists() {
        assert!(child.try_wait().unwrap().is_none(), "raylab ended before its first checkpoint");
        assert!(start.elapsed() < Duration::from_secs(60), "no checkpoint after 60 s");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn reference(dir: &Path) -> Vec<u8> {
    let scene = cornell();
    let o = raylab(&args(&scene, &["-o", "reference.pfm"]), dir);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read(dir.join("reference.pfm")).unwrap()
}

#[test]
fn interrupted_at_a_random_pass_and_resumed_gives_the_same_bytes() {
    let dir = scratch("resume");
    let reference = reference(&dir);
    let mut seed = seed();
    let scene = cornell();
    for (round, sig) in ["INT", "TERM", "KILL"].into_iter().enumerate() {
        let ckpt = format!("c{round}.film");
        let _ = std::fs::remove_file(dir.join(&ckpt));
        let mut child = spawn(&args(&scene, &["-o", "out.pfm", "--checkpoint", &ckpt, "--checkpoint-every", "0"]), &dir);
        wait_for(&dir.join(&ckpt), &mut child);
        std::thread::sleep(Duration::from_millis(random_ms(&mut seed, 150)));
        signal(&child, sig);
        let o = child.wait_with_output().unwrap();
        let err = stderr(&o);
        assert!(!err.contains("panicked"), "{err}");
        match sig {
            "INT" | "TERM" => {
                assert_eq!(o.status.code(), Some(if sig == "INT" { 130 } else { 143 }), "{err}");
                let last = err.lines().last().unwrap_or("");
                assert!(last.starts_with(&format!("raylab: error: interrupted by SIG{sig}: Wrote out.pfm holding samples 0..")), "{err}");
                assert!(last.ends_with(&format!("; checkpoint {ckpt} (continue with --resume {ckpt})")), "{err}");
                // The partial image is a valid image of the samples it holds.
                let (w, h, _) = raylab_loader::image_io::read_image(&dir.join("out.pfm"), false).unwrap();
                assert_eq!((w, h), (32, 24));
            }
            _ => assert_eq!(o.status.code(), None, "killed by a signal"),
        }
        let o = raylab(&args(&scene, &["-o", "resumed.pfm", "--resume", &ckpt, "--checkpoint", &ckpt]), &dir);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(std::fs::read(dir.join("resumed.pfm")).unwrap() == reference, "SIG{sig}: resumed image differs from the uninterrupted one");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_kill_during_a_write_leaves_the_old_file_or_the_new_one() {
    let dir = scratch("kill-write");
    // A large image written at the end of a short render, killed at random moments
    // around the write: the output is always the old bytes or a complete new image.
    let old = b"the previous output".to_vec();
    let mut seed = seed();
    let scene = cornell();
    let big = ["render", &scene, "--width", "1000", "--height", "800", "--spp", "1", "--integrator", "normals", "--threads", "2", "--quiet", "-o", "out.pfm"];
    let start = Instant::now();
    let o = raylab(&big, &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let full_ms = start.elapsed().as_millis() as u64;
    let new = std::fs::read(dir.join("out.pfm")).unwrap();
    let (mut saw_old, mut saw_new) = (0, 0);
    for _ in 0..6 {
        std::fs::write(dir.join("out.pfm"), &old).unwrap();
        let child = spawn(&big, &dir);
        std::thread::sleep(Duration::from_millis(full_ms / 3 + random_ms(&mut seed, full_ms)));
        let mut child = child;
        let _ = child.kill();
        let _ = child.wait();
        let now = std::fs::read(dir.join("out.pfm")).unwrap();
        if now == old {
            saw_old += 1;
        } else {
            assert!(now == new, "a killed write left {} bytes that are neither the old file nor the new one", now.len());
            saw_new += 1;
        }
    }
    eprintln!("old file kept {saw_old} times, new file complete {saw_new} times");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_checkpoint_of_another_scene_or_settings_is_refused() {
    let dir = scratch("refuse");
    let cornell = cornell();
    let o = raylab(&args(&cornell, &["-o", "a.png", "--checkpoint", "a.film", "--time-limit", "0"]), &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("a.film").exists());
    let other = repo().join("scenes/spheres_phong.toml").display().to_string();
    let o = raylab(&args(&other, &["-o", "b.png", "--resume", "a.film"]), &dir);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.starts_with("raylab: error: --resume a.film: refusing the checkpoint: it is of another scene (scene hash "), "{err}");
    let o = raylab(&args(&cornell, &["-o", "b.png", "--resume", "a.film", "--seed", "7"]), &dir);
    let err = stderr(&o);
    assert!(err.starts_with("raylab: error: --resume a.film: refusing the checkpoint: it has other render settings (32×24, 1024 spp in passes of 16, settings hash "), "{err}");
    std::fs::write(dir.join("bad.film"), b"RAYLABFM\x01\0\0\0garbage").unwrap();
    let o = raylab(&args(&cornell, &["-o", "b.png", "--resume", "bad.film"]), &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: --resume: bad.film: not a raylab film: truncated at byte 8");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tiles_and_sample_ranges_merge_into_the_bytes_of_a_single_render() {
    let dir = scratch("merge");
    let scene = cornell();
    let small = ["render", &scene, "--width", "32", "--height", "24", "--spp", "64", "--pass-spp", "16", "--sampler", "random", "--quiet"];
    let run = |extra: &[&str]| {
        let a: Vec<&str> = small.iter().copied().chain(extra.iter().copied()).collect();
        let o = raylab(&a, &dir);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    };
    run(&["-o", "single.exr"]);
    run(&["--tile", "0/3", "-o", "t0.film"]);
    run(&["--tile", "1/3", "-o", "t1.film"]);
    // The last tile in two sample ranges.
    run(&["--tile", "2/3", "--samples", "0..48", "-o", "t2a.film"]);
    run(&["--tile", "2/3", "--samples", "48..64", "-o", "t2b.film"]);
    let o = raylab(&["merge", "t2b.film", "t0.film", "t2a.film", "t1.film", "-o", "merged.exr"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(dir.join("merged.exr")).unwrap() == std::fs::read(dir.join("single.exr")).unwrap(), "merged tiles differ from the single render");
    // Missing, doubled and foreign parts are refused by name.
    let o = raylab(&["merge", "t0.film", "t1.film", "t2a.film", "-o", "m.exr"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: cannot merge: crop 0,16,32,24 holds samples 0..48, crop 0,0,32,8 holds 0..64 (parts: t0.film, t1.film, t2a.film)");
    let o = raylab(&["merge", "t0.film", "t1.film", "-o", "m.exr"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: the parts do not make the whole image: they cover pixels 0,0,32,16 of 0,0,32,24 and samples 0..64 of 0..64 (write a .film to keep a partial merge)");
    let o = raylab(&["merge", "t0.film", "t0.film", "-o", "m.exr"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: cannot merge: crop 0,0,32,8: samples 0..64 and 0..64 overlap: samples would be counted twice (parts: t0.film, t0.film)");
    run(&["--tile", "1/3", "--seed", "3", "-o", "seeded.film"]);
    let o = raylab(&["merge", "t0.film", "seeded.film", "-o", "m.film"], &dir);
    assert!(stderr(&o).starts_with("raylab: error: cannot merge: part 2 does not match part 1: it has other render settings"), "{}", stderr(&o));
    let o = raylab(&small.iter().copied().chain(["--tile", "0/3", "-o", "t.png"]).collect::<Vec<_>>(), &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: t.png: --tile, --crop and --samples render part of the image: give -o PART.film (join the parts with `raylab merge`)");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_outputs_and_exposures_fail_before_rendering() {
    let dir = scratch("early");
    let start = Instant::now();
    // 4096² at 64 spp would take minutes: the error must come first.
    let o = raylab(&["render", "--width", "4096", "--height", "4096", "--spp", "64", "-o", "missing/x.png"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: cannot write missing/x.png: the folder missing does not exist");
    let o = raylab(&["render", "--width", "4096", "--height", "4096", "--spp", "64", "-o", "x.pfm", "--exposure", "128"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: --exposure: exposure 128 out of range (-64 to 64 stops)");
    let o = raylab(&["render", "--width", "4096", "--height", "4096", "--spp", "64", "-o", "x.png", "--checkpoint", "missing/c.film"], &dir);
    assert_eq!(stderr(&o).trim_end(), "raylab: error: --checkpoint: cannot write missing/c.film: the folder missing does not exist");
    assert!(start.elapsed() < Duration::from_secs(20), "errors took {:?}", start.elapsed());
    assert!(!dir.join("x.pfm").exists() && !dir.join("x.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_time_limit_writes_a_valid_image_of_the_passes_that_fit() {
    let dir = scratch("time-limit");
    let scene = cornell();
    let o = raylab(&["render", &scene, "--width", "64", "--height", "48", "--spp", "1048576", "--pass-spp", "4", "--sampler", "random", "--time-limit", "2s", "-o", "t.pfm"], &dir);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("Wrote t.pfm holding samples 0.."), "{err}");
    let (w, h, pixels) = raylab_loader::image_io::read_image(&dir.join("t.pfm"), false).unwrap();
    assert_eq!((w, h), (64, 48));
    assert!(pixels.iter().any(|p| p.max_element() > 0.0));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_sigint_exits_at_once() {
    let dir = scratch("twice");
    let scene = cornell();
    // One pass of 65536 samples: after the first SIGINT the tile in flight still takes many
    // seconds to finish; the second SIGINT must not wait for it.
    let mut child = spawn(&["render", &scene, "--width", "32", "--height", "32", "--spp", "65536", "--pass-spp", "65536", "--threads", "1", "-q", "-o", "x.png"], &dir);
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, "INT");
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "the first SIGINT lets the tile in flight finish");
    signal(&child, "INT");
    let start = Instant::now();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert!(start.elapsed() < Duration::from_secs(3), "took {:?}", start.elapsed());
    assert!(!dir.join("x.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
