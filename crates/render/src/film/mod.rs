//! The film: per-pixel sample sums for a crop window and a range of sample passes, which
//! merges with other films of the same scene and settings and resolves to the image.
//!
//! # Summation order (why any split gives the same bytes)
//!
//! Samples are grouped into *passes* of `pass_samples` consecutive sample indices (the last
//! pass may be shorter). A pass's value at a pixel is the `f64` sum of its samples in index
//! order, starting from 0. Passes are then combined along a fixed binary tree over pass
//! indices: a *block* of `2^k` passes starting at a multiple of `2^k` is the sum
//! `left + right` of its two half blocks. A film holds the maximal such blocks inside the
//! passes it covers (the binary-counter decomposition; at most ~log2(passes) of them), and
//! the resolved pixel is `((0 + B0) + B1) + ...` over those blocks in pass order, divided by
//! the number of samples.
//!
//! Each block's value is fixed by the tree alone, and the set of maximal blocks depends
//! only on the covered pass range, so a film rendered in one go, pass by pass with
//! interruptions and resumes, or in sample ranges merged later holds the same blocks with
//! the same bits. Pixels are independent, so tiles and crops merge trivially. `f64` keeps the
//! sum of millions of `f32` samples accurate; the image is rounded to `f32` once, at resolve.

pub mod atomic;
pub mod codec;
pub mod image_out;

use std::fmt;
use std::ops::Range;

use raylab_accel::Counters;
use raylab_core::Rgb;

/// Values kept per pixel per block: the RGB sum and the sum of squared luminance (for the
/// variance of the pixel estimate).
pub const CHANNELS: usize = 4;

/// Samples per pass unless a caller chooses otherwise: small enough for frequent
/// checkpoints and a responsive Ctrl-C, large enough that the per-pass overhead is nil.
pub const DEFAULT_PASS_SAMPLES: u32 = 16;

/// A pixel rectangle `[x0, x1) × [y0, y1)` of the full image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Crop {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Crop {
    pub fn full(width: u32, height: u32) -> Self {
        Self { x0: 0, y0: 0, x1: width, y1: height }
    }
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    pub fn pixels(&self) -> usize {
        self.width() as usize * self.height() as usize
    }
    /// Tile `index` of `count`: horizontal bands of whole rows, sizes differing by at most
    /// one row, together covering the image exactly once.
    pub fn tile(width: u32, height: u32, index: u32, count: u32) -> Result<Self, FilmError> {
        if count == 0 || index >= count {
            return Err(FilmError::Invalid(format!("tile {index}/{count}: the index must be below the count (tiles are numbered from 0)")));
        }
        if count > height {
            return Err(FilmError::Invalid(format!("tile {index}/{count}: the image has only {height} rows, so at most {height} tiles")));
        }
        let row = |i: u32| (i as u64 * height as u64 / count as u64) as u32;
        Ok(Self { x0: 0, y0: row(index), x1: width, y1: row(index + 1) })
    }
    /// Checks the crop is non-empty and inside a `width × height` image.
    pub fn check(&self, width: u32, height: u32) -> Result<(), FilmError> {
        if self.x0 >= self.x1 || self.y0 >= self.y1 || self.x1 > width || self.y1 > height {
            return Err(FilmError::Invalid(format!("crop {self} is empty or outside the {width}×{height} image")));
        }
        Ok(())
    }
    fn overlaps(&self, o: &Crop) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
}

impl fmt::Display for Crop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// What a film belongs to: two films merge only if their headers are equal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FilmHeader {
    /// Full image size.
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the complete render.
    pub spp: u32,
    pub pass_samples: u32,
    /// Fingerprint of the scene's contents (geometry, materials, lights, camera, ...).
    pub scene_hash: u64,
    /// Fingerprint of the render settings (size, spp, sampler, integrator, seed, ...).
    pub settings_hash: u64,
    /// The raylab version that rendered it (sampling code may change between versions).
    pub version: String,
    /// Whether resolve colourises the heat map (done on the full image only).
    pub heatmap: bool,
}

