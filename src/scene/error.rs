//! Errors in scene files, each one line naming the file, the line, and the field.

use std::fmt;
use std::ops::Range;
use std::path::PathBuf;

/// What went wrong loading a scene.
#[derive(Debug)]
pub enum SceneError {
    /// The scene file could not be read.
    Read {
        /// The scene file.
        path: DisplayPath,
        /// Why.
        source: std::io::Error,
    },
    /// Something in the scene file is wrong.
    Invalid {
        /// Where: `file:line:column`.
        location: Location,
        /// The field, as a dotted path such as `objects[2].scale`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
}

// Written out rather than derived (thiserror): one proc-macro crate fewer in a student's
// first build.
impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { path, source } => write!(f, "{path}: cannot read the scene: {source}"),
            Self::Invalid { location, field, message } => write!(f, "{location}: {field}: {message}"),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Read { source, .. } => Some(source),
            Self::Invalid { .. } => None,
        }
    }
}

/// A path shown as the user typed it.
#[derive(Debug, Clone)]
pub struct DisplayPath(pub PathBuf);

impl fmt::Display for DisplayPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0.display())
    }
}

/// A position in a scene file.
#[derive(Debug, Clone)]
pub struct Location {
    /// The scene file.
    pub path: DisplayPath,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.path, self.line, self.column)
    }
}

/// Maps byte offsets of a scene file's text to lines and field paths, for error messages.
pub struct SourceMap<'a> {
    /// The file, for messages.
    pub path: &'a std::path::Path,
    /// Its text.
    pub text: &'a str,
}

impl SourceMap<'_> {
    /// An error at byte range `span` (or the start of the file), with the field found there.
    pub fn error(&self, span: Option<Range<usize>>, message: impl Into<String>) -> SceneError {
        let offset = span.map_or(0, |s| s.start).min(self.text.len());
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        SceneError::Invalid {
            location: Location { path: DisplayPath(self.path.to_path_buf()), line, column },
            field: self.field_at(line),
            message: one_line(&message.into()),
        }
    }

    /// The byte range of the line `key = ...` inside `[table]`, for fields serde keeps no span of.
    pub fn key_span(&self, table: &str, key: &str) -> Option<Range<usize>> {
        let mut current = "";
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            let text = line.trim();
            if let Some(name) = text.strip_prefix('[').and_then(|t| t.split(']').next()) {
                current = name.trim_matches('[').trim();
            } else if current == table && text.split_once('=').is_some_and(|(k, _)| k.trim() == key) {
                return Some(offset..offset + line.len());
            }
            offset += line.len();
        }
        None
    }

    /// The byte range of the header line `[table]`.
    pub fn header_span(&self, table: &str) -> Option<Range<usize>> {
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            if line.trim().strip_prefix('[').and_then(|t| t.strip_suffix(']')) == Some(table) {
                return Some(offset..offset + line.len());
            }
            offset += line.len();
        }
        None
    }

    /// The dotted path of the key on `line`: the last table header up to that line (arrays of
    /// tables numbered from 0) and the key on the line itself, if it has one.
    fn field_at(&self, line: usize) -> String {
        let mut table = String::new();
        let mut array_counts: std::collections::HashMap<String, usize> = Default::default();
        let lines: Vec<&str> = self.text.lines().collect();
        for text in lines.iter().take(line) {
            let text = text.trim();
            if let Some(name) = text.strip_prefix("[[").and_then(|t| t.split("]]").next()) {
                let count = array_counts.entry(name.trim().to_string()).or_insert(0);
                table = format!("{}[{}]", name.trim(), *count);
                *count += 1;
            } else if let Some(name) = text.strip_prefix('[').and_then(|t| t.split(']').next()) {
                table = name.trim().to_string();
            }
        }
        let here = lines.get(line.saturating_sub(1)).map_or("", |l| l.trim());
        let key =
            here.split_once('=').map(|(k, _)| k.trim()).filter(|k| !k.is_empty() && !k.starts_with('['));
        match (table.is_empty(), key) {
            (true, None) => "(top level)".to_string(),
            (false, None) => table,
            (true, Some(k)) => k.to_string(),
            (false, Some(k)) => format!("{table}.{k}"),
        }
    }
}

/// The first line of a message, without serde's trailing detail.
fn one_line(message: &str) -> String {
    message.lines().next().unwrap_or("").trim().to_string()
}
