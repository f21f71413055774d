//! The side-by-side table: Mrays/s of every structure per ray kind, as a ratio to a
//! reference structure (Embree HIGH) measured in the same run.

use std::fmt::Write;

/// One structure's figures for one ray set.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Speed {
    /// Millions of rays per second of wall-clock time (medians over the passes).
    pub mrays_wall: f64,
    /// Millions of rays per CPU second of the whole process (stable on a busy machine).
    pub mrays_cpu: f64,
}

/// A row: a structure and its speed per ray kind (`None`: not traced).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub structure: String,
    pub speeds: Vec<Option<Speed>>,
}

/// Which rate a table shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    Cpu,
    Wall,
}

impl Speed {
    /// The rate by `clock`; CPU time falls back to wall clock where it is unavailable (0).
    pub fn rate(self, clock: Clock) -> f64 {
        match clock {
            Clock::Cpu if self.mrays_cpu > 0.0 => self.mrays_cpu,
            _ => self.mrays_wall,
        }
    }
}

/// `speed / reference` by CPU-time rates (wall clock where CPU time is unavailable):
/// above 1, the structure is faster than the reference.
pub fn ratio(speed: Speed, reference: Speed) -> f64 {
    ratio_by(speed, reference, Clock::Cpu)
}

fn ratio_by(speed: Speed, reference: Speed, clock: Clock) -> f64 {
    let cpu = clock == Clock::Cpu && speed.mrays_cpu > 0.0 && reference.mrays_cpu > 0.0;
    let clock = if cpu { Clock::Cpu } else { Clock::Wall };
    speed.rate(clock) / reference.rate(clock)
}

/// A Markdown table: per ray kind, `Mrays/s (ratio to reference)` by `clock`; the
/// reference row reads `1.00x`; without a reference row the ratios are left out.
pub fn speed_table(kinds: &[&str], rows: &[Row], reference: &str, clock: Clock) -> String {
    let refs = rows.iter().find(|r| r.structure == reference);
    let mut s = String::from("| structure |");
    for k in kinds {
        let _ = write!(s, " {k} |");
    }
    s.push_str("\n|---|");
    s.push_str(&"---|".repeat(kinds.len()));
    s.push('\n');
    for r in rows {
        let _ = write!(s, "| {} |", r.structure);
        for (j, speed) in r.speeds.iter().enumerate() {
            let cell = match (speed, refs.and_then(|x| x.speeds[j])) {
                (None, _) => "—".to_string(),
                (Some(v), Some(base)) => format!("{:.2} ({:.2}x)", v.rate(clock), ratio_by(*v, base, clock)),
                (Some(v), None) => format!("{:.2}", v.rate(clock)),
            };
            let _ = write!(s, " {cell} |");
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sp(cpu: f64) -> Option<Speed> {
        Some(Speed { mrays_wall: cpu * 2.0, mrays_cpu: cpu })
    }

    #[test]
    fn ratios_are_to_the_reference_row_of_the_same_kind() {
        let rows = vec![
            Row { structure: "embree".into(), speeds: vec![sp(10.0), sp(4.0), None] },
            Row { structure: "raylab bvh8".into(), speeds: vec![sp(5.3), sp(5.0), sp(3.0)] },
        ];
        let t = speed_table(&["primary", "diffuse", "packets"], &rows, "embree", Clock::Cpu);
        assert_eq!(
            t,
            "| structure | primary | diffuse | packets |\n|---|---|---|---|\n\
             | embree | 10.00 (1.00x) | 4.00 (1.00x) | — |\n\
             | raylab bvh8 | 5.30 (0.53x) | 5.00 (1.25x) | 3.00 |\n"
        );
        let t = speed_table(&["primary", "diffuse", "packets"], &rows[1..], "embree", Clock::Wall);
        assert!(t.ends_with("| raylab bvh8 | 10.60 | 10.00 | 6.00 |\n"), "{t}");
        // Without CPU time the wall-clock rates give the ratio.
        let w = |x| Speed { mrays_wall: x, mrays_cpu: 0.0 };
        assert_eq!(ratio(w(3.0), w(12.0)), 0.25);
    }
}
