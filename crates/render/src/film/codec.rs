//! The binary film format of checkpoints and partial films: little endian,
//!
//! ```text
//! magic "RAYLABFM", u32 format version,
//! u32 width, height, spp, pass_samples, u8 heatmap, u64 scene_hash, settings_hash,
//! u16 version length + UTF-8 version,
//! u32 crop x0 y0 x1 y1, u64 nonfinite, rays, nodes_visited, prim_tests, object_tests,
//! u32 block count, then per block: u32 first, u32 count, pixels × CHANNELS f64,
//! u64 FNV-1a checksum of everything before it.
//! ```
//!
//! Nothing read from a file is trusted: the size the header implies is computed with
//! checked arithmetic and compared with the bytes present before anything is allocated,
//! and the blocks must be the maximal blocks of a contiguous pass range.

use raylab_accel::Counters;

use super::{Block, Crop, Film, FilmError, FilmHeader, CHANNELS};

const MAGIC: &[u8; 8] = b"RAYLABFM";
/// Bumped whenever the layout changes; older files are refused with a clear message.
pub const FORMAT_VERSION: u32 = 1;
/// More blocks than a 2^32-pass render could ever need: a sign of corruption.
const MAX_BLOCKS: u32 = 64;

/// FNV-1a, 64 bit: stable across platforms and compiler versions (unlike `DefaultHasher`),
/// used for the checksum here and for the scene and settings fingerprints.
#[derive(Clone, Copy, Debug)]
pub struct Fnv64(pub u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

impl std::fmt::Write for Fnv64 {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.update(s.as_bytes());
        Ok(())
    }
}

impl Film {
    /// The film in the binary format above.
    pub fn to_bytes(&self) -> Vec<u8> {
        let h = &self.header;
        let mut out = Vec::with_capacity(128 + self.blocks.iter().map(|b| 8 + b.sums.len() * 8).sum::<usize>());
        out.extend_from_slice(MAGIC);
        for v in [FORMAT_VERSION, h.width, h.height, h.spp, h.pass_samples] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.push(h.heatmap as u8);
        out.extend_from_slice(&h.scene_hash.to_le_bytes());
        out.extend_from_slice(&h.settings_hash.to_le_bytes());
        let version = &h.version.as_bytes()[..h.version.len().min(u16::MAX as usize)];
        out.extend_from_slice(&(version.len() as u16).to_le_bytes());
        out.extend_from_slice(version);
        for v in [self.crop.x0, self.crop.y0, self.crop.x1, self.crop.y1] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let c = &self.counters;
        for v in [self.nonfinite_samples, c.rays, c.nodes_visited, c.prim_tests, c.object_tests] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(self.blocks.len() as u32).to_le_bytes());
        for b in &self.blocks {
            out.extend_from_slice(&b.first.to_le_bytes());
            out.extend_from_slice(&b.count.to_le_bytes());
            for v in &b.sums {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        let mut sum = Fnv64::default();
        sum.update(&out);
        out.extend_from_slice(&sum.0.to_le_bytes());
        out
    }

    /// Reads a film written by [`Film::to_bytes`], checking every count against the bytes
    /// present before allocating.
    pub fn from_bytes(bytes: &[u8]) -> Result<Film, FilmError> {
        let corrupt = |m: String| FilmError::Corrupt(m);
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(corrupt("wrong magic bytes (expected RAYLABFM)".into()));
        }
        if bytes.len() < MAGIC.len() + 8 {
            return Err(corrupt(format!("truncated ({} bytes)", bytes.len())));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let mut sum = Fnv64::default();
        sum.update(body);
        let mut r = Reader { bytes: body, at: MAGIC.len() };
        let format = r.u32()?;
        if format != FORMAT_VERSION {
            return Err(corrupt(format!("film format version {format}, this raylab reads version {FORMAT_VERSION}")));
        }
        if u64::from_le_bytes(tail.try_into().unwrap()) != sum.0 {
            return Err(corrupt("checksum mismatch: the file is truncated or damaged".into()));
        }
        let (width, height, spp, pass_samples) = (r.u32()?, r.u32()?, r.u32()?, r.u32()?);
        let heatmap = match r.take(1)?[0] {
            0 => false,
            1 => true,
            v => return Err(corrupt(format!("heatmap flag {v} is neither 0 nor 1"))),
        };
        let (scene_hash, settings_hash) = (r.u64()?, r.u64()?);
        let len = u16::from_le_bytes(r.take(2)?.try_into().unwrap()) as usize;
        let version = String::from_utf8(r.take(len)?.to_vec()).map_err(|_| corrupt("the version is not UTF-8".into()))?;
        let header = FilmHeader { width, height, spp, pass_samples, scene_hash, settings_hash, version, heatmap };
        let crop = Crop { x0: r.u32()?, y0: r.u32()?, x1: r.u32()?, y1: r.u32()? };
        let mut film = Film::new(header, crop).map_err(|e| corrupt(e.to_string()))?;
        film.nonfinite_samples = r.u64()?;
        film.counters = Counters { rays: r.u64()?, nodes_visited: r.u64()?, prim_tests: r.u64()?, object_tests: r.u64()? };
        let count = r.u32()?;
        if count > MAX_BLOCKS {
            return Err(corrupt(format!("{count} blocks (at most {MAX_BLOCKS})")));
        }
        let values = crop.pixels().checked_mul(CHANNELS).ok_or_else(|| corrupt("crop too large".into()))?;
        let block_bytes = values.checked_mul(8).and_then(|n| n.checked_add(8)).ok_or_else(|| corrupt("crop too large".into()))?;
        let expected = (count as usize).checked_mul(block_bytes).ok_or_else(|| corrupt("size overflows".into()))?;
        if r.remaining() != expected {
            return Err(corrupt(format!("the header announces {count} blocks of {} pixels ({expected} bytes) but {} bytes follow", crop.pixels(), r.remaining())));
        }
        let passes = film.header.passes();
        let mut end = None;
        for _ in 0..count {
            let (first, n) = (r.u32()?, r.u32()?);
            let valid = n.is_power_of_two() && first % n == 0 && first.checked_add(n).is_some_and(|e| e <= passes) && end.is_none_or(|e| e == first);
            if !valid {
                return Err(corrupt(format!("block of passes {first}+{n} is not an aligned block following the previous one (of {passes} passes)")));
            }
            end = Some(first + n);
            let sums = r.take(values * 8)?.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect();
            film.blocks.push(Block { first, count: n, sums });
        }
        let before = film.blocks.iter().map(|b| (b.first, b.count)).collect::<Vec<_>>();
        super::canonicalize(&mut film.blocks);
        if film.blocks.iter().map(|b| (b.first, b.count)).ne(before) {
            return Err(corrupt("its blocks are not the maximal blocks of their passes".into()));
        }
        Ok(film)
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], FilmError> {
        let s = self.bytes.get(self.at..self.at.saturating_add(n)).ok_or_else(|| FilmError::Corrupt(format!("truncated at byte {}", self.at)))?;
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, FilmError> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn u64(&mut self) -> Result<u64, FilmError> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }
}
