//! docs/scene-format.md's `[render]` table lists exactly the settings of the one settings
//! table (`raylab_render::settings::SETTINGS`), with their defaults and names; a setting
//! added or renamed without its row fails here.

use raylab_render::settings::{SettingKind, SETTINGS};

/// The rows of the markdown table that follows `heading`: the cells of each, trimmed.
fn table_after(doc: &str, heading: &str) -> Vec<Vec<String>> {
    let start = doc.find(heading).unwrap_or_else(|| panic!("no `{heading}` in docs/scene-format.md"));
    doc[start..].lines().skip_while(|l| !l.starts_with('|')).take_while(|l| l.starts_with('|')).skip(2).map(|l| l.trim_matches('|').split(" | ").map(|c| c.trim().to_string()).collect()).collect()
}

fn backticked(cell: &str) -> Vec<&str> {
    cell.split('`').skip(1).step_by(2).collect()
}

#[test]
fn the_render_table_of_the_docs_lists_exactly_the_settings() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md")).unwrap();
    let rows = table_after(&doc, "## `[render]`");
    let documented: Vec<&str> = rows.iter().map(|r| r[0].trim_matches('`')).collect();
    let keys: Vec<&str> = SETTINGS.iter().filter(|s| s.table == "render").map(|s| s.key).collect();
    assert_eq!(documented, keys, "the docs' [render] rows, in the settings table's order");
    for (row, spec) in rows.iter().zip(SETTINGS.iter().filter(|s| s.table == "render")) {
        assert_eq!(row[2].trim_matches('`'), (spec.default)(), "default of `{}`", spec.key);
        match spec.kind {
            SettingKind::Name(names) => {
                let listed: Vec<String> = backticked(&row[1]).iter().map(|n| n.trim_matches('"').to_string()).collect();
                let valid: Vec<String> = names().split(", ").map(String::from).collect();
                // The structures are too many for one cell: a few, then `...`.
                if spec.key == "accel" {
                    assert!(listed.iter().all(|n| valid.contains(n)), "`accel` lists {listed:?}");
                } else {
                    assert_eq!(listed, valid, "names of `{}`", spec.key);
                }
            }
            SettingKind::Integer { min, max } => {
                let range = if max == u64::MAX { format!("integer ≥ {min}") } else { format!("integer {min}–{max}") };
                assert_eq!(row[1], range, "values of `{}`", spec.key);
            }
        }
    }
    let camera = table_after(&doc, "## `[camera]`");
    let size = camera.iter().find(|r| r[0] == "`width`, `height`").expect("a `width`, `height` row in [camera]");
    let (w, h) = (raylab_render::settings::spec("width").unwrap(), raylab_render::settings::spec("height").unwrap());
    assert_eq!(size[1], format!("integer in {}..{}", w.range().unwrap().0, w.range().unwrap().1));
    assert_eq!(size[2], format!("{}, {}", (w.default)(), (h.default)()));
}
