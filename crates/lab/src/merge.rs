//! Merging the parts of a sharded sweep (`raylab bench --shard I/N`) into the report of the
//! whole run: the parts must come from the same raylab version and settings (hence the same
//! job list), and hold every job exactly once.

use std::collections::BTreeMap;

use crate::bench::{BenchReport, BenchResult};
use crate::sweep::{jobs, JobsRecord, Shard};

/// A part as read from its file: the file's name (for messages) and its report.
pub struct Part {
    pub file: String,
    pub report: BenchReport,
}

/// Reads a part (the JSON of `raylab bench --shard I/N --json-out FILE`).
pub fn read_part(path: &std::path::Path) -> Result<Part, String> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{file}: cannot read: {e}"))?;
    let report = serde_json::from_str(&text).map_err(|e| format!("{file}: not a bench result (line {}, column {}): {e}", e.line(), e.column()))?;
    Ok(Part { file, report })
}

/// The report of the whole run from its parts. Results come in the order of the job list, as
/// in an unsharded run; the machine is the first part's.
pub fn merge(parts: &[Part]) -> Result<BenchReport, String> {
    let first = parts.first().ok_or("no parts to merge")?;
    let settings = &first.report.settings;
    for p in &parts[1..] {
        if p.report.raylab_version != first.report.raylab_version {
            return Err(format!("{}: raylab {} differs from {}'s raylab {}", p.file, p.report.raylab_version, first.file, first.report.raylab_version));
        }
        if p.report.settings != *settings {
            return Err(format!("{}: settings differ from {}'s ({})", p.file, first.file, differences(&p.report.settings, settings)));
        }
    }
    let list = jobs(settings).map_err(|e| format!("{}: {e}", first.file))?;
    let mut holder: Vec<Option<&str>> = vec![None; list.len()];
    for p in parts {
        let r = &p.report.jobs;
        for j in r.ran.iter().copied().chain(r.skipped.iter().map(|s| s.job)) {
            let job = list.get(j).ok_or_else(|| format!("{}: job {j} is not in the list of {} jobs", p.file, list.len()))?;
            if let Some(other) = holder[j] {
                return Err(format!("{} is in both {other} and {}", job.describe(settings), p.file));
            }
            holder[j] = Some(&p.file);
        }
    }
    let missing: Vec<usize> = (0..list.len()).filter(|&j| holder[j].is_none()).collect();
    if let Some(&j) = missing.first() {
        let mut m = format!("{} of {} jobs are in no part, the first {}", missing.len(), list.len(), list[j].describe(settings));
        // Name the shard that holds it, when the parts agree on the number of shards.
        if let Some(count) = first.report.jobs.shard.map(|s| s.count).filter(|&c| parts.iter().all(|p| p.report.jobs.shard.map(|s| s.count) == Some(c))) {
            if let Some(s) = (1..=count).map(|index| Shard { index, count }).find(|s| s.range(list.len()).contains(&j)) {
                m.push_str(&format!(": is the part of shard {s} missing?"));
            }
        }
        return Err(m);
    }
    // Rows in job-list order; a structure whose ray sets were split between parts gets one row
    // (build figures from the first part that built it).
    let scene_order = |name: &str| (0..settings.scenes.len()).position(|i| settings.scene_name(i) == name).unwrap_or(usize::MAX);
    let accel_order = |name: &str| settings.accels.iter().position(|a| a == name).unwrap_or(usize::MAX);
    let mut rows: BTreeMap<(usize, usize), BenchResult> = BTreeMap::new();
    for p in parts {
        for r in &p.report.results {
            let key = (scene_order(&r.scene), accel_order(&r.accel));
            match rows.get_mut(&key) {
                Some(row) => row.rays.extend(r.rays.clone()),
                None => {
                    rows.insert(key, r.clone());
                }
            }
        }
    }
    let mut heatmaps: Vec<_> = parts.iter().flat_map(|p| p.report.heatmaps.iter().cloned()).collect();
    heatmaps.sort_by_key(|h| (scene_order(&h.scene), accel_order(&h.accel)));
    let mut ran: Vec<usize> = parts.iter().flat_map(|p| p.report.jobs.ran.iter().copied()).collect();
    ran.sort_unstable();
    let mut skipped: Vec<_> = parts.iter().flat_map(|p| p.report.jobs.skipped.iter().cloned()).collect();
    skipped.sort_by_key(|s| s.job);
    Ok(BenchReport {
        machine: first.report.machine.clone(),
        raylab_version: first.report.raylab_version.clone(),
        repeats: settings.repeats,
        resolution: settings.resolution,
        results: rows.into_values().collect(),
        settings: settings.clone(),
        jobs: JobsRecord { total: list.len(), shard: None, ran, skipped },
        heatmaps,
    })
}

/// `field: a against b` for each setting that differs.
fn differences<T: serde::Serialize>(a: &T, b: &T) -> String {
    let (a, b) = (serde_json::to_value(a).unwrap_or_default(), serde_json::to_value(b).unwrap_or_default());
    let (Some(a), Some(b)) = (a.as_object(), b.as_object()) else { return String::new() };
    a.iter().filter(|(k, v)| b.get(*k) != Some(v)).map(|(k, v)| format!("{k}: {v} against {}", b.get(k).cloned().unwrap_or_default())).collect::<Vec<_>>().join("; ")
}
