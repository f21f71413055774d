//! Finding the files a scene names: next to the scene first, then in a `shared/scenes`
//! folder of any ancestor directory (where raylab keeps its large test meshes), or, for the
//! embedded default scene, in the binary itself.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use crate::error::{text_from_bytes, LoadError};
use raylab_render::memory_guard::human;

/// Reads a scene's text (at most [`MAX_SCENE_BYTES`]), naming the file in every error, and
/// the line of the first byte that is not UTF-8.
pub fn read_text(path: &Path) -> Result<String, LoadError> {
    text_from_bytes(path, read_capped(path, MAX_SCENE_BYTES)?)
}

/// Files compiled into the binary for the default scene.
const EMBEDDED: &[(&str, &[u8])] = &[("bunny_4968.obj", include_bytes!("../../../assets/bunny_4968.obj"))];

/// Resolves file names relative to a scene.
#[derive(Clone, Debug)]
pub enum Resolver {
    /// Paths relative to this directory, then `shared/scenes` of its ancestors.
    Disk { base: PathBuf },
    /// Only the embedded assets.
    Embedded,
}

/// A file found by a [`Resolver`].
#[derive(Clone, Debug)]
pub enum Found {
    Disk(PathBuf),
    Embedded(&'static str, &'static [u8]),
}

impl Found {
    /// The path to show in messages.
    pub fn path(&self) -> PathBuf {
        match self {
            Found::Disk(p) => p.clone(),
            Found::Embedded(name, _) => PathBuf::from(format!("<embedded>/{name}")),
        }
    }

    /// The file's bytes, gunzipped when the name ends in `.gz`.
    pub fn read(&self) -> Result<Vec<u8>, LoadError> {
        let path = self.path();
        let raw = match self {
            Found::Disk(p) => read_capped(p, MAX_DATA_BYTES)?,
            Found::Embedded(_, bytes) => bytes.to_vec(),
        };
        if path.extension().is_some_and(|e| e == "gz") {
            // Capped too: a few kilobytes of gzip can expand to terabytes.
            let mut out = Vec::new();
            flate2::read::GzDecoder::new(raw.as_slice()).take(MAX_DATA_BYTES + 1).read_to_end(&mut out).map_err(|e| LoadError::file(&path, format!("cannot decompress: {e}")))?;
            if out.len() as u64 > MAX_DATA_BYTES {
                return Err(LoadError::file(&path, format!("decompresses to more than {}, the most raylab reads from one file", human(MAX_DATA_BYTES))));
            }
            return Ok(out);
        }
        Ok(raw)
    }

    /// The file's lines, one at a time, gunzipped when the name ends in `.gz`: for a large
    /// text (an OBJ) that is parsed as it is read rather than held whole.
    pub fn lines(&self) -> Result<Lines, LoadError> {
        let path = self.path();
        let gz = path.extension().is_some_and(|e| e == "gz");
        let raw: Box<dyn Read> = match self {
            Found::Disk(p) => Box::new(open_checked(p, MAX_DATA_BYTES)?),
            Found::Embedded(_, bytes) => Box::new(*bytes),
        };
        let inner: Box<dyn BufRead> = if gz { Box::new(BufReader::new(flate2::read::GzDecoder::new(BufReader::new(raw)))) } else { Box::new(BufReader::new(raw)) };
        Ok(Lines { path, gz, inner, read: 0 })
    }

    /// A resolver for files named inside this one (an OBJ's MTL, an MTL's textures).
    pub fn sibling_resolver(&self) -> Resolver {
        match self {
            Found::Disk(p) => Resolver::Disk { base: p.parent().map(Path::to_path_buf).unwrap_or_default() },
            Found::Embedded(..) => Resolver::Embedded,
        }
    }
}

