/// Work done by traversals, kept per thread and merged at the end: never shared atomics
/// on the hot path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counters {
    /// Rays traced (closest or any hit).
    pub rays: u64,
    /// Nodes (or grid cells) whose contents were examined.
    pub nodes_visited: u64,
    /// Ray–primitive tests (triangle, sphere, ...).
    pub prim_tests: u64,
    /// Ray–object bounding-box tests (the first report's "ray–mesh tests").
    pub object_tests: u64,
}

impl Counters {
    pub fn merge(&mut self, o: &Counters) {
        self.rays += o.rays;
        self.nodes_visited += o.nodes_visited;
        self.prim_tests += o.prim_tests;
        self.object_tests += o.object_tests;
    }
}

impl std::ops::AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.merge(&o);
    }
}
