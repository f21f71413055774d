//! `raylab bench --shard I/N` and `--merge`: the parts of a sharded run merge into the result
//! of the unsharded run (timings aside), and parts that do not make up one run are refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-bench-shard-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn cube() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cube.toml").canonicalize().unwrap().display().to_string()
}

/// `raylab bench` on the cube with three structures and the three ray sets: 9 jobs.
fn bench(dir: &Path, extra: &[&str]) {
    let cube = cube();
    let mut args = vec!["bench", cube.as_str(), "--accels", "bvh,kdtree,none", "--resolution", "16", "--repeats", "1"];
    args.extend_from_slice(extra);
    let o = raylab(&args, dir);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

fn read(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The JSON without its timings (which no two runs share).
fn without_timings(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(m.iter().filter(|(k, _)| !["build_ms", "mrays_per_s"].contains(&k.as_str())).map(|(k, v)| (k.clone(), without_timings(v))).collect()),
        Value::Array(a) => Value::Array(a.iter().map(without_timings).collect()),
        v => v.clone(),
    }
}

fn fails_with(args: &[&str], dir: &Path, message: &str) {
    let o = raylab(args, dir);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.trim_end(), format!("raylab: error: {message}"), "{args:?}");
}

#[test]
fn two_shards_merge_into_the_unsharded_run() {
    let dir = scratch("merge");
    bench(&dir, &["--json-out", "whole.json", "--report", "whole.html"]);
    // The old spelling `--json FILE` writes the part as `--json-out FILE` does.
    bench(&dir, &["--shard", "1/2", "--json", "p1.json"]);
    bench(&dir, &["--shard", "2/2", "--json-out", "p2.json"]);
    let (p1, p2) = (read(&dir.join("p1.json")), read(&dir.join("p2.json")));
    // Contiguous blocks of the list (scene × structure × ray set): jobs 0-3 and 4-8.
    assert_eq!(p1["jobs"]["ran"], serde_json::json!([0, 1, 2, 3]));
    assert_eq!(p2["jobs"]["ran"], serde_json::json!([4, 5, 6, 7, 8]));
    assert_eq!(p1["jobs"]["shard"], serde_json::json!({"index": 1, "count": 2}));
    // kdtree's primary rays ran in the first shard, its other rays in the second.
    assert_eq!(p1["results"][1]["rays"].as_object().unwrap().keys().collect::<Vec<_>>(), ["primary"]);
    let o = raylab(&["bench", "--merge", "p2.json", "p1.json", "--json-out", "merged.json", "--report", "merged.html"], &dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (whole, merged) = (read(&dir.join("whole.json")), read(&dir.join("merged.json")));
    assert_eq!(without_timings(&merged), without_timings(&whole));
    assert_eq!(whole["jobs"]["ran"].as_array().unwrap().len(), 9);
    assert_eq!(merged["heatmaps"].as_array().unwrap().len(), 3);
    let html = std::fs::read_to_string(dir.join("merged.html")).unwrap();
    assert_eq!(html.matches("<figure>").count(), 3, "a heat map per structure");
}

#[test]
fn parts_that_do_not_make_up_one_run_are_refused() {
    let dir = scratch("refuse");
    bench(&dir, &["--shard", "1/2", "--json-out", "p1.json"]);
    bench(&dir, &["--shard", "2/2", "--json-out", "p2.json"]);
    bench(&dir, &["--shard", "2/2", "--json-out", "seed2.json", "--seed", "2"]);
    let cube = cube();
    fails_with(&["bench", "--merge", "p1.json", "--json-out", "m.json"], &dir, &format!("5 of 9 jobs are in no part, the first job 4 ({cube}, kdtree, diffuse rays): is the part of shard 2/2 missing?"));
    std::fs::copy(dir.join("p2.json"), dir.join("again.json")).unwrap();
    fails_with(&["bench", "--merge", "p1.json", "p2.json", "again.json", "--json-out", "m.json"], &dir, &format!("job 4 ({cube}, kdtree, diffuse rays) is in both p2.json and again.json"));
    fails_with(&["bench", "--merge", "p1.json", "seed2.json", "--json-out", "m.json"], &dir, "seed2.json: settings differ from p1.json's (seed: 2 against 1)");
    let mut old = read(&dir.join("p2.json"));
    old["raylab_version"] = "0.0.1".into();
    std::fs::write(dir.join("old.json"), old.to_string()).unwrap();
    fails_with(&["bench", "--merge", "p1.json", "old.json", "--json-out", "m.json"], &dir, &format!("old.json: raylab 0.0.1 differs from p1.json's raylab {}", env!("CARGO_PKG_VERSION")));
    std::fs::write(dir.join("junk.json"), "{\"machine\": 3}").unwrap();
    fails_with(&["bench", "--merge", "p1.json", "junk.json"], &dir, "junk.json: not a bench result (line 1, column 13): invalid type: integer `3`, expected struct Machine at line 1 column 13");
    // A shard out of range is a usage error, reported by the option parser.
    let o = raylab(&["bench", "--shard", "3/2", "--json-out", "m.json"], &dir);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).starts_with("error: invalid value '3/2' for '--shard <I/N>': expected I/N with 1 <= I <= N (e.g. 2/8), found `3/2`\n"));
    fails_with(&["bench", "--shard", "1/2"], &dir, "--shard: give --json-out FILE for the part (merge the parts with --merge)");
    assert!(!dir.join("m.json").exists(), "a refused merge writes nothing");
}