impl Resolver {
    /// Finds `name`, or returns every path that was tried.
    pub fn find(&self, name: &str) -> Result<Found, Vec<PathBuf>> {
        match self {
            Resolver::Embedded => {
                EMBEDDED.iter().find(|(n, _)| *n == name).map(|&(n, b)| Found::Embedded(n, b)).ok_or_else(|| vec![PathBuf::from(format!("<embedded>/{name}"))])
            }
            Resolver::Disk { base } => {
                let mut tried = Vec::new();
                let direct = base.join(name);
                // Anything that exists is found (a folder or a device too), so that reading it
                // says what it is rather than "cannot find".
                if direct.exists() {
                    return Ok(Found::Disk(direct));
                }
                tried.push(direct);
                if Path::new(name).is_relative() {
                    // A scene named without a folder (`cd scenes && raylab render bunny.toml`) has an
                    // empty parent, which `std::path::absolute` refuses: it is the current directory.
                    let dir = if base.as_os_str().is_empty() { Path::new(".") } else { base.as_path() };
                    let abs = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
                    for dir in abs.ancestors() {
                        let candidate = dir.join("shared").join("scenes").join(name);
                        if candidate.exists() {
                            return Ok(Found::Disk(candidate));
                        }
                        if dir.join("shared").join("scenes").is_dir() {
                            tried.push(candidate);
                        }
                    }
                }
                Err(tried)
            }
        }
    }
}

/// A data file read a line at a time, with [`Found::read`]'s cap and messages.
pub struct Lines {
    path: PathBuf,
    gz: bool,
    inner: Box<dyn BufRead>,
    read: u64,
}

impl Lines {
    /// The next line into `buf` (cleared first; its end of line kept): `false` at the end.
    pub fn next_into(&mut self, buf: &mut Vec<u8>) -> Result<bool, LoadError> {
        buf.clear();
        let n = self.inner.read_until(b'\n', buf).map_err(|e| LoadError::file(&self.path, format!("{}: {e}", if self.gz { "cannot decompress" } else { "cannot read" })))?;
        self.read += n as u64;
        if self.read > MAX_DATA_BYTES {
            let m = if self.gz { format!("decompresses to more than {}, the most raylab reads from one file", human(MAX_DATA_BYTES)) } else { format!("more than {} (the most raylab reads from one such file): is it endless?", human(MAX_DATA_BYTES)) };
            return Err(LoadError::file(&self.path, m));
        }
        Ok(n > 0)
    }
}

/// The largest scene text (TOML, pbrt) raylab reads: a scene file is settings and names;
/// its geometry lives in the files it names. An endless input (`/dev/zero`, a pipe that
/// never ends) stops here with an error instead of exhausting memory.
pub const MAX_SCENE_BYTES: u64 = 256 << 20;
/// The largest data file (mesh, curves, patches, image), and the largest a `.gz` may
/// decompress to.
pub const MAX_DATA_BYTES: u64 = 32 << 30;

/// Reads a whole file of at most `cap` bytes. A folder or a device is refused by name; a
/// regular file larger than `cap` (or than the machine's memory, unless --allow-large) is
/// refused before reading; a pipe is read up to `cap` bytes.
pub fn read_capped(path: &Path, cap: u64) -> Result<Vec<u8>, LoadError> {
    let fail = |m: String| LoadError::file(path, m);
    let file = open_checked(path, cap)?;
    let mut bytes = Vec::new();
    file.take(cap + 1).read_to_end(&mut bytes).map_err(|e| fail(format!("cannot read: {e}")))?;
    if bytes.len() as u64 > cap {
        return Err(fail(format!("more than {} (the most raylab reads from one such file): is it endless?", human(cap))));
    }
    Ok(bytes)
}

/// Opens a file for reading after [`read_capped`]'s checks of its kind and size.
fn open_checked(path: &Path, cap: u64) -> Result<std::fs::File, LoadError> {
    let fail = |m: String| LoadError::file(path, m);
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let kind = meta.file_type();
    if kind.is_dir() {
        return Err(fail("is a folder, not a file".into()));
    }
    if is_device(&kind) {
        return Err(fail("is a device, not a regular file".into()));
    }
    if kind.is_file() {
        if meta.len() > cap {
            return Err(fail(format!("is {} bytes ({}), more than the {} raylab reads from one such file", meta.len(), human(meta.len()), human(cap))));
        }
        raylab_render::memory_guard::check("reading it", Some(meta.len())).map_err(fail)?;
    }
    std::fs::File::open(path).map_err(|e| fail(format!("cannot read: {e}")))
}

#[cfg(unix)]
fn is_device(kind: &std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    kind.is_block_device() || kind.is_char_device()
}

#[cfg(not(unix))]
fn is_device(_: &std::fs::FileType) -> bool {
    false
}

/// "cannot find `x` (looked in a, b)".
pub fn not_found_message(name: &str, tried: &[PathBuf]) -> String {
    let list: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
    format!("cannot find `{name}` (looked in {})", list.join(", "))
}
