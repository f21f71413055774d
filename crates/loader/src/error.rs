use std::fmt;
use std::path::{Path, PathBuf};

/// Anything that went wrong while reading a scene and the files it names. The message
/// always starts with the file, then the line when there is one, then the field:
/// `scene.toml:3: camera.at: expected an array of 3 numbers, found a string`.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadError {
    pub file: PathBuf,
    pub line: Option<usize>,
    /// Dotted path of the offending field (`shapes[2].radius`), or empty.
    pub field: String,
    pub message: String,
}

impl LoadError {
    pub fn new(file: &Path, line: Option<usize>, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self { file: file.to_path_buf(), line, field: field.into(), message: message.into() }
    }

    /// An error about a whole file (cannot open, not UTF-8, ...).
    pub fn file(file: &Path, message: impl Into<String>) -> Self {
        Self::new(file, None, "", message)
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if !self.field.is_empty() {
            write!(f, ": {}", shorten(&self.field))?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for LoadError {}

/// Text from a file as a message shows it: whole when short, else its start and its size,
/// so that a 10 MB key or line does not come back in full.
pub fn shorten(text: &str) -> String {
    const KEEP: usize = 60;
    if text.chars().count() <= KEEP + 20 {
        return text.to_string();
    }
    let head: String = text.chars().take(KEEP).collect();
    format!("{head}... ({} bytes)", text.len())
}

pub fn text_from_bytes(path: &Path, bytes: Vec<u8>) -> Result<String, LoadError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        LoadError::new(path, Some(line), "", format!("not valid UTF-8 (byte 0x{:02x})", bytes[at]))
    })
}
