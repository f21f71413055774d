//! Multiple importance sampling weights (Veach 1997, §9.2): `[render] mis_heuristic`.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MisHeuristic {
    /// `f / (f + g)`: provably close to optimal among all weightings.
    Balance,
    /// `f² / (f² + g²)` (β = 2): sharper, better where one strategy is far better (Veach's default).
    Power,
}

raylab_core::named_enum!(MisHeuristic, "MIS heuristic", {
    Power => "power",
    Balance => "balance",
});

impl MisHeuristic {
    /// The weight of a sample drawn with density `f` when `g` is the other strategy's
    /// density for the same direction (one sample from each).
    pub fn weight(self, f: f32, g: f32) -> f32 {
        let (f, g) = match self {
            MisHeuristic::Balance => (f, g),
            MisHeuristic::Power => (f * f, g * g),
        };
        if f.is_infinite() {
            1.0
        } else if f + g == 0.0 {
            0.0
        } else {
            f / (f + g)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_the_two_strategies_sum_to_one() {
        for h in MisHeuristic::ALL {
            for (f, g) in [(1.0f32, 3.0f32), (0.2, 0.2), (5.0, 0.0), (f32::INFINITY, 2.0)] {
                let sum = h.weight(f, g) + if g.is_infinite() || f.is_infinite() { 0.0 } else { h.weight(g, f) };
                assert!((sum - 1.0).abs() < 1e-6, "{h} {f} {g}: {sum}");
            }
        }
        assert_eq!(MisHeuristic::Balance.weight(1.0, 3.0), 0.25);
        assert_eq!(MisHeuristic::Power.weight(1.0, 3.0), 0.1);
        assert_eq!(MisHeuristic::Power.weight(0.0, 0.0), 0.0);
    }
}
