//! A benchmark sweep as a list of independent jobs — one per scene × structure × ray set —
//! and the lab's method to run any subset of them: load each scene once, generate its rays
//! once, trace them through an oracle, build each structure (median of `repeats` builds,
//! validated), trace with a warm-up and interleaved timed passes, and check every answer
//! against the oracle. The CLI and Python only parse options and show progress.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_loader::Overrides;

pub use crate::bench::{BenchSettings, JobsRecord, Shard, SkippedJob};
use crate::bench::{cpu_name, median, BenchReport, BenchResult, HeatmapRecord, Machine, RayFigures, SceneSummary};
use crate::heatmap;
use crate::{rayfile, rays, RayKind, TraceResult};

impl BenchSettings {
    /// Settings with the defaults of `raylab bench`, for `scenes` and the structures in `accels`
    /// (`all`, or names separated by commas).
    pub fn new(scenes: Vec<Option<PathBuf>>, accels: &str) -> Result<BenchSettings, LabError> {
        let all = accels.trim() == "all";
        let accels = if all { AccelKind::ALL.to_vec() } else { parse_list::<AccelKind>("--accels", accels)? };
        Ok(BenchSettings {
            scenes,
            accels: accels.iter().map(|k| k.name().to_string()).collect(),
            all,
            rays: ["primary", "diffuse", "shadow"].map(String::from).to_vec(),
            resolution: 256,
            repeats: 3,
            oracle_limit: 20_000,
            seed: 1,
            heatmap_width: None,
        })
    }

    /// A scene's name in results: its path as given, or `default scene`.
    pub fn scene_name(&self, i: usize) -> String {
        self.scenes[i].as_ref().map_or("default scene".to_string(), |p| p.display().to_string())
    }
}

/// The structures of an `--accels` list: comma-separated names, or `all` for every one.
pub fn parse_accels(option: &str, list: &str) -> Result<Vec<AccelKind>, LabError> {
    if list.trim() == "all" {
        return Ok(AccelKind::ALL.to_vec());
    }
    parse_list(option, list)
}

/// Parses a comma-separated list of names, naming the option in errors.
pub fn parse_list<T: std::str::FromStr>(option: &str, list: &str) -> Result<Vec<T>, LabError>
where
    T::Err: fmt::Display,
{
    list.split(',').map(|s| s.trim().parse::<T>().map_err(|e| LabError::Settings(format!("{option}: {e}")))).collect()
}

/// One job: a structure built on a scene and timed on one ray set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Job {
    /// Position in the full job list.
    pub index: usize,
    /// Position of the scene in [`BenchSettings::scenes`].
    pub scene: usize,
    pub accel: AccelKind,
    pub rays: RayKind,
}

impl Job {
    /// `job 3 (scenes/cube.toml, bvh, shadow rays)`.
    pub fn describe(&self, settings: &BenchSettings) -> String {
        format!("job {} ({}, {}, {} rays)", self.index, settings.scene_name(self.scene), self.accel, self.rays)
    }
}

/// The full job list: scene-major, then structure, then ray set, each in the order given.
/// Jobs of one scene and one structure are neighbours, so that a shard mostly loads each
/// scene and builds each structure once.
pub fn jobs(settings: &BenchSettings) -> Result<Vec<Job>, LabError> {
    let accels = parse_list::<AccelKind>("accels", &settings.accels.join(","))?;
    let kinds = parse_list::<RayKind>("rays", &settings.rays.join(","))?;
    let mut out = Vec::new();
    for scene in 0..settings.scenes.len() {
        for &accel in &accels {
            for &rays in &kinds {
                out.push(Job { index: out.len(), scene, accel, rays });
            }
        }
    }
    Ok(out)
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let parsed = s.split_once('/').and_then(|(i, n)| Some((i.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?)));
        match parsed {
            Some((index, count)) if count >= 1 && (1..=count).contains(&index) => Ok(Shard { index, count }),
            _ => Err(format!("expected I/N with 1 <= I <= N (e.g. 2/8), found `{s}`")),
        }
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The positions of this shard's jobs in a list of `n`: the contiguous block
    /// `[(I-1)·n/N, I·n/N)`, so the blocks of `1/N … N/N` cover the list exactly once and
    /// differ in size by at most one job.
    pub fn range(&self, n: usize) -> std::ops::Range<usize> {
        let (i, c) = (self.index as usize, self.count as usize);
        (i - 1) * n / c..i * n / c
    }
}

