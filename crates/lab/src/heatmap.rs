//! Heat maps of traversal cost: nodes visited by each camera ray, recorded as raw counts so
//! that every structure of a scene can be drawn on one shared scale (and merged from shards).

use rayon::prelude::*;
use raylab_accel::{Accel, AnyAccel, Counters, Primitives};
use raylab_core::{Ray, Rgb};
use raylab_render::film::image_out::{encode_png, Tonemap};
use raylab_render::integrator::heatmap::ramp;

/// Nodes visited by each ray (closest hit, counting traversal).
pub fn nodes_per_ray<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: &[Ray]) -> Vec<u32> {
    rays.par_iter()
        .map(|r| {
            let mut c = Counters::default();
            accel.intersect(prims, r, &mut c);
            c.nodes_visited.min(u32::MAX as u64) as u32
        })
        .collect()
}

/// Counts as base64 of little-endian `u16` (saturated at 65,535: no structure that works visits
/// that many nodes per ray, and saturation only flattens the top of the scale).
pub fn pack(counts: &[u32]) -> String {
    let bytes: Vec<u8> = counts.iter().flat_map(|&n| (n.min(u16::MAX as u32) as u16).to_le_bytes()).collect();
    base64::encode(bytes)
}

/// The counts of [`pack`]; `None` when `text` is not such base64 or its length is odd.
pub fn unpack(text: &str) -> Option<Vec<u32>> {
    let bytes = base64::decode(text).ok()?;
    (bytes.len() % 2 == 0).then(|| bytes.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]]) as u32).collect())
}

/// The counts as a PNG in false colour, `0..=max` mapped onto the ramp of the renderer's heat
/// maps (so that thumbnails drawn with the same `max` compare).
pub fn to_png(width: u32, height: u32, counts: &[u32], max: u32) -> Vec<u8> {
    let max = max.max(1) as f32;
    let pixels: Vec<Rgb> = counts.iter().map(|&n| ramp(n as f32 / max)).collect();
    encode_png(width, height, &pixels, Tonemap::Clamp, 0.0).unwrap_or_default()
}

/// The ramp's colour at `x` in 8-bit sRGB, as a browser shows it (for the legend).
pub fn display_rgb(x: f32) -> [u8; 3] {
    let c = ramp(x);
    [c.x, c.y, c.z].map(|v| (raylab_core::color::linear_to_srgb(v).clamp(0.0, 1.0) * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_round_trip_through_base64() {
        for counts in [vec![], vec![7], vec![0, 1, 255, 256, 65535], vec![3, 70000]] {
            let back = unpack(&pack(&counts)).unwrap();
            let want: Vec<u32> = counts.iter().map(|&n| n.min(65535)).collect();
            assert_eq!(back, want);
        }
        // Two counts: bytes 01 00 02 01 → "AQACAQ==".
        assert_eq!(pack(&[1, 258]), "AQACAQ==");
        assert_eq!(unpack("AQACAQ=="), Some(vec![1, 258]));
        assert_eq!(unpack("AQ*="), None);
        // One byte is half a count.
        assert_eq!(unpack("AQ=="), None);
        // The `base64` crate reads unpadded text too.
        assert_eq!(unpack("AQA"), Some(vec![1]));
    }
}
