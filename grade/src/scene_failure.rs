//! Why a graded scene has no score, as a value: the renderer did not build, its child failed or
//! wrote no readable image, or the image cannot be compared with the reference. A hidden scene's
//! failure carries its fixed category only, never what the student's code wrote: the grader
//! drops the detail when it makes the value ([`SceneFailure::hidden`]).

use std::path::PathBuf;

use crate::regions::stub::stub_panic;
use crate::run::child::Failure;
use crate::ssim::SizeMismatch;

/// Why a scene has no score.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneFailure {
    /// The renderer does not build: what the build said (nothing for a hidden scene).
    #[error("the renderer does not build{}", .0.as_ref().map(|w| format!(": {w}")).unwrap_or_default())]
    NoRenderer(Option<String>),
    /// The grader could not make the render's own folder (its machine, not the student's code).
    #[error("cannot make a folder for the render: {0}")]
    NoFolder(std::io::ErrorKind),
    /// The renderer could not be started.
    #[error("cannot start {}: {kind}", .renderer.display())]
    CannotStart {
        /// The renderer's binary.
        renderer: PathBuf,
        /// What the system said.
        kind: std::io::ErrorKind,
    },
    /// The render failed: its category, and what it wrote (a public scene only).
    #[error("{0}")]
    Failed(Failure),
    /// The renderer exited well without writing its image.
    #[error("the renderer exited without writing an image")]
    NoImage,
    /// It wrote an image that cannot be read: why (a public scene only).
    #[error("{}", .0.as_deref().unwrap_or("wrote an image that cannot be read"))]
    Unreadable(Option<String>),
    /// The image is not the reference's size.
    #[error("{0} (render vs reference)")]
    Size(SizeMismatch),
    /// One render of a tile test failed.
    #[error("render {k} of {n}: {failure}")]
    RenderOf {
        /// Which render, from 1.
        k: u32,
        /// Of how many.
        n: u32,
        /// Why.
        failure: Box<SceneFailure>,
    },
    /// It stopped in the stub of a checkpoint not written yet (the student's own tree).
    #[error("the scene could not run: checkpoint {0} is not written yet")]
    NotWritten(u32),
}

impl SceneFailure {
    /// The same failure as a hidden scene may show it: no word the student's code wrote.
    pub fn hidden(self) -> SceneFailure {
        match self {
            SceneFailure::NoRenderer(_) => SceneFailure::NoRenderer(None),
            SceneFailure::Failed(f) => SceneFailure::Failed(Failure { detail: None, ..f }),
            SceneFailure::Unreadable(_) => SceneFailure::Unreadable(None),
            SceneFailure::RenderOf { k, n, failure } => {
                SceneFailure::RenderOf { k, n, failure: Box::new(failure.hidden()) }
            }
            other => other,
        }
    }

    /// The checkpoint whose stub the render stopped in, if it panicked with a stub's words.
    pub fn stub_panic(&self) -> Option<u32> {
        match self {
            SceneFailure::Failed(failure) => stub_panic(failure.detail.as_deref()?),
            SceneFailure::RenderOf { failure, .. } => failure.stub_panic(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::child::Category;

    /// A hidden scene shows the category of a crash, never the text the student's code wrote.
    #[test]
    fn a_hidden_failure_keeps_no_word_of_the_student() {
        let crash = Failure { category: Category::Panicked, detail: Some("\"secret\"".to_string()) };
        let failure = SceneFailure::RenderOf { k: 2, n: 16, failure: Box::new(SceneFailure::Failed(crash)) };
        assert!(failure.to_string().contains("secret"));
        let hidden = failure.hidden().to_string();
        assert!(!hidden.contains("secret"), "{hidden}");
        assert!(hidden.starts_with("render 2 of 16: "), "{hidden}");
        let unreadable = SceneFailure::Unreadable(Some("secret".to_string())).hidden().to_string();
        assert_eq!(unreadable, "wrote an image that cannot be read");
        assert_eq!(
            SceneFailure::NoRenderer(Some("secret".into())).hidden().to_string(),
            "the renderer does not build"
        );
    }
}
