//! A self-contained HTML report of a benchmark: tables per scene, bar charts of build time,
//! Mrays/s, nodes visited and primitive tests per ray (on a log axis: brute force's thousands
//! beside a tree's one), a Pareto plot of build time against trace speed, heat-map thumbnails
//! on one shared scale with its legend, and scaling curves on log–log plots (build time and
//! time per ray against primitive count). Every structure keeps one colour throughout; legends
//! sit beside the plots. Charts are SVG drawn with plotters and inlined; images are inlined as
//! base64 PNG. Checked in headless Chromium with scripts/report-screenshot.sh.

use std::collections::BTreeMap;
use std::fmt::Write;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::bench::{BenchReport, BenchResult};

/// Tableau's 20 colours, the dark shade of each hue first: distinct at a glance for up to 20
/// series; beyond, [`color`] walks the hue circle by the golden angle.
const PALETTE: [RGBColor; 20] = [
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
    RGBColor(174, 199, 232),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(255, 152, 150),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(247, 182, 210),
    RGBColor(199, 199, 199),
    RGBColor(219, 219, 141),
    RGBColor(158, 218, 229),
];

/// The `i`-th series colour: distinct for every `i` (the palette, then golden-angle hues).
pub(crate) fn color(i: usize) -> RGBColor {
    if i < PALETTE.len() {
        return PALETTE[i];
    }
    let hue = ((i - PALETTE.len()) as f64 * 137.508 + 15.0) % 360.0;
    let light = if (i / 7).is_multiple_of(2) { 0.4 } else { 0.62 };
    let c = HSLColor(hue / 360.0, 0.75, light).to_rgba();
    RGBColor(c.0, c.1, c.2)
}

/// One colour per structure name, in order of first appearance, used by every chart of a report.
pub(crate) struct Colors(Vec<String>);

impl Colors {
    pub(crate) fn new<'a>(names: impl IntoIterator<Item = &'a str>) -> Colors {
        let mut v: Vec<String> = Vec::new();
        for n in names {
            if !v.iter().any(|x| x == n) {
                v.push(n.to_string());
            }
        }
        Colors(v)
    }
    pub(crate) fn of(&self, name: &str) -> RGBColor {
        color(self.0.iter().position(|x| x == name).unwrap_or(self.0.len()))
    }
}

pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Axis numbers as a reader writes them: 0.01, 2.5, 40, 1200, 3.2e6.
fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

/// Powers of ten and their 2 and 5 multiples within `[lo, hi]` (in log10 units), as
/// log10 positions: the ticks of a log axis, at most about 8.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut t = Vec::new();
    let steps: &[f64] = if hi - lo > 4.0 { &[1.0] } else if hi - lo > 2.0 { &[1.0, 3.0] } else { &[1.0, 2.0, 5.0] };
    let mut e = lo.floor() as i32;
    while (e as f64) <= hi.ceil() {
        for m in steps {
            let v = (m * 10f64.powi(e)).log10();
            if v >= lo - 1e-9 && v <= hi + 1e-9 {
                t.push(v);
            }
        }
        e += 1;
    }
    t
}

/// Labels of a log axis at `ticks` (log10 positions), drawn by hand: plotters' own key points
/// fall on round log10 values, not on 2 and 5 multiples. `at` maps a tick to the pixel where the
/// axis meets it; `vertical` axes put the label to the left.
fn draw_log_ticks<DB: DrawingBackend>(root: &DrawingArea<DB, plotters::coord::Shift>, ticks: &[f64], at: impl Fn(f64) -> (i32, i32), vertical: bool) {
    let style = ("sans-serif", 12).into_font().color(&BLACK);
    for &t in ticks {
        let (x, y) = at(t);
        let label = number(10f64.powf(t));
        if vertical {
            root.draw(&PathElement::new(vec![(x - 5, y), (x, y)], BLACK)).ok();
            root.draw(&Text::new(label, (x - 8, y), style.pos(Pos::new(HPos::Right, VPos::Center)))).ok();
        } else {
            root.draw(&PathElement::new(vec![(x, y), (x, y + 5)], BLACK)).ok();
            root.draw(&Text::new(label, (x, y + 8), style.pos(Pos::new(HPos::Center, VPos::Top)))).ok();
        }
    }
}