impl FilmHeader {
    pub fn passes(&self) -> u32 {
        self.spp.div_ceil(self.pass_samples)
    }
    /// Sample indices of pass `p`.
    pub fn pass_range(&self, p: u32) -> Range<u32> {
        p * self.pass_samples..((p + 1) * self.pass_samples).min(self.spp)
    }
    /// The passes covering sample range `samples`, which must start and end on pass boundaries.
    pub fn passes_of(&self, samples: &Range<u32>) -> Result<Range<u32>, FilmError> {
        let k = self.pass_samples;
        if k == 0 {
            return Err(FilmError::Invalid("the pass size must be at least 1 sample".into()));
        }
        let aligned = |s: u32| s.is_multiple_of(k) || s == self.spp;
        if samples.start >= samples.end || samples.end > self.spp || !aligned(samples.start) || !aligned(samples.end) {
            return Err(FilmError::Invalid(format!(
                "samples {}..{} must be a non-empty range within 0..{} starting and ending on a multiple of the pass size {k}",
                samples.start, samples.end, self.spp
            )));
        }
        Ok(samples.start / k..samples.end.div_ceil(k))
    }
    /// Why `other` cannot be merged with or resumed into a film of this header, if it cannot.
    pub fn mismatch(&self, other: &FilmHeader) -> Option<String> {
        if self.version != other.version {
            return Some(format!("it was rendered by raylab {}, this is raylab {}", other.version, self.version));
        }
        if self.scene_hash != other.scene_hash {
            return Some(format!("it is of another scene (scene hash {:016x}, expected {:016x})", other.scene_hash, self.scene_hash));
        }
        if self.settings_hash != other.settings_hash || self.width != other.width || self.height != other.height || self.spp != other.spp || self.pass_samples != other.pass_samples || self.heatmap != other.heatmap {
            return Some(format!(
                "it has other render settings ({}×{}, {} spp in passes of {}, settings hash {:016x}; expected {}×{}, {} spp in passes of {}, settings hash {:016x})",
                other.width, other.height, other.spp, other.pass_samples, other.settings_hash, self.width, self.height, self.spp, self.pass_samples, self.settings_hash
            ));
        }
        None
    }
}

/// Errors of films: mismatched merges, bad ranges, corrupt files.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum FilmError {
    #[error("{0}")]
    Invalid(String),
    #[error("cannot merge: {0}")]
    Mismatch(String),
    #[error("not a raylab film: {0}")]
    Corrupt(String),
}

/// The sums of the passes `first..first + count` (`count` a power of two, `first` a
/// multiple of it) over the film's crop, `CHANNELS` values per pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub first: u32,
    pub count: u32,
    pub sums: Vec<f64>,
}

impl Block {
    fn end(&self) -> u32 {
        self.first + self.count
    }
    /// Whether `next` is this block's right sibling in the pass tree.
    fn is_left_sibling_of(&self, next: &Block) -> bool {
        self.count == next.count && self.first.is_multiple_of(2 * self.count) && next.first == self.end()
    }
}

/// Per-pixel sample sums for a crop window and a contiguous range of passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub header: FilmHeader,
    pub crop: Crop,
    /// Maximal blocks of the pass tree, in pass order, contiguous.
    blocks: Vec<Block>,
    /// Traversal work of the passes held (summed on merge).
    pub counters: Counters,
    /// Samples that came out NaN or infinite and were dropped (counted, never summed).
    pub nonfinite_samples: u64,
}

impl Film {
    /// An empty film (no passes yet) for `crop` of the image described by `header`.
    pub fn new(header: FilmHeader, crop: Crop) -> Result<Self, FilmError> {
        if header.pass_samples == 0 || header.spp == 0 {
            return Err(FilmError::Invalid("spp and the pass size must be at least 1".into()));
        }
        crop.check(header.width, header.height)?;
        Ok(Self { header, crop, blocks: Vec::new(), counters: Counters::default(), nonfinite_samples: 0 })
    }

    /// The passes this film holds (empty range at 0 for a new film).
    pub fn passes(&self) -> Range<u32> {
        match (self.blocks.first(), self.blocks.last()) {
            (Some(a), Some(b)) => a.first..b.end(),
            _ => 0..0,
        }
    }

