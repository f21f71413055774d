//! Convergence studies: the error of renders against a reference as the sample count grows,
//! per light-sampling strategy — the third seed report's MSE-against-samples study. This
//! module renders the series ([`measure`], shared by `raylab converge` and Python), fits
//! slopes and writes the CSV and the HTML page; the callers parse options and write files.

use std::collections::BTreeMap;
use std::fmt::Write;

use raylab_core::Rgb;
use raylab_render::light::LightSampling;
use raylab_render::Scene;

use crate::report::{esc, loglog_chart, STYLE};

/// The seed of a rendered reference is the renders' seed with these bits flipped: a reference
/// sharing the renders' random streams would correlate with them and understate their error.
pub const REFERENCE_SEED_XOR: u64 = 0x9e37_79b9_7f4a_7c15;

/// Renders `scene` with `strategy` at `spp` and `seed`; none of them needs the acceleration
/// structure rebuilt.
pub fn render_with(scene: &mut Scene, strategy: LightSampling, spp: u32, seed: u64) -> raylab_render::RenderOutput {
    scene.settings.light_sampling = strategy;
    scene.settings.spp = spp;
    scene.settings.seed = seed;
    raylab_render::render(scene, &|_| {})
}

/// What a study renders: each strategy at each sample count, in increasing order.
pub struct Study<'a> {
    pub strategies: &'a [LightSampling],
    pub spps: &'a [u32],
    /// A strategy's series stops after its first render over this many seconds (that render
    /// is still measured).
    pub time_budget: Option<f64>,
    /// Pixels whose reference luminance exceeds this are left out of the errors.
    pub exclude_bright: Option<f32>,
}

/// A strategy's last render of a study.
pub struct FinalImage {
    pub strategy: LightSampling,
    pub spp: u32,
    pub pixels: Vec<Rgb>,
}

/// Renders the study of `scene` (at its own seed) and measures each render against
/// `reference`. `on_point` sees each point as it is measured; `cancelled` is asked before each
/// render and stops the study with the error `interrupted`.
pub fn measure(scene: &mut Scene, reference: &[Rgb], study: &Study, on_point: &mut dyn FnMut(&ConvergencePoint), cancelled: &dyn Fn() -> bool) -> Result<(Vec<ConvergencePoint>, Vec<FinalImage>), String> {
    let (width, seed) = (scene.settings.width, scene.settings.seed);
    let mut points = Vec::new();
    let mut finals = Vec::new();
    for &strategy in study.strategies {
        let mut last = None;
        for &spp in study.spps {
            if cancelled() {
                return Err("interrupted".into());
            }
            let out = render_with(scene, strategy, spp, seed);
            let d = crate::compare::compare(&out.pixels, reference, width, study.exclude_bright).map_err(|e| format!("{strategy} at {spp} spp: {e}"))?;
            let p = ConvergencePoint { strategy: strategy.name().into(), spp, seconds: out.seconds, mse: d.mse, rmse: d.rmse, rel_mse: d.rel_mse };
            on_point(&p);
            points.push(p);
            let over = study.time_budget.is_some_and(|t| out.seconds > t);
            last = Some((spp, out.pixels));
            if over {
                break;
            }
        }
        if let Some((spp, pixels)) = last {
            finals.push(FinalImage { strategy, spp, pixels });
        }
    }
    Ok((points, finals))
}

/// One render of a study, measured against the reference.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergencePoint {
    pub strategy: String,
    pub spp: u32,
    /// Render time (the scene's acceleration structure is built once, outside it).
    pub seconds: f64,
    pub mse: f64,
    pub rmse: f64,
    pub rel_mse: f64,
}

/// An image shown on the page, encoded as PNG.
pub struct LabelledImage {
    pub label: String,
    pub png: Vec<u8>,
}