/// A chart wrapped for the page; `class` and `scale` let readers (and tests) find it.
fn figure(class: &str, title: &str, x_scale: &str, svg: &str) -> String {
    format!("<figure class=\"chart {class}\" data-title=\"{}\" data-x-scale=\"{x_scale}\">{svg}</figure>", esc(title))
}

/// Horizontal bars, one per structure in its colour; on a log axis (for counts spanning
/// decades, such as primitive tests per ray: brute force's thousands beside a tree's one)
/// bars start at the axis' lower end, and zero values get no bar. Each bar is labelled with
/// its value.
fn bar_chart(title: &str, unit: &str, bars: &[(String, f64)], colors: &Colors, log: bool) -> String {
    let mut svg = String::new();
    let h = 70 + 24 * bars.len() as u32;
    {
        let root = SVGBackend::with_string(&mut svg, (560, h)).into_drawing_area();
        root.fill(&WHITE).ok();
        let max = bars.iter().map(|b| b.1).fold(0.0, f64::max).max(1e-9);
        let min_pos = bars.iter().map(|b| b.1).filter(|v| *v > 0.0).fold(f64::MAX, f64::min).min(max);
        // In log mode, x is log10 of the value.
        let (x0, x1) = if log { ((min_pos.log10() - 0.3).floor(), max.log10() + 0.45) } else { (0.0, max * 1.18) };
        let labels: Vec<String> = bars.iter().map(|b| b.0.clone()).collect();
        let Ok(mut chart) = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(8)
            .margin_right(24)
            .x_label_area_size(46)
            .y_label_area_size(110)
            .build_cartesian_2d(x0..x1, (0..bars.len()).into_segmented())
        else {
            return svg_fallback(title);
        };
        let ticks = log_ticks(x0, x1);
        // The first bar on top, as in the table.
        let row = |i: usize| bars.len() - 1 - i;
        let name_of = |v: &SegmentValue<usize>| match v {
            SegmentValue::CenterOf(i) if *i < bars.len() => labels[row(*i)].clone(),
            _ => String::new(),
        };
        let mut mesh = chart.configure_mesh();
        mesh.disable_y_mesh()
            .y_labels(2 * bars.len() + 2)
            .x_desc(if log { format!("{unit} (log scale)") } else { unit.to_string() })
            .x_label_offset(0)
            .y_label_formatter(&name_of);
        let lin = |v: &f64| number(*v);
        let none = |_: &f64| String::new();
        if log {
            mesh.x_labels(2).x_label_formatter(&none).disable_x_mesh().draw().ok();
            draw_log_ticks(&root, &ticks, |t| chart.backend_coord(&(t, SegmentValue::Exact(0))), false);
        } else {
            mesh.x_labels(6).x_label_formatter(&lin).draw().ok();
        }
        chart
            .draw_series(bars.iter().enumerate().filter(|(_, (_, v))| !log || *v > 0.0).map(|(i, (name, v))| {
                let end = if log { v.log10() } else { *v };
                let mut r = Rectangle::new([(x0, SegmentValue::Exact(row(i))), (end, SegmentValue::Exact(row(i) + 1))], colors.of(name).filled());
                r.set_margin(3, 3, 0, 0);
                r
            }))
            .ok();
        chart
            .draw_series(bars.iter().enumerate().map(|(i, (_, v))| {
                let end = if log && *v > 0.0 { v.log10() } else if log { x0 } else { *v };
                Text::new(number(*v), (end, SegmentValue::CenterOf(row(i))), ("sans-serif", 11).into_font().color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center)))
            }))
            .ok();
        root.present().ok();
    }
    svg
}

fn svg_fallback(title: &str) -> String {
    format!("<p>({} could not be drawn)</p>", esc(title))
}

/// The legend of a chart's series as HTML beside it, so that it never covers data.
fn html_legend(names: &[&str], colors: &Colors) -> String {
    let mut h = String::from("<div class=\"legend\">");
    for n in names {
        let c = colors.of(n);
        let _ = write!(h, "<span><i style=\"background:rgb({},{},{})\"></i>{}</span>", c.0, c.1, c.2, esc(n));
    }
    h.push_str("</div>");
    h
}