    /// The sample indices this film holds.
    pub fn samples(&self) -> Range<u32> {
        let p = self.passes();
        if p.is_empty() {
            return 0..0;
        }
        self.header.pass_range(p.start).start..self.header.pass_range(p.end - 1).end
    }

    /// Whether the film holds every pixel and every sample of the image.
    pub fn is_complete(&self) -> bool {
        self.crop == Crop::full(self.header.width, self.header.height) && self.samples() == (0..self.header.spp)
    }

    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Appends the sums of pass `pass` (`CHANNELS` per crop pixel), which must directly follow
    /// the passes held, and folds completed sibling blocks together.
    pub fn add_pass(&mut self, pass: u32, sums: Vec<f64>, counters: &Counters, nonfinite: u64) -> Result<(), FilmError> {
        if sums.len() != self.crop.pixels() * CHANNELS {
            return Err(FilmError::Invalid(format!("pass {pass}: {} values for {} pixels", sums.len(), self.crop.pixels())));
        }
        let held = self.passes();
        if pass >= self.header.passes() || (!held.is_empty() && pass != held.end) {
            return Err(FilmError::Invalid(format!("pass {pass} does not follow the passes {}..{} held (of {})", held.start, held.end, self.header.passes())));
        }
        self.blocks.push(Block { first: pass, count: 1, sums });
        self.counters.merge(counters);
        self.nonfinite_samples += nonfinite;
        canonicalize(&mut self.blocks);
        Ok(())
    }

    /// Merges films of the same header: same crop and adjoining pass ranges (in any order),
    /// or disjoint crops holding the same passes. Anything else is an error, so the parts of
    /// a merged image cover it exactly once.
    pub fn merge_all(mut parts: Vec<Film>) -> Result<Film, FilmError> {
        let Some(first) = parts.first() else { return Err(FilmError::Invalid("nothing to merge".into())) };
        let header = first.header.clone();
        for (i, p) in parts.iter().enumerate() {
            if let Some(why) = header.mismatch(&p.header) {
                return Err(FilmError::Mismatch(format!("part {} does not match part 1: {why}", i + 1)));
            }
            if p.blocks.is_empty() {
                return Err(FilmError::Mismatch(format!("part {} holds no samples", i + 1)));
            }
        }
        // Same crop: join the sample ranges.
        parts.sort_by_key(|p| (p.crop, p.passes().start));
        let mut by_crop: Vec<Film> = Vec::new();
        for p in parts {
            match by_crop.last_mut() {
                Some(last) if last.crop == p.crop => last.join_passes(p)?,
                _ => by_crop.push(p),
            }
        }
        if by_crop.len() == 1 {
            return Ok(by_crop.pop().unwrap());
        }
        // Disjoint crops holding the same passes: paste into their bounding box, which they
        // must fill exactly (no overlap, areas summing to the box).
        let passes = by_crop[0].passes();
        for (i, a) in by_crop.iter().enumerate() {
            if a.passes() != passes {
                return Err(FilmError::Mismatch(format!("crop {} holds samples {:?}, crop {} holds {:?}", a.crop, a.samples(), by_crop[0].crop, by_crop[0].samples())));
            }
            if let Some(b) = by_crop[i + 1..].iter().find(|b| a.crop.overlaps(&b.crop)) {
                return Err(FilmError::Mismatch(format!("crops {} and {} overlap: a pixel would be counted twice", a.crop, b.crop)));
            }
        }
        let bbox = by_crop.iter().fold(by_crop[0].crop, |c, f| Crop { x0: c.x0.min(f.crop.x0), y0: c.y0.min(f.crop.y0), x1: c.x1.max(f.crop.x1), y1: c.y1.max(f.crop.y1) });
        let area: usize = by_crop.iter().map(|f| f.crop.pixels()).sum();
        if area != bbox.pixels() {
            return Err(FilmError::Mismatch(format!("the crops leave {} pixels of {} uncovered", bbox.pixels() - area, bbox)));
        }
        let mut out = Film::new(header, bbox)?;
        out.blocks = by_crop[0].blocks.iter().map(|b| Block { first: b.first, count: b.count, sums: vec![0.0; bbox.pixels() * CHANNELS] }).collect();
        for f in &by_crop {
            for (dst, src) in out.blocks.iter_mut().zip(&f.blocks) {
                for y in f.crop.y0..f.crop.y1 {
                    let s = ((y - f.crop.y0) * f.crop.width()) as usize * CHANNELS;
                    let d = ((y - bbox.y0) * bbox.width() + f.crop.x0 - bbox.x0) as usize * CHANNELS;
                    let n = f.crop.width() as usize * CHANNELS;
                    dst.sums[d..d + n].copy_from_slice(&src.sums[s..s + n]);
                }
            }
            out.counters.merge(&f.counters);
            out.nonfinite_samples += f.nonfinite_samples;
        }
        Ok(out)
    }