/// The slope of the least-squares line through `(ln x, ln y)`: MSE ∝ x^slope.
///
/// An unbiased Monte Carlo estimator with independent samples has variance ∝ 1/N, so its MSE
/// against an exact reference falls with slope −1 against spp; stratified (jittered) and
/// Sobol samples reach steeper slopes on smooth integrands, and a biased one flattens out
/// at its bias. Points with a non-positive `x` or `y` (a render equal to the reference) have
/// no logarithm and are skipped; `None` when fewer than two distinct `x` remain.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = logs.len() as f64;
    let (mx, my) = logs.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx) = logs.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + (x - mx) * (y - my), b + (x - mx) * (x - mx)));
    (logs.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

/// The strategies of `points` in order of first appearance.
pub fn strategies(points: &[ConvergencePoint]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for p in points {
        if !names.contains(&p.strategy.as_str()) {
            names.push(&p.strategy);
        }
    }
    names
}

/// The fitted slope of MSE against spp for one strategy (see [`loglog_slope`]).
pub fn spp_slope(points: &[ConvergencePoint], strategy: &str) -> Option<f64> {
    loglog_slope(&points.iter().filter(|p| p.strategy == strategy).map(|p| (p.spp as f64, p.mse)).collect::<Vec<_>>())
}

/// The points as CSV, header `strategy,spp,seconds,mse,rmse,rel_mse`, one row per render;
/// numbers in Rust's shortest round-trip notation.
pub fn csv(points: &[ConvergencePoint]) -> String {
    let mut s = String::from("strategy,spp,seconds,mse,rmse,rel_mse\n");
    for p in points {
        let _ = writeln!(s, "{},{},{},{},{},{}", p.strategy, p.spp, p.seconds, p.mse, p.rmse, p.rel_mse);
    }
    s
}

/// The study as one self-contained HTML page: `intro` (plain text) on top, log–log charts of MSE
/// against spp and against seconds, a table of the fitted slopes and final errors, and the
/// `images` side by side.
pub fn html(intro: &str, points: &[ConvergencePoint], images: &[LabelledImage]) -> String {
    let mut h = format!("<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>raylab converge</title><style>{STYLE}</style></head><body><h1>raylab converge</h1><p>{}</p>", esc(intro));
    let series = |x: fn(&ConvergencePoint) -> f64| {
        let mut m: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        for p in points {
            m.entry(p.strategy.clone()).or_default().push((x(p), p.mse));
        }
        m
    };
    h.push_str("<div class=\"charts\">");
    h.push_str(&loglog_chart("MSE against samples per pixel", "spp", "MSE", &series(|p| p.spp as f64)));
    h.push_str(&loglog_chart("MSE against render time", "seconds", "MSE", &series(|p| p.seconds)));
    h.push_str("</div><table><tr><th>strategy</th><th>slope of MSE against spp</th><th>renders</th><th>last spp</th><th>seconds</th><th>MSE</th><th>relative MSE</th></tr>");
    for name in strategies(points) {
        let last = points.iter().rfind(|p| p.strategy == name).expect("a strategy has points");
        let slope = spp_slope(points, name).map_or("–".into(), |s| format!("{s:.3}"));
        let renders = points.iter().filter(|p| p.strategy == name).count();
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{slope}</td><td>{renders}</td><td>{}</td><td>{:.3}</td><td>{:.4e}</td><td>{:.4e}</td></tr>",
            esc(name),
            last.spp,
            last.seconds,
            last.mse,
            last.rel_mse
        );
    }
    h.push_str("</table><div class=\"thumbs\">");
    for i in images {
        let _ = write!(h, "<figure><img alt=\"{l}\" src=\"data:image/png;base64,{}\"><figcaption>{l}</figcaption></figure>", base64::encode(&i.png), l = esc(&i.label));
    }
    h.push_str("</div></body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(strategy: &str, spp: u32, mse: f64) -> ConvergencePoint {
        ConvergencePoint { strategy: strategy.into(), spp, seconds: spp as f64 * 0.01, mse, rmse: mse.sqrt(), rel_mse: 2.0 * mse }
    }

    #[test]
    fn the_slope_of_a_power_law_is_exact() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0, 64.0].iter().map(|&n| (n, 3.0 / n)).collect();
        assert!((loglog_slope(&pts).unwrap() + 1.0).abs() < 1e-12);
        let pts: Vec<(f64, f64)> = [1.0, 4.0, 16.0].iter().map(|&n: &f64| (n, 0.5 * n.powf(-1.5))).collect();
        assert!((loglog_slope(&pts).unwrap() + 1.5).abs() < 1e-12);
    }

    #[test]
    fn the_slope_needs_two_distinct_positive_points() {
        assert_eq!(loglog_slope(&[]), None);
        assert_eq!(loglog_slope(&[(4.0, 1.0)]), None);
        assert_eq!(loglog_slope(&[(4.0, 1.0), (4.0, 2.0)]), None);
        // A zero error (a render equal to the reference) is skipped, not a -∞.
        assert_eq!(loglog_slope(&[(1.0, 1.0), (2.0, 0.0)]), None);
        assert!((loglog_slope(&[(1.0, 1.0), (2.0, 0.0), (4.0, 0.25)]).unwrap() + 1.0).abs() < 1e-12);
    }

    #[test]
    fn slopes_are_fitted_per_strategy() {
        let pts: Vec<ConvergencePoint> = [1, 2, 4, 8].iter().flat_map(|&n| [point("mis", n, 3.0 / n as f64), point("bsdf", n, 5.0 / (n * n) as f64)]).collect();
        assert_eq!(strategies(&pts), ["mis", "bsdf"]);
        assert!((spp_slope(&pts, "mis").unwrap() + 1.0).abs() < 1e-12);
        assert!((spp_slope(&pts, "bsdf").unwrap() + 2.0).abs() < 1e-12);
        assert_eq!(spp_slope(&pts, "uniform"), None);
    }

    #[test]
    fn csv_has_a_header_and_one_row_per_point() {
        let s = csv(&[point("mis", 1, 0.25), point("solid-angle", 16, 0.0625)]);
        assert_eq!(s, "strategy,spp,seconds,mse,rmse,rel_mse\nmis,1,0.01,0.25,0.5,0.5\nsolid-angle,16,0.16,0.0625,0.25,0.125\n");
    }

    #[test]
    fn the_page_has_both_charts_the_slopes_and_the_images() {
        let pts: Vec<ConvergencePoint> = [1, 4, 16].iter().map(|&n| point("mis", n, 3.0 / n as f64)).collect();
        let page = html("a <b>study</b>", &pts, &[LabelledImage { label: "mis, 16 spp".into(), png: b"foo".to_vec() }]);
        assert_eq!(page.matches("<svg").count(), 2);
        assert!(page.contains("<td>mis</td><td>-1.000</td><td>3</td><td>16</td>"), "{page}");
        assert!(page.contains("src=\"data:image/png;base64,Zm9v\""));
        assert!(page.contains("<p>a &lt;b&gt;study&lt;/b&gt;</p>"));
    }
}
