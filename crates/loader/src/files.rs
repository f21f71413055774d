//! Finding the files a scene names: next to the scene first, then in a `shared/scenes`
//! folder of any ancestor directory (where raylab keeps its large test meshes), or, for the
//! embedded default scene, in the binary itself.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::LoadError;

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
            Found::Disk(p) => std::fs::read(p).map_err(|e| LoadError::file(&path, format!("cannot read: {e}")))?,
            Found::Embedded(_, bytes) => bytes.to_vec(),
        };
        if path.extension().is_some_and(|e| e == "gz") {
            let mut out = Vec::new();
            flate2::read::GzDecoder::new(raw.as_slice()).read_to_end(&mut out).map_err(|e| LoadError::file(&path, format!("cannot decompress: {e}")))?;
            return Ok(out);
        }
        Ok(raw)
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
                if direct.is_file() {
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
                        if candidate.is_file() {
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

/// "cannot find `x` (looked in a, b)".
pub fn not_found_message(name: &str, tried: &[PathBuf]) -> String {
    let list: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
    format!("cannot find `{name}` (looked in {})", list.join(", "))
}