#[derive(Debug, thiserror::Error)]
pub enum LabError {
    #[error(transparent)]
    Load(#[from] raylab_loader::LoadError),
    #[error("{0}")]
    Settings(String),
    /// A structure failed its validation, or disagreed with the oracle.
    #[error("{0}")]
    Wrong(String),
    #[error("{0}")]
    Io(String),
    #[error("interrupted")]
    Interrupted,
}

/// What a sweep tells its caller as it goes. Every method has a do-nothing default.
pub trait Progress: Sync {
    /// A scene's structures are about to be built and traced: `steps` calls of [`Progress::step`] follow.
    fn start_scene(&self, _name: &str, _steps: u64) {}
    fn step(&self) {}
    /// A scene is done; `results` are its rows.
    fn scene_done(&self, _summary: &SceneSummary, _results: &[BenchResult]) {}
    /// A note for the user (e.g. structures left out).
    fn note(&self, _text: &str) {}
    /// Checked between passes: `true` stops the sweep with [`LabError::Interrupted`].
    fn cancelled(&self) -> bool {
        false
    }
}

/// A [`Progress`] that shows nothing.
pub struct Silent;
impl Progress for Silent {}

/// Runs `jobs` (the whole list, a shard of it, any subset in list order) on the current
/// rayon pool. `shard` is recorded in the report; `dump_rays` writes the generated ray sets.
pub fn run(settings: &BenchSettings, jobs_to_run: &[Job], shard: Option<Shard>, dump_rays: Option<&Path>, progress: &dyn Progress) -> Result<BenchReport, LabError> {
    let total = jobs(settings)?.len();
    let mut report = BenchReport {
        machine: Machine { cpu: cpu_name(), threads: rayon::current_num_threads() },
        raylab_version: env!("CARGO_PKG_VERSION").into(),
        repeats: settings.repeats,
        resolution: settings.resolution,
        results: Vec::new(),
        settings: settings.clone(),
        jobs: JobsRecord { total, shard, ran: Vec::new(), skipped: Vec::new() },
        heatmaps: Vec::new(),
    };
    let mut scenes: Vec<usize> = jobs_to_run.iter().map(|j| j.scene).collect();
    scenes.dedup();
    for scene in scenes {
        let mine: Vec<Job> = jobs_to_run.iter().copied().filter(|j| j.scene == scene).collect();
        run_scene(settings, scene, &mine, dump_rays, progress, &mut report)?;
    }
    Ok(report)
}

/// The jobs of one scene: they share its rays, its oracle and (per structure) one build.
fn run_scene(settings: &BenchSettings, scene_index: usize, jobs: &[Job], dump_rays: Option<&Path>, progress: &dyn Progress, report: &mut BenchReport) -> Result<(), LabError> {
    let name = settings.scene_name(scene_index);
    let path = settings.scenes.get(scene_index).cloned().flatten();
    let o = Overrides { accel: Some(AccelKind::Bvh), ..Default::default() };
    let scene = match &path {
        Some(p) => raylab_loader::load_scene_or_mesh(p, &o)?,
        None => raylab_loader::default_scene(&o)?,
    };
    let prims = &scene.geometry;
    let height = ((settings.resolution as f64 * scene.settings.height as f64 / scene.settings.width as f64).round() as u32).max(1);
    let mut kinds: Vec<RayKind> = Vec::new();
    for j in jobs {
        if !kinds.contains(&j.rays) {
            kinds.push(j.rays);
        }
    }
    kinds.sort();
    let sets = rays::generate(&scene, settings.resolution, height, &kinds, settings.seed);
    if let Some(dir) = dump_rays {
        std::fs::create_dir_all(dir).map_err(|e| LabError::Io(format!("{}: cannot create: {e}", dir.display())))?;
        let stem = path.as_ref().and_then(|p| p.file_name()).map_or("default".into(), |s| s.to_string_lossy().replace(".obj.gz", "").replace(".obj", "").replace(".toml", ""));
        for s in &sets {
            let file = dir.join(format!("{stem}-{}.rays", s.kind));
            rayfile::write(&file, &s.rays).map_err(|e| LabError::Io(format!("{}: {e}", file.display())))?;
        }
    }
    let oracle_kind = if prims.len() <= settings.oracle_limit { AccelKind::None } else { AccelKind::Bvh };
    // Structures that test every primitive per ray (per object, for one big mesh) take hours
    // on large scenes: `all` leaves them out there; naming them keeps them in.
    let linear = [AccelKind::None, AccelKind::Aabb];
    let skip = |k: AccelKind| settings.all && oracle_kind != AccelKind::None && linear.contains(&k);
    let mut accels: Vec<AccelKind> = Vec::new();
    for j in jobs {
        if skip(j.accel) {
            report.jobs.skipped.push(SkippedJob { job: j.index, reason: format!("{} primitives, above the oracle limit of {}: `all` leaves out none and aabb", prims.len(), settings.oracle_limit) });
        } else if !accels.contains(&j.accel) {
            accels.push(j.accel);
        }
    }
    if jobs.iter().any(|j| skip(j.accel)) {
        progress.note(&format!("{name}: {} primitives, above --oracle-limit: `all` leaves out none and aabb (name them to include them)", prims.len()));
    }
    let oracle = AnyAccel::build(oracle_kind, prims, &BuildOptions::default());
    let reference: Vec<TraceResult> = sets.iter().map(|s| crate::trace(&oracle, prims, &s.rays, s.kind.any_hit())).collect();
    // Each structure traces the ray sets of its own jobs (all of them, in a whole run).
    let sets_of = |k: AccelKind| -> Vec<usize> { (0..sets.len()).filter(|&i| jobs.iter().any(|j| j.accel == k && j.rays == sets[i].kind)).collect() };

    progress.start_scene(&name, (accels.len() * (settings.repeats as usize + 2)) as u64);
    // Builds: a median over `repeats` builds, keeping the last structure.
    let mut built = Vec::new();
    for &k in &accels {
        let mut times = Vec::new();
        let mut accel = None;
        for _ in 0..settings.repeats.max(1) {
            let x = AnyAccel::build(k, prims, &BuildOptions::default());
            times.push(x.stats().build_ms);
            accel = Some(x);
        }
        let accel = accel.expect("at least one build");
        accel.validate(prims).map_err(|e| LabError::Wrong(format!("{name}: {k} failed validation: {e}")))?;
        built.push((k, accel, median(times), sets_of(k)));
        progress.step();
    }
    // Traces: pass 0 is the warm-up; structures interleave within each pass.
    let mut times: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); sets.len()]; built.len()];
    let mut last: Vec<Vec<TraceResult>> = vec![vec![TraceResult::default(); sets.len()]; built.len()];
    for pass in 0..=settings.repeats {
        if progress.cancelled() {
            return Err(LabError::Interrupted);
        }
        for (i, (_, accel, _, mine)) in built.iter().enumerate() {
            for &j in mine {
                let s = &sets[j];
                let r = crate::trace(accel, prims, &s.rays, s.kind.any_hit());
                if pass > 0 {
                    times[i][j].push(r.seconds);
                }
                last[i][j] = r;
            }
            progress.step();
        }
    }
    let mut results = Vec::new();
    let mut mismatches = Vec::new();
    for (i, (k, accel, build_ms, mine)) in built.iter().enumerate() {
        let stats = accel.stats();
        let mut figures = BTreeMap::new();
        for &j in mine {
            let (r, s) = (last[i][j], &sets[j]);
            if !r.agrees_with(&reference[j]) {
                mismatches.push(format!("{k} on {} rays: {} hits, t sum {} (oracle {oracle_kind}: {} hits, t sum {})", s.kind, r.hits, r.t_sum, reference[j].hits, reference[j].t_sum));
            }
            let secs = median(times[i][j].clone());
            let n = r.count.max(1) as f64;
            figures.insert(
                s.kind.name().to_string(),
                RayFigures {
                    count: r.count,
                    hits: r.hits,
                    t_sum: r.t_sum,
                    mrays_per_s: r.count as f64 / secs.max(1e-12) / 1e6,
                    node_visits_per_ray: r.counters.nodes_visited as f64 / n,
                    prim_tests_per_ray: r.counters.prim_tests as f64 / n,
                    object_tests_per_ray: r.counters.object_tests as f64 / n,
                },
            );
        }
        results.push(BenchResult { scene: name.clone(), primitives: prims.len(), accel: k.name().into(), build_ms: *build_ms, memory_bytes: stats.memory_bytes, stats, rays: figures });
    }
    if !mismatches.is_empty() {
        return Err(LabError::Wrong(format!("{name}: answers differ from the oracle:\n  {}", mismatches.join("\n  "))));
    }
    // A heat map belongs to the structure's job on the first ray set of the list, so that a
    // sharded run records each exactly once.
    if let Some(width) = settings.heatmap_width {
        let first = settings.rays.first().and_then(|r| r.parse::<RayKind>().ok());
        let h = ((width as f64 * scene.settings.height as f64 / scene.settings.width as f64).round() as u32).max(1);
        let camera = rays::primary(&scene, width, h);
        for (k, accel, _, _) in &built {
            if jobs.iter().any(|j| j.accel == *k && Some(j.rays) == first) {
                let nodes: Vec<u32> = heatmap::nodes_per_ray(accel, prims, &camera);
                report.heatmaps.push(HeatmapRecord { scene: name.clone(), accel: k.name().into(), width, height: h, nodes: heatmap::pack(&nodes) });
            }
        }
    }
    report.jobs.ran.extend(jobs.iter().filter(|j| !skip(j.accel)).map(|j| j.index));
    progress.scene_done(&SceneSummary { name, primitives: prims.len(), grid: (settings.resolution, height), oracle: oracle_kind.name().into(), repeats: settings.repeats }, &results);
    report.results.extend(results);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jobs_are_scene_major_then_structure_then_ray_set() {
        let mut s = BenchSettings::new(vec![Some("a.toml".into()), None], "bvh,kdtree").unwrap();
        s.rays = vec!["primary".into(), "shadow".into()];
        let j = jobs(&s).unwrap();
        assert_eq!(j.len(), 8);
        assert_eq!((j[0].scene, j[0].accel, j[0].rays), (0, AccelKind::Bvh, RayKind::Primary));
        assert_eq!((j[3].scene, j[3].accel, j[3].rays), (0, AccelKind::KdTree, RayKind::Shadow));
        assert_eq!((j[4].scene, j[4].accel, j[4].rays), (1, AccelKind::Bvh, RayKind::Primary));
        assert_eq!(j[5].describe(&s), "job 5 (default scene, bvh, shadow rays)");
        assert!(jobs(&BenchSettings::new(vec![], "all").unwrap()).unwrap().is_empty());
    }

    #[test]
    fn shards_cover_the_list_exactly_once_in_near_equal_blocks() {
        for n in [0, 1, 5, 9, 42] {
            for count in 1..=12 {
                let ranges: Vec<_> = (1..=count).map(|index| Shard { index, count }.range(n)).collect();
                assert_eq!(ranges[0].start, 0);
                assert_eq!(ranges[count as usize - 1].end, n);
                for w in ranges.windows(2) {
                    assert_eq!(w[0].end, w[1].start);
                }
                let sizes: Vec<usize> = ranges.iter().map(|r| r.len()).collect();
                assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1, "{n} jobs in {count}: {sizes:?}");
            }
        }
        assert_eq!(Shard { index: 2, count: 3 }.range(9), 3..6);
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "1/0", "3", "a/b"] {
            assert_eq!(bad.parse::<Shard>(), Err(format!("expected I/N with 1 <= I <= N (e.g. 2/8), found `{bad}`")));
        }
    }
}