    /// Appends `next`'s passes (same crop), which must follow this film's directly.
    fn join_passes(&mut self, next: Film) -> Result<(), FilmError> {
        let (a, b) = (self.samples(), next.samples());
        if b.start != a.end {
            let why = if b.start < a.end { "overlap: samples would be counted twice" } else { "leave a gap" };
            return Err(FilmError::Mismatch(format!("crop {}: samples {}..{} and {}..{} {why}", self.crop, a.start, a.end, b.start, b.end)));
        }
        self.blocks.extend(next.blocks);
        self.counters.merge(&next.counters);
        self.nonfinite_samples += next.nonfinite_samples;
        canonicalize(&mut self.blocks);
        Ok(())
    }

    /// The crop's image: each pixel's sum over the blocks in pass order, divided by the
    /// samples held, in `f32`. A heat-map film of the whole frame is colourised here (its
    /// scale is the frame's maximum, so tiles are colourised only once merged).
    pub fn resolve(&self) -> Vec<Rgb> {
        let n = self.samples().len().max(1) as f64;
        let mut pixels: Vec<Rgb> = (0..self.crop.pixels())
            .map(|i| {
                let mut sum = [0.0f64; 3];
                for b in &self.blocks {
                    for (c, s) in sum.iter_mut().enumerate() {
                        *s += b.sums[i * CHANNELS + c];
                    }
                }
                Rgb::new((sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32)
            })
            .collect();
        if self.header.heatmap && self.crop == Crop::full(self.header.width, self.header.height) {
            crate::integrator::heatmap::colorize(&mut pixels, self.crop.width(), self.crop.height());
        }
        pixels
    }

    /// Per-pixel variance of the estimate of the luminance mean (sample variance / n), from
    /// the sums of luminance and squared luminance; 0 where fewer than two samples.
    pub fn variance(&self) -> Vec<f32> {
        let n = self.samples().len() as f64;
        (0..self.crop.pixels())
            .map(|i| {
                if n < 2.0 {
                    return 0.0;
                }
                let (mut s, mut s2) = (0.0f64, 0.0f64);
                for b in &self.blocks {
                    let v = &b.sums[i * CHANNELS..(i + 1) * CHANNELS];
                    s += luminance(v[0], v[1], v[2]);
                    s2 += v[3];
                }
                (((s2 - s * s / n) / (n - 1.0)).max(0.0) / n) as f32
            })
            .collect()
    }
}

/// Rec. 709 luminance.
pub fn luminance(r: f64, g: f64, b: f64) -> f64 {
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// Folds adjacent sibling blocks (`left + right`, pixel by pixel) until none are left: the
/// maximal-block decomposition, whatever order the passes arrived in.
fn canonicalize(blocks: &mut Vec<Block>) {
    blocks.sort_by_key(|b| b.first);
    let mut i = 0;
    while i + 1 < blocks.len() {
        if blocks[i].is_left_sibling_of(&blocks[i + 1]) {
            let right = blocks.remove(i + 1);
            let left = &mut blocks[i];
            for (l, r) in left.sums.iter_mut().zip(&right.sums) {
                *l += r;
            }
            left.count *= 2;
            // The merged block may now complete a sibling pair with the one before it.
            i = i.saturating_sub(1);
        } else {
            i += 1;
        }
    }
}

#[cfg(test)]
mod tests;
