use std::fmt;

/// A structure's report after build (after Embree's `bvh_statistics` and pbrt's stats).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AccelStats {
    pub name: String,
    pub build_ms: f64,
    pub primitives: usize,
    /// Interior nodes (or non-empty grid cells for grids).
    pub interior_nodes: usize,
    pub leaves: usize,
    pub max_depth: usize,
    /// Primitive references in leaves; above `primitives` when splits duplicate references.
    pub references: usize,
    /// `leaf_histogram[k]` = number of leaves holding `k` primitives (the last bucket holds the rest).
    pub leaf_histogram: Vec<usize>,
    /// SAH cost of the tree relative to its root box (traversal and intersection cost 1).
    pub sah_cost: f64,
    pub memory_bytes: usize,
    /// Structure-specific figures in display order (a grid's resolution and cell counts, a
    /// kd-tree's empty leaves, ...), as `(name, value)`.
    pub notes: Vec<(String, String)>,
}

impl AccelStats {
    /// Adds a leaf of `n` primitives to the histogram (buckets 0..=16, the last one open).
    pub fn add_leaf(&mut self, n: usize) {
        const BUCKETS: usize = 17;
        if self.leaf_histogram.len() < BUCKETS {
            self.leaf_histogram.resize(BUCKETS, 0);
        }
        self.leaf_histogram[n.min(BUCKETS - 1)] += 1;
        self.leaves += 1;
        self.references += n;
    }

    /// Appends a structure-specific figure to [`AccelStats::notes`].
    pub fn note(&mut self, name: &str, value: impl fmt::Display) {
        self.notes.push((name.to_string(), value.to_string()));
    }
}

impl fmt::Display for AccelStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}: {} primitives, built in {:.2} ms", self.name, self.primitives, self.build_ms)?;
        writeln!(f, "  interior nodes {}, leaves {}, max depth {}", self.interior_nodes, self.leaves, self.max_depth)?;
        let avg = if self.leaves > 0 { self.references as f64 / self.leaves as f64 } else { 0.0 };
        writeln!(f, "  references {} ({avg:.2} per leaf), SAH cost {:.2}", self.references, self.sah_cost)?;
        write!(f, "  memory {:.1} KiB", self.memory_bytes as f64 / 1024.0)?;
        for (k, (name, value)) in self.notes.iter().enumerate() {
            write!(f, "{}{name} {value}", if k == 0 { "\n  " } else { ", " })?;
        }
        if !self.leaf_histogram.is_empty() {
            let last = self.leaf_histogram.iter().rposition(|&c| c > 0).unwrap_or(0);
            write!(f, "\n  leaf sizes:")?;
            for (k, c) in self.leaf_histogram[..=last].iter().enumerate() {
                let plus = if k + 1 == self.leaf_histogram.len() { "+" } else { "" };
                write!(f, " {k}{plus}:{c}")?;
            }
        }
        Ok(())
    }
}