/// One line per series (a structure, a strategy) through `(x, y)` points, both axes
/// logarithmic with labelled ticks (1, 2, 5 × powers of ten), the legend beside the plot.
pub(crate) fn loglog_chart(title: &str, x_desc: &str, y_desc: &str, series: &BTreeMap<String, Vec<(f64, f64)>>) -> String {
    loglog_chart_in(title, x_desc, y_desc, series, &Colors::new(series.keys().map(String::as_str)))
}

/// [`loglog_chart`] with the report's colours, the legend in their order.
fn loglog_chart_in(title: &str, x_desc: &str, y_desc: &str, series: &BTreeMap<String, Vec<(f64, f64)>>, colors: &Colors) -> String {
    let names: Vec<&str> = colors.0.iter().map(String::as_str).filter(|n| series.contains_key(*n)).collect();
    let svg = loglog_svg(title, x_desc, y_desc, series, colors, &[]);
    if svg.is_empty() {
        return svg;
    }
    format!("<div class=\"plot\">{}{}</div>", figure("loglog", title, "log", &svg), html_legend(&names, colors))
}

/// The SVG of a log–log plot; `front` (indices into the flattened points) are drawn large and
/// joined, for the Pareto plot.
fn loglog_svg(title: &str, x_desc: &str, y_desc: &str, series: &BTreeMap<String, Vec<(f64, f64)>>, colors: &Colors, front: &[(f64, f64)]) -> String {
    let pts: Vec<(f64, f64)> = series.values().flatten().copied().filter(|(x, y)| *x > 0.0 && *y > 0.0).collect();
    if pts.len() < 2 {
        return String::new();
    }
    let (x0, x1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0.log10()), b.max(p.0.log10())));
    let (y0, y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1.log10()), b.max(p.1.log10())));
    // Pad by a tenth of the span (at least a tenth of a decade) so no point sits on the frame.
    let (px, py) = (((x1 - x0) * 0.1).max(0.1), ((y1 - y0) * 0.1).max(0.1));
    let (x0, x1, y0, y1) = (x0 - px, x1 + px, y0 - py, y1 + py);
    let (xt, yt) = (log_ticks(x0, x1), log_ticks(y0, y1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (560, 400)).into_drawing_area();
        root.fill(&WHITE).ok();
        let Ok(mut chart) = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(10)
            .margin_right(36)
            .x_label_area_size(50)
            .y_label_area_size(74)
            .build_cartesian_2d(x0..x1, y0..y1)
        else {
            return svg_fallback(title);
        };
        let none = |_: &f64| String::new();
        chart.configure_mesh().x_desc(format!("{x_desc} (log scale)")).y_desc(format!("{y_desc} (log scale)")).x_labels(2).y_labels(2).x_label_formatter(&none).y_label_formatter(&none).disable_mesh().draw().ok();
        draw_log_ticks(&root, &xt, |t| chart.backend_coord(&(t, y0)), false);
        draw_log_ticks(&root, &yt, |t| chart.backend_coord(&(x0, t)), true);
        // Light grid lines at the labelled ticks only.
        let grid = RGBColor(225, 225, 225);
        for &t in &xt {
            chart.draw_series(LineSeries::new([(t, y0), (t, y1)], grid.stroke_width(1))).ok();
        }
        for &t in &yt {
            chart.draw_series(LineSeries::new([(x0, t), (x1, t)], grid.stroke_width(1))).ok();
        }
        if front.len() >= 2 {
            let f: Vec<(f64, f64)> = front.iter().map(|(x, y)| (x.log10(), y.log10())).collect();
            chart.draw_series(LineSeries::new(f, BLACK.stroke_width(2))).ok();
        }
        for (name, points) in series {
            let color = colors.of(name);
            let mut p: Vec<(f64, f64)> = points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.log10(), y.log10())).collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            if front.is_empty() {
                chart.draw_series(LineSeries::new(p.clone(), color.stroke_width(2))).ok();
            }
            chart.draw_series(p.iter().map(|&(x, y)| Circle::new((x, y), 4, color.filled()))).ok();
        }
        for &(x, y) in front {
            chart.draw_series([Circle::new((x.log10(), y.log10()), 7, BLACK.stroke_width(2))]).ok();
        }
        root.present().ok();
    }
    svg
}

