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

/// `speed / reference` from CPU-time rates (wall clock where CPU time is unavailable):
/// above 1, the structure is faster than the reference.
pub fn ratio(speed: Speed, reference: Speed) -> f64 {
    if speed.mrays_cpu > 0.0 && reference.mrays_cpu > 0.0 {
        speed.mrays_cpu / reference.mrays_cpu
    } else {
        speed.mrays_wall / reference.mrays_wall
    }
}

/// A Markdown table: per ray kind, `CPU Mrays/s (ratio to reference)`; the reference row
/// reads `1.00x`; without a reference row the ratios are left out.
pub fn speed_table(kinds: &[&str], rows: &[Row], reference: &str) -> String {
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
                (Some(v), Some(base)) => format!("{:.2} ({:.2}x)", v.mrays_cpu, ratio(*v, base)),
                (Some(v), None) => format!("{:.2}", v.mrays_cpu),
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
        let t = speed_table(&["primary", "diffuse", "packets"], &rows, "embree");
        assert_eq!(
            t,
            "| structure | primary | diffuse | packets |\n|---|---|---|---|\n\
             | embree | 10.00 (1.00x) | 4.00 (1.00x) | — |\n\
             | raylab bvh8 | 5.30 (0.53x) | 5.00 (1.25x) | 3.00 |\n"
        );
        // Without CPU time the wall-clock rates give the ratio.
        let w = |x| Speed { mrays_wall: x, mrays_cpu: 0.0 };
        assert_eq!(ratio(w(3.0), w(12.0)), 0.25);
    }
}
