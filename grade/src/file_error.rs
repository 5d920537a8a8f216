//! A file the grader reads that is not as it must be (a rubric, a reference manifest, a scene, a
//! reference image, a tile file), or one it cannot write: which file, where in it when that is
//! known, and what is wrong, as a value. The grader's `main` reports it in one line with exit
//! code 2.

use std::path::{Path, PathBuf};

use raylab_base::image_io::ImageError;

use crate::plain::NotRead;

/// A file the grader reads or writes, and what is wrong with it.
#[derive(Debug)]
pub struct FileError {
    /// The file.
    pub file: PathBuf,
    /// What is wrong with it.
    pub problem: Problem,
}

/// What is wrong with a file.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// It cannot be read: missing, not a plain file, too large, no permission.
    #[error("cannot read: {0}")]
    Unreadable(NotRead),
    /// A reference manifest that cannot be read: the references were never made.
    #[error("cannot read ({0}); run `grader update-references`")]
    NoReferences(NotRead),
    /// It cannot be written (a full disk, no permission): as the system words it.
    #[error("cannot write: {0}")]
    Unwritable(String),
    /// Its TOML or JSON does not parse into what the file must hold (a missing field, a wrong
    /// type).
    #[error("{message}")]
    Syntax {
        /// The line the parser points at, from 1, if it points.
        line: Option<usize>,
        /// What the parser says.
        message: String,
    },
    /// A reference (image or tile file) no longer matches what it was made from.
    #[error("is stale: {0}; run `grader update-references`")]
    Stale(Staleness),
    /// A reference image of another size than the scene's film.
    #[error(
        "the image is {}x{} but the scene renders {}x{}; run `grader update-references`",
        image.0,
        image.1,
        film.0,
        film.1
    )]
    WrongSize {
        /// The image's width and height.
        image: (u32, u32),
        /// The scene's film width and height.
        film: (u32, u32),
    },
    /// It is not an image the grader can read and decode: why.
    #[error("cannot read the image: {0}")]
    NotAnImage(String),
}

/// Why a stored reference no longer matches what it was made from.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum Staleness {
    /// The manifest has no entry for the scene.
    #[error("not in the manifest")]
    NotInManifest,
    /// The scene file or one of its meshes changed since the reference was made.
    #[error("{} or its meshes changed since it was made", .0.display())]
    InputsChanged(PathBuf),
    /// The rubric's `reference_spp` or `seed` for the scene changed.
    #[error("the rubric's reference_spp or seed changed")]
    SamplesOrSeed,
    /// The rubric's tile test or the film size changed.
    #[error("the rubric's tile, spp or render counts, or the film size, changed")]
    TileTest,
}

impl std::fmt::Display for FileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let file = self.file.display();
        match &self.problem {
            Problem::Stale(_) => write!(f, "{file} {}", self.problem),
            Problem::Syntax { line: Some(line), .. } => write!(f, "{file}:{line}: {}", self.problem),
            _ => write!(f, "{file}: {}", self.problem),
        }
    }
}

impl std::error::Error for FileError {}

impl FileError {
    /// `problem` with `file`.
    pub fn new(file: &Path, problem: Problem) -> FileError {
        FileError { file: file.to_path_buf(), problem }
    }

    /// `file`, which the system could not read.
    pub fn unreadable(file: &Path, error: &std::io::Error) -> FileError {
        FileError::new(file, Problem::Unreadable(NotRead::Io(error.to_string())))
    }

    /// `file`, which the system could not write.
    pub fn unwritable(file: &Path, error: &std::io::Error) -> FileError {
        FileError::new(file, Problem::Unwritable(error.to_string()))
    }

    /// An image of `file` that cannot be read or written.
    pub fn image(file: &Path, error: &ImageError) -> FileError {
        match error {
            ImageError::Read { message, .. } => FileError::new(file, Problem::NotAnImage(message.clone())),
            ImageError::Write { message, .. } => FileError::new(file, Problem::Unwritable(message.clone())),
        }
    }

    /// A JSON error of `file`.
    pub fn json(file: &Path, error: &serde_json::Error) -> FileError {
        // serde_json's message already ends with its line and column.
        FileError::new(file, Problem::Syntax { line: None, message: error.to_string() })
    }

    /// A TOML error of `text`, the contents of `file`, with the line it points at.
    pub fn toml(file: &Path, text: &str, error: &toml::de::Error) -> FileError {
        let line = error.span().map(|span| {
            text.as_bytes()[..span.start.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
        });
        FileError::new(file, Problem::Syntax { line, message: error.message().to_string() })
    }
}

/// Parses `text`, the contents of `file`, as TOML into `T`.
pub fn parse_toml<T: serde::de::DeserializeOwned>(file: &Path, text: &str) -> Result<T, FileError> {
    toml::from_str(text).map_err(|e| FileError::toml(file, text, &e))
}

/// Reads `file` and parses it as JSON into `T`.
pub fn read_json<T: serde::de::DeserializeOwned>(file: &Path) -> Result<T, FileError> {
    let text = std::fs::read_to_string(file).map_err(|e| FileError::unreadable(file, &e))?;
    serde_json::from_str(&text).map_err(|e| FileError::json(file, &e))
}

/// Reads `file` and parses it as TOML into `T`.
pub fn read_toml<T: serde::de::DeserializeOwned>(file: &Path) -> Result<T, FileError> {
    let text = std::fs::read_to_string(file).map_err(|e| FileError::unreadable(file, &e))?;
    parse_toml(file, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)] // read only to be refused
    struct Scene {
        name: String,
        spp: u32,
    }

    #[test]
    fn a_toml_error_names_the_file_the_line_and_the_field() {
        let file = Path::new("scenes/room.toml");
        let text = "name = \"room\"\n\nspp = \"many\"\n";
        let error = parse_toml::<Scene>(file, text).unwrap_err();
        assert!(matches!(error.problem, Problem::Syntax { line: Some(3), .. }), "{error:?}");
        assert!(error.to_string().starts_with("scenes/room.toml:3: invalid type"), "{error}");
        let missing = parse_toml::<Scene>(file, "name = \"room\"\n").unwrap_err();
        assert!(missing.to_string().contains("missing field `spp`"), "{missing}");
    }

    #[test]
    fn a_stale_reference_reads_as_a_sentence_and_says_what_to_run() {
        let file = Path::new("reference/room.png");
        let stale = FileError::new(file, Problem::Stale(Staleness::InputsChanged("scenes/room.toml".into())));
        assert_eq!(
            stale.to_string(),
            "reference/room.png is stale: scenes/room.toml or its meshes changed since it was made; run `grader update-references`"
        );
        let size = FileError::new(file, Problem::WrongSize { image: (4, 3), film: (8, 6) });
        assert_eq!(
            size.to_string(),
            "reference/room.png: the image is 4x3 but the scene renders 8x6; run `grader update-references`"
        );
    }
}
