//! A self-contained HTML report of a benchmark: tables per scene, bar charts of build time,
//! Mrays/s, nodes visited and primitive tests per ray, scaling curves on a log–log plot
//! (build time and time per ray against primitive count), and heat-map thumbnails. Charts
//! are SVG drawn with plotters and inlined; images are inlined as base64 PNG.

use std::collections::BTreeMap;
use std::fmt::Write;

use plotters::prelude::*;

use crate::bench::{BenchReport, BenchResult};

const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Horizontal bars, one per label.
fn bar_chart(title: &str, unit: &str, bars: &[(String, f64)]) -> String {
    let mut svg = String::new();
    let h = 60 + 24 * bars.len() as u32;
    {
        let root = SVGBackend::with_string(&mut svg, (560, h)).into_drawing_area();
        root.fill(&WHITE).ok();
        let max = bars.iter().map(|b| b.1).fold(0.0, f64::max).max(1e-9) * 1.1;
        let labels: Vec<String> = bars.iter().map(|b| b.0.clone()).collect();
        let mut chart = match ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(110)
            .build_cartesian_2d(0.0..max, (0..bars.len()).into_segmented())
        {
            Ok(c) => c,
            Err(_) => return svg_fallback(title),
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc(unit)
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
                _ => String::new(),
            })
            .draw()
            .ok();
        chart
            .draw_series(bars.iter().enumerate().map(|(i, (_, v))| {
                let mut r = Rectangle::new([(0.0, SegmentValue::Exact(i)), (*v, SegmentValue::Exact(i + 1))], PALETTE[i % PALETTE.len()].filled());
                r.set_margin(3, 3, 0, 0);
                r
            }))
            .ok();
        root.present().ok();
    }
    svg
}

fn svg_fallback(title: &str) -> String {
    format!("<p>({} could not be drawn)</p>", esc(title))
}

/// One line per series (a structure, a strategy) through `(x, y)` points, both axes logarithmic.
pub(crate) fn loglog_chart(title: &str, x_desc: &str, y_desc: &str, series: &BTreeMap<String, Vec<(f64, f64)>>) -> String {
    let pts: Vec<(f64, f64)> = series.values().flatten().copied().filter(|(x, y)| *x > 0.0 && *y > 0.0).collect();
    if pts.len() < 2 {
        return String::new();
    }
    let (x0, x1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (560, 380)).into_drawing_area();
        root.fill(&WHITE).ok();
        let Ok(mut chart) = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), (y0 * 0.8..y1 * 1.25).log_scale())
        else {
            return svg_fallback(title);
        };
        chart.configure_mesh().x_desc(x_desc).y_desc(y_desc).draw().ok();
        for (i, (name, points)) in series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let mut p = points.clone();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            if let Ok(s) = chart.draw_series(LineSeries::new(p.clone(), color.stroke_width(2))) {
                s.label(name.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
            }
            chart.draw_series(p.iter().map(|&(x, y)| Circle::new((x, y), 3, color.filled()))).ok();
        }
        chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).position(SeriesLabelPosition::UpperLeft).draw().ok();
        root.present().ok();
    }
    svg
}

pub(crate) fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The style sheet of the lab's HTML pages.
pub(crate) const STYLE: &str = "body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222} table{border-collapse:collapse;margin:1em 0}\
    td,th{border:1px solid #ccc;padding:3px 8px;text-align:right} th{background:#f2f2f2} td:first-child{text-align:left}\
    .charts{display:flex;flex-wrap:wrap;gap:8px} .thumbs img{width:240px;margin:4px;image-rendering:pixelated} figure{display:inline-block;margin:4px}";

/// The heat maps of one scene's structures, drawn on one shared scale (the most nodes any
/// structure's ray visited) with its legend.
fn heatmaps(report: &BenchReport, scene: &str) -> String {
    let maps: Vec<(&str, u32, u32, Vec<u32>)> = report.heatmaps.iter().filter(|m| m.scene == scene).filter_map(|m| Some((m.accel.as_str(), m.width, m.height, crate::heatmap::unpack(&m.nodes)?))).collect();
    let Some(max) = maps.iter().flat_map(|m| m.3.iter().copied()).max() else { return String::new() };
    let mut h = format!("<h3>Nodes visited per camera ray</h3><p>One colour scale for every structure of this scene: 0 to {max} nodes.</p>{}<div class=\"thumbs\">", legend(max));
    for (accel, w, hgt, counts) in &maps {
        let png = crate::heatmap::to_png(*w, *hgt, counts, max);
        let _ = write!(h, "<figure><img alt=\"{a}\" src=\"data:image/png;base64,{}\"><figcaption>{a}</figcaption></figure>", base64(&png), a = esc(accel));
    }
    h.push_str("</div>");
    h
}