/// The Pareto front of `(build ms, Mrays/s)` points: those no other point beats on both
/// (builds no slower and traces no slower, one of them strictly), by increasing build time.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0).then(points[b].1.total_cmp(&points[a].1)));
    let mut best = f64::NEG_INFINITY;
    let mut front = Vec::new();
    for i in order {
        if points[i].1 > best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

/// Build time against trace speed, one point per structure, the Pareto front joined and ringed
/// (the trade-off plot of Meister et al. 2021, "A Survey on Bounding Volume Hierarchies for Ray
/// Tracing").
fn pareto_chart(kind: &str, rows: &[&BenchResult], colors: &Colors) -> String {
    let pts: Vec<(String, (f64, f64))> = rows.iter().filter_map(|r| Some((r.accel.clone(), (r.build_ms.max(1e-4), r.rays.get(kind)?.mrays_per_s)))).filter(|(_, (_, y))| *y > 0.0).collect();
    if pts.len() < 2 {
        return String::new();
    }
    let xy: Vec<(f64, f64)> = pts.iter().map(|p| p.1).collect();
    let front = pareto_front(&xy);
    let series: BTreeMap<String, Vec<(f64, f64)>> = pts.iter().map(|(n, p)| (n.clone(), vec![*p])).collect();
    let title = format!("Build time against {kind} trace speed");
    let svg = loglog_svg(&title, "build ms", "Mrays/s", &series, colors, &front.iter().map(|&i| xy[i]).collect::<Vec<_>>());
    let names: Vec<&str> = pts.iter().map(|p| p.0.as_str()).collect();
    let on_front: Vec<String> = front.iter().map(|&i| esc(&pts[i].0)).collect();
    format!(
        "<div class=\"plot\">{}{}<p class=\"pareto-front\">Pareto front (ringed, joined; nothing both builds and traces faster): {}</p></div>",
        figure("pareto", &title, "log", &svg),
        html_legend(&names, colors),
        on_front.join(", ")
    )
}

/// The style sheet of the lab's HTML pages.
pub(crate) const STYLE: &str = "body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222} table{border-collapse:collapse;margin:1em 0}\
    td,th{border:1px solid #ccc;padding:3px 8px;text-align:right} th{background:#f2f2f2} td:first-child{text-align:left}\
    .charts{display:flex;flex-wrap:wrap;gap:8px} .thumbs img{width:240px;margin:4px;image-rendering:pixelated} figure{display:inline-block;margin:4px}\
    .plot{display:flex;align-items:flex-start;gap:4px;flex-wrap:wrap} .legend{display:flex;flex-direction:column;font-size:12px;margin-top:40px}\
    .legend i{display:inline-block;width:14px;height:10px;margin-right:5px} .pareto-front{flex-basis:100%;font-size:13px}";

/// The heat maps of one scene's structures, drawn on one shared scale (the most nodes any
/// structure's ray visited) with its legend.
fn heatmaps(report: &BenchReport, scene: &str) -> String {
    let maps: Vec<(&str, u32, u32, Vec<u32>)> = report.heatmaps.iter().filter(|m| m.scene == scene).filter_map(|m| Some((m.accel.as_str(), m.width, m.height, crate::heatmap::unpack(&m.nodes)?))).collect();
    let Some(max) = maps.iter().flat_map(|m| m.3.iter().copied()).max() else { return String::new() };
    let mut h = format!("<h3>Nodes visited per camera ray</h3><p>One colour scale for every structure of this scene: 0 to {max} nodes.</p>{}<div class=\"thumbs\">", legend(max));
    for (accel, w, hgt, counts) in &maps {
        let png = crate::heatmap::to_png(*w, *hgt, counts, max);
        let _ = write!(h, "<figure><img alt=\"{a}\" src=\"data:image/png;base64,{}\"><figcaption>{a}</figcaption></figure>", base64::encode(&png), a = esc(accel));
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
    // One colour per structure across the whole report.
    let colors = Colors::new(report.results.iter().map(|r| r.accel.as_str()));
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
        let bars = |f: &dyn Fn(&BenchResult) -> f64| rows.iter().map(|r| (r.accel.clone(), f(r))).collect::<Vec<_>>();
        h.push_str(&figure("bars", "Build time", "linear", &bar_chart("Build time", "ms", &bars(&|r| r.build_ms), &colors, false)));
        for k in &kinds {
            let t = format!("{k} rays: Mrays/s");
            h.push_str(&figure("bars", &t, "linear", &bar_chart(&t, "Mrays/s", &bars(&|r| r.rays[k].mrays_per_s), &colors, false)));
            let t = format!("{k} rays: nodes visited per ray");
            h.push_str(&figure("bars", &t, "linear", &bar_chart(&t, "nodes / ray", &bars(&|r| r.rays[k].node_visits_per_ray), &colors, false)));
            // Brute force tests every primitive (thousands) where a tree tests one or two.
            let t = format!("{k} rays: primitive tests per ray");
            h.push_str(&figure("bars", &t, "log", &bar_chart(&t, "tests / ray", &bars(&|r| r.rays[k].prim_tests_per_ray), &colors, true)));
        }
        h.push_str("</div>");
        let pareto_kind = if kinds.iter().any(|k| k == "primary") { "primary".to_string() } else { kinds.first().cloned().unwrap_or_default() };
        h.push_str(&pareto_chart(&pareto_kind, &rows, &colors));
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
        h.push_str(&loglog_chart_in("Build time against primitives", "primitives", "build ms", &build, &colors));
        h.push_str(&loglog_chart_in("Time per ray against primitives", "primitives", "ns per ray", &per_ray, &colors));
        h.push_str("</div>");
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{HeatmapRecord, Machine, RayFigures};
    use crate::sweep::{BenchSettings, JobsRecord};

    /// A report of `accels` on two scenes (of 100 and 10,000 primitives), brute force testing
    /// every primitive per ray and the others one to three, with one heat map per structure
    /// (the heat map of structure `i` counts `i` nodes in its first pixel, 1 in its second).
    fn report(accels: &[String]) -> BenchReport {
        let mut results = Vec::new();
        let mut heatmaps = Vec::new();
        for (scene, prims) in [("a.toml", 100usize), ("b.toml", 10_000)] {
            for (i, a) in accels.iter().enumerate() {
                let tests = if i == 0 { prims as f64 } else { 1.0 + (i % 3) as f64 };
                let f = RayFigures { count: 100, hits: 50, t_sum: 1.0, mrays_per_s: 1.0 + i as f64, node_visits_per_ray: 3.0, prim_tests_per_ray: tests, object_tests_per_ray: 0.0 };
                let stats = raylab_accel::AccelStats { name: a.clone(), ..Default::default() };
                results.push(BenchResult { scene: scene.into(), primitives: prims, accel: a.clone(), build_ms: 0.5 + i as f64, memory_bytes: 0, stats, rays: [("primary".to_string(), f)].into() });
                heatmaps.push(HeatmapRecord { scene: scene.into(), accel: a.clone(), width: 2, height: 1, nodes: crate::heatmap::pack(&[i as u32, 1]) });
            }
        }
        let settings = BenchSettings::new(vec![Some("a.toml".into()), Some("b.toml".into())], "all").unwrap();
        BenchReport { machine: Machine { cpu: "test".into(), threads: 1 }, raylab_version: "0".into(), repeats: 1, resolution: 8, results, settings, jobs: JobsRecord { total: 0, shard: None, ran: vec![], skipped: vec![] }, heatmaps }
    }

    /// The chart with `title` (its `<figure>` element).
    fn chart<'a>(html: &'a str, title: &str) -> &'a str {
        let start = html.find(&format!("data-title=\"{title}\"")).unwrap_or_else(|| panic!("no chart {title}"));
        &html[start..start + html[start..].find("</figure>").unwrap()]
    }

    /// Whether an SVG has a text element reading exactly `label` (plotters writes the text on a line of its own).
    fn has_label(svg: &str, label: &str) -> bool {
        svg.contains(&format!(">\n{label}\n</text>"))
    }

    #[test]
    fn every_structure_has_its_own_colour() {
        let names: Vec<String> = (0..24).map(|i| format!("s{i}")).collect();
        let html = html(&report(&names));
        let bars = chart(&html, "Build time");
        let mut fills: Vec<&str> = bars.match_indices("<rect").filter_map(|(i, _)| bars[i..].split("fill=\"").nth(1)?.split('"').next()).filter(|f| *f != "#FFFFFF" && *f != "none").collect();
        fills.sort_unstable();
        fills.dedup();
        assert_eq!(fills.len(), names.len(), "{fills:?}");
        let distinct: std::collections::BTreeSet<(u8, u8, u8)> = (0..200).map(|i| { let c = color(i); (c.0, c.1, c.2) }).collect();
        assert_eq!(distinct.len(), 200);
    }

    #[test]
    fn primitive_tests_are_on_a_log_axis() {
        let names: Vec<String> = ["none", "bvh", "kdtree"].map(String::from).to_vec();
        let html = html(&report(&names));
        let tests = chart(&html, "primary rays: primitive tests per ray");
        assert!(tests.contains("data-x-scale=\"log\""));
        assert!(tests.contains("tests / ray (log scale)"));
        // Ticks at 1, 10, 100 and 1000 (brute force's 10,000 tests on the second scene are
        // beside the first's 100): decades, not a linear axis.
        let html_b = &html[html.find("<h2>b.toml").unwrap()..];
        let tests_b = chart(html_b, "primary rays: primitive tests per ray");
        for tick in ["1", "10", "100", "1000", "10000"] {
            assert!(has_label(tests_b, tick), "{tick}");
        }
        assert!(chart(&html, "primary rays: Mrays/s").contains("data-x-scale=\"linear\""));
    }

    #[test]
    fn heat_maps_share_one_scale_and_a_legend() {
        let names: Vec<String> = ["none", "bvh", "kdtree", "grid"].map(String::from).to_vec();
        let html = html(&report(&names));
        assert_eq!(html.matches("class=\"heat-legend\"").count(), 2, "one legend per scene");
        assert!(html.contains("One colour scale for every structure of this scene: 0 to 3 nodes."));
        // kdtree's 2 nodes are drawn at 2/3 of the scene's maximum, not at the top of its own.
        let shared = base64::encode(crate::heatmap::to_png(2, 1, &[2, 1], 3));
        let own = base64::encode(crate::heatmap::to_png(2, 1, &[2, 1], 2));
        assert!(html.contains(&shared));
        assert!(!html.contains(&own));
    }

    #[test]
    fn the_pareto_plot_rings_the_front() {
        // (build ms, Mrays/s): 0 and 2 are on the front; 1 builds slower than 0 and traces
        // slower than 2; 3 builds slower than 2 without tracing faster.
        assert_eq!(pareto_front(&[(1.0, 2.0), (5.0, 3.0), (4.0, 6.0), (9.0, 6.0)]), [0, 2]);
        assert_eq!(pareto_front(&[]), Vec::<usize>::new());
        let names: Vec<String> = ["none", "bvh", "kdtree"].map(String::from).to_vec();
        let html = html(&report(&names));
        assert!(chart(&html, "Build time against primary trace speed").contains("<svg"));
        // Build time and speed both grow with the index: every structure is on the front.
        assert!(html.contains("Pareto front (ringed, joined; nothing both builds and traces faster): none, bvh, kdtree</p>"));
    }

    #[test]
    fn the_scaling_plot_has_labelled_ticks_and_its_legend_beside_it() {
        let names: Vec<String> = ["bvh", "kdtree"].map(String::from).to_vec();
        let html = html(&report(&names));
        let scaling = chart(&html, "Build time against primitives");
        for tick in ["100", "1000", "10000"] {
            assert!(has_label(scaling, tick), "{tick}");
        }
        let after = &html[html.find("data-title=\"Build time against primitives\"").unwrap()..];
        assert!(after.contains("<div class=\"legend\"><span><i style=\"background:rgb(31,119,180)\"></i>bvh</span>"));
    }
}
