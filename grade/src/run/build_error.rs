//! Why a build of the graded tree gave nothing to run, as values: the compiler's first error with
//! its place, read from cargo's JSON messages (never parsed back from text), or what else went
//! wrong. The words are in the `Display` implementations; callers decide with the fields.

use std::path::{Path, PathBuf};

use crate::plain::quote;
use crate::run::child::Failure;

/// Where a compiler error points: the file (relative to the tree, as the compiler names it) and
/// the 1-based line and column of its primary span.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourcePlace {
    /// The file, relative to the tree.
    pub file: PathBuf,
    /// Its line, from 1.
    pub line: usize,
    /// Its column, from 1.
    pub column: usize,
}

/// The first error the compiler reported.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompileError {
    /// rustc's error code (`E0425`), if the error has one.
    pub code: Option<String>,
    /// What the compiler said, on one line and [`quote()`]d.
    pub message: String,
    /// Where, if the compiler named a place.
    pub place: Option<SourcePlace>,
}

impl CompileError {
    /// The first error among cargo's JSON messages (`--message-format=json`), if any.
    pub fn first_in(messages: &str) -> Option<CompileError> {
        messages
            .lines()
            .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
            .filter(|m| m["reason"] == "compiler-message" && m["message"]["level"] == "error")
            .map(|m| CompileError::from_diagnostic(&m["message"]))
            .next()
    }

    fn from_diagnostic(diagnostic: &serde_json::Value) -> CompileError {
        let spans = diagnostic["spans"].as_array().map(Vec::as_slice).unwrap_or_default();
        let place = spans.iter().find(|s| s["is_primary"] == true).and_then(|s| {
            Some(SourcePlace {
                file: PathBuf::from(s["file_name"].as_str()?),
                line: s["line_start"].as_u64()? as usize,
                column: s["column_start"].as_u64()? as usize,
            })
        });
        CompileError {
            code: diagnostic["code"]["code"].as_str().map(str::to_string),
            message: quote(diagnostic["message"].as_str().unwrap_or("no message")),
            place,
        }
    }

    /// `error[E0308]`, or `error`: all that may be said of an error in a file a student cannot see.
    pub fn heading(&self) -> String {
        match &self.code {
            Some(code) => format!("error[{code}]"),
            None => "error".to_string(),
        }
    }
}

impl std::fmt::Display for CompileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.heading(), self.message)?;
        if let Some(SourcePlace { file, line, column }) = &self.place {
            write!(f, " at {}:{line}:{column}", quote(&file.to_string_lossy()))?;
        }
        Ok(())
    }
}

/// Why a build gave no executable to run.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// cargo, or a built test binary, could not be started.
    #[error("cannot run {}: {source}", program.display())]
    CannotStart {
        /// What was to run.
        program: PathBuf,
        /// Why it could not.
        source: std::io::Error,
    },
    /// The compiler refused the code.
    #[error("{0}")]
    Compile(CompileError),
    /// cargo refused before compiling (a manifest, a lock file): its first error line, [`quote()`]d.
    #[error("{message}")]
    Cargo {
        /// What cargo said.
        message: String,
    },
    /// The build itself failed: out of time, out of memory, a crash.
    #[error("{0}")]
    Failed(Failure),
    /// The build succeeded but made no `render` executable.
    #[error("cargo built no `render` executable")]
    NoRenderer,
    /// A test binary was built but would not list its tests.
    #[error("cannot list the tests of {}: {failure}", executable.display())]
    CannotList {
        /// The test binary.
        executable: PathBuf,
        /// How listing failed.
        failure: Failure,
    },
}

impl BuildError {
    /// Why a finished build failed: the compiler's first error in its JSON `messages`, else
    /// cargo's own first error line in `stderr`, else `failure`.
    pub fn of_failed_build(messages: &str, stderr: &str, failure: Failure) -> BuildError {
        if let Some(error) = CompileError::first_in(messages) {
            return BuildError::Compile(error);
        }
        match stderr.lines().find(|l| l.starts_with("error")) {
            Some(line) => BuildError::Cargo { message: quote(line) },
            None => BuildError::Failed(failure),
        }
    }

    /// The place of the compiler error, if this is one that names a place.
    pub fn place(&self) -> Option<(&Path, usize)> {
        match self {
            BuildError::Compile(CompileError { place: Some(place), .. }) => Some((&place.file, place.line)),
            _ => None,
        }
    }

    /// `error[E0308]` for a compiler error with a code, else `error`.
    pub fn heading(&self) -> String {
        match self {
            BuildError::Compile(error) => error.heading(),
            _ => "error".to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::child::Category;

    /// A `compiler-message` line as cargo writes it, trimmed to the fields read.
    const UNKNOWN_NAME: &str = r#"{"reason":"compiler-message","message":{"message":"cannot find value `x` in this scope","code":{"code":"E0425","explanation":"..."},"level":"error","spans":[{"file_name":"src/geometry/macros.rs","line_start":3,"column_start":1,"is_primary":false},{"file_name":"src/geometry/triangle.rs","line_start":101,"line_end":101,"column_start":9,"column_end":10,"is_primary":true}],"rendered":"error[E0425]: cannot find value"}}"#;
    const WARNING: &str = r#"{"reason":"compiler-message","message":{"message":"unused variable: `y`","code":{"code":"unused_variables"},"level":"warning","spans":[]}}"#;
    const LINK: &str = r#"{"reason":"compiler-message","message":{"message":"linking with `cc` failed: exit status: 1","code":null,"level":"error","spans":[]}}"#;

    fn failure() -> Failure {
        Failure { category: Category::Failed, detail: Some("exit status: 101".to_string()) }
    }

    #[test]
    fn the_first_compiler_error_keeps_its_code_and_primary_place() {
        let messages = [WARNING, "not json", UNKNOWN_NAME, LINK].join("\n");
        let error = BuildError::of_failed_build(&messages, "error: could not compile `raylab`", failure());
        assert_eq!(error.place(), Some((Path::new("src/geometry/triangle.rs"), 101)));
        assert_eq!(error.heading(), "error[E0425]");
        assert_eq!(
            error.to_string(),
            "error[E0425]: cannot find value `x` in this scope at src/geometry/triangle.rs:101:9"
        );
    }

    #[test]
    fn an_error_without_code_or_place_says_so() {
        let error = BuildError::of_failed_build(LINK, "", failure());
        assert_eq!((error.place(), error.heading()), (None, "error".to_string()));
        assert_eq!(error.to_string(), "error: linking with `cc` failed: exit status: 1");
    }

    #[test]
    fn without_a_compiler_error_cargo_or_the_process_is_named() {
        let manifest = "error: failed to parse manifest at `/t/Cargo.toml`\n\nCaused by:\n  bad";
        let cargo = BuildError::of_failed_build(WARNING, manifest, failure());
        assert_eq!(cargo.to_string(), "error: failed to parse manifest at `/t/Cargo.toml`");
        let killed = BuildError::of_failed_build("", "   Compiling raylab", failure());
        assert_eq!(killed.to_string(), "failed: exit status: 101");
        assert_eq!((killed.place(), killed.heading()), (None, "error".to_string()));
    }
}
