//! Why the launcher could not raise a wall: which step failed and what the system said, as a
//! value. The launcher prints it on one line (`sandbox: ...`) and exits with status 125 before
//! the graded program runs.

use std::io;

/// A wall the launcher could not raise.
#[derive(Debug, thiserror::Error)]
pub enum WallError {
    /// A system call of `step` failed.
    #[error("cannot {step}: {source}")]
    System {
        /// What the launcher was doing.
        step: Step,
        /// What the system said.
        source: io::Error,
    },
    /// The grader that started the launcher died before the walls were up.
    #[error("the grader is gone")]
    GraderGone,
    /// The program's name, an argument or a variable holds a NUL byte, which exec cannot pass.
    #[error("a NUL in the program's name, an argument or a variable")]
    Nul,
    /// The seccomp filter could not be built for this machine.
    #[error("cannot build the seccomp filter: {0}")]
    FilterBuild(#[from] seccompiler::BackendError),
    /// The kernel refused the seccomp filter.
    #[error("cannot install the seccomp filter: {0}")]
    FilterInstall(#[from] seccompiler::Error),
    /// Landlock refused the file wall.
    #[error("cannot raise the file wall: {0}")]
    Landlock(#[from] landlock::RulesetError),
    /// The launcher's own arguments are wrong (the grader wrote them: a bug, or a person).
    #[error(transparent)]
    Arguments(#[from] super::ArgumentError),
}

/// A step of the launcher that calls the system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Asking to die with the grader (`PR_SET_PDEATHSIG`).
    DieWithGrader,
    /// Reading the descriptor limit.
    ReadDescriptorLimit,
    /// Opening the program.
    OpenProgram,
    /// Moving the program's descriptor below the limit.
    MoveDescriptor,
    /// Lowering the descriptor limit.
    LowerDescriptorLimit,
    /// Setting a resource limit.
    SetLimit,
    /// Dropping the supplementary groups.
    DropGroups,
    /// Changing group.
    ChangeGroup,
    /// Changing user.
    ChangeUser,
    /// Executing the program.
    Exec,
    /// Forking a build's child.
    StartBuild,
    /// Waiting for a build's child.
    WaitBuild,
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Step::DieWithGrader => "ask to die with the grader",
            Step::ReadDescriptorLimit => "read the descriptor limit",
            Step::OpenProgram => "open the program",
            Step::MoveDescriptor => "move the program's descriptor",
            Step::LowerDescriptorLimit => "lower the descriptor limit",
            Step::SetLimit => "set a resource limit",
            Step::DropGroups => "drop the supplementary groups",
            Step::ChangeGroup => "change group",
            Step::ChangeUser => "change user",
            Step::Exec => "start the program",
            Step::StartBuild => "start the build",
            Step::WaitBuild => "wait for the build",
        })
    }
}

impl WallError {
    /// `step` failed with the system's last error.
    pub fn last_os(step: Step) -> WallError {
        WallError::System { step, source: io::Error::last_os_error() }
    }
}