/// The heat maps' colour ramp as an SVG bar labelled from 0 to `max` nodes.
fn legend(max: u32) -> String {
    const STEPS: usize = 32;
    let mut stops = String::new();
    for i in 0..=STEPS {
        let x = i as f32 / STEPS as f32;
        let c = crate::heatmap::display_rgb(x);
        let _ = write!(stops, "<stop offset=\"{:.3}\" stop-color=\"rgb({},{},{})\"/>", x, c[0], c[1], c[2]);
    }
    let ticks: String = (0..=4)
        .map(|i| {
            let x = 10.0 + 400.0 * i as f64 / 4.0;
            format!("<line x1=\"{x}\" y1=\"30\" x2=\"{x}\" y2=\"36\" stroke=\"black\"/><text x=\"{x}\" y=\"50\" text-anchor=\"middle\" font-size=\"12\">{}</text>", (max as f64 * i as f64 / 4.0).round())
        })
        .collect();
    format!(
        "<svg class=\"heat-legend\" width=\"520\" height=\"56\" xmlns=\"http://www.w3.org/2000/svg\"><defs><linearGradient id=\"heat-ramp\">{stops}</linearGradient></defs>\
         <rect x=\"10\" y=\"8\" width=\"400\" height=\"22\" fill=\"url(#heat-ramp)\" stroke=\"black\"/>{ticks}<text x=\"420\" y=\"24\" font-size=\"12\">nodes per ray</text></svg>"
    )
}

/// The whole report as one HTML page.
pub fn html(report: &BenchReport) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>raylab bench</title><style>{STYLE}</style></head><body><h1>raylab bench</h1><p>raylab {} on {} ({} threads); medians of {} timed passes after a warm-up; \
         primary rays on a {}-pixel-wide grid. Every structure's hit count and sum of hit distances matched the oracle.</p>",
        esc(&report.raylab_version),
        esc(&report.machine.cpu),
        report.machine.threads,
        report.repeats,
        report.resolution
    );
    let mut scenes: Vec<&str> = Vec::new();
    for r in &report.results {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    for scene in &scenes {
        let rows: Vec<&BenchResult> = report.results.iter().filter(|r| r.scene == *scene).collect();
        let kinds: Vec<String> = rows.first().map(|r| r.rays.keys().cloned().collect()).unwrap_or_default();
        let _ = write!(h, "<h2>{}</h2><p>{} primitives</p><table><tr><th>structure</th><th>build ms</th><th>memory KiB</th><th>nodes</th><th>leaves</th><th>depth</th><th>SAH cost</th>", esc(scene), rows.first().map_or(0, |r| r.primitives));
        for k in &kinds {
            let _ = write!(h, "<th>{k} Mrays/s</th><th>{k} nodes/ray</th><th>{k} tests/ray</th>");
        }
        h.push_str("</tr>");
        for r in &rows {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{:.2}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td>",
                esc(&r.accel),
                r.build_ms,
                r.memory_bytes as f64 / 1024.0,
                r.stats.interior_nodes,
                r.stats.leaves,
                r.stats.max_depth,
                r.stats.sah_cost
            );
            for k in &kinds {
                let f = &r.rays[k];
                let _ = write!(h, "<td>{:.2}</td><td>{:.1}</td><td>{:.1}</td>", f.mrays_per_s, f.node_visits_per_ray, f.prim_tests_per_ray);
            }
            h.push_str("</tr>");
        }
        h.push_str("</table><div class=\"charts\">");
        h.push_str(&bar_chart("Build time", "ms", &rows.iter().map(|r| (r.accel.clone(), r.build_ms)).collect::<Vec<_>>()));
        for k in &kinds {
            h.push_str(&bar_chart(&format!("{k} rays: Mrays/s"), "Mrays/s", &rows.iter().map(|r| (r.accel.clone(), r.rays[k].mrays_per_s)).collect::<Vec<_>>()));
            h.push_str(&bar_chart(&format!("{k} rays: nodes visited per ray"), "nodes / ray", &rows.iter().map(|r| (r.accel.clone(), r.rays[k].node_visits_per_ray)).collect::<Vec<_>>()));
            h.push_str(&bar_chart(&format!("{k} rays: primitive tests per ray"), "tests / ray", &rows.iter().map(|r| (r.accel.clone(), r.rays[k].prim_tests_per_ray)).collect::<Vec<_>>()));
        }
        h.push_str("</div>");
        h.push_str(&heatmaps(report, scene));
    }
    if scenes.len() >= 2 {
        let mut build: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        let mut per_ray: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        for r in &report.results {
            build.entry(r.accel.clone()).or_default().push((r.primitives as f64, r.build_ms));
            if let Some(f) = r.rays.get("primary").or_else(|| r.rays.values().next()) {
                per_ray.entry(r.accel.clone()).or_default().push((r.primitives as f64, 1e3 / f.mrays_per_s.max(1e-9)));
            }
        }
        h.push_str("<h2>Scaling</h2><div class=\"charts\">");
        h.push_str(&loglog_chart("Build time against primitives", "primitives", "build ms", &build));
        h.push_str(&loglog_chart("Time per ray against primitives", "primitives", "ns per ray", &per_ray));
        h.push_str("</div>");
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_of_known_strings() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
