//! What the checker refuses in a region, as values, each worded for the student who wrote it: the
//! name or path at fault and the rule, never the grader's internals.

use super::lists::{ALLOWED_LINTS, MAX_NESTING, MAX_NUMBERS, MAX_REGION_BYTES, MAX_TEXT};

/// Why a region is refused: the first thing the checker found.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Refusal {
    /// The region is longer than [`MAX_REGION_BYTES`].
    #[error("longer than {} KiB: a solution region is a function body", MAX_REGION_BYTES / 1024)]
    TooLong,
    /// The region is not Rust: what the parser said.
    #[error("does not parse: {0}")]
    DoesNotParse(String),
    /// Its brackets do not match.
    #[error("does not parse: its brackets do not match")]
    Unbalanced,
    /// Its brackets nest deeper than [`MAX_NESTING`].
    #[error("brackets nested {0} deep, more than {MAX_NESTING}: split the code up")]
    TooDeep(usize),
    /// The checker itself failed on it (its thread could not start or panicked).
    #[error("could not be checked")]
    Unchecked,
    /// A raw identifier, `r#name`.
    #[error("`{0}`: raw identifiers are not allowed in solutions (rustc reads it as `{bare}`)", bare = &.0[2..])]
    RawIdentifier(String),
    /// More literal data than [`MAX_NUMBERS`] numbers or [`MAX_TEXT`] bytes of text.
    #[error("{numbers} numbers and {text} bytes of text, more than {MAX_NUMBERS} or {MAX_TEXT}: a solution computes, it does not embed data")]
    TooMuchData {
        /// Number literals.
        numbers: usize,
        /// Bytes of strings, chars, bytes and doc text.
        text: usize,
    },
    /// A path through a name of the harness.
    #[error("`{path}`: `{name}` is the harness's, not for solutions")]
    Harness {
        /// The path.
        path: String,
        /// The harness's name in it.
        name: String,
    },
    /// A module of `std` other than maths, collections and language items.
    #[error("`{0}`: only maths, collections and language items of std may be used")]
    StdModule(String),
    /// A module of the student API that the region's checkpoint does not work with.
    #[error("`{path}`: checkpoint {checkpoint} works with crate::{{{}}}, not `{module}`", .modules.join(", "))]
    OtherCheckpointModule {
        /// The path.
        path: String,
        /// The region's checkpoint.
        checkpoint: u32,
        /// The modules it may name.
        modules: Vec<String>,
        /// The module named.
        module: String,
    },
    /// A `crate::` path outside the student API.
    #[error("`{0}`: not part of the student API")]
    NotStudentApi(String),
    /// A `self::` or `super::` path.
    #[error("`{0}`: use the names imported outside the region, or a `crate::` path")]
    SelfOrSuper(String),
    /// A path into another crate of the workspace or its dependencies.
    #[error("`{path}`: the crate `{krate}` is not for solutions")]
    OtherCrate {
        /// The path.
        path: String,
        /// The crate.
        krate: String,
    },
    /// `use ... as ...`.
    #[error("`use ... {name} as {rename}`: name things by their own names in solutions")]
    UseAs {
        /// The name imported.
        name: String,
        /// Its new name.
        rename: String,
    },
    /// `use path::*`.
    #[error("`use {0}::*`: import the names you need one by one")]
    Glob(String),
    /// `use std;`: a whole crate.
    #[error("`use {0}`: name the items, not the crate")]
    WholeCrate(String),
    /// A macro a `use` in the region brought in.
    #[error("`{0}!` was brought in by a `use`: call macros by their own names")]
    ImportedMacro(String),
    /// A macro not in the list, or called through a path.
    #[error("the macro `{0}!` is not allowed in solutions")]
    Macro(String),
    /// A listed macro whose arguments are not expressions or patterns.
    #[error("the arguments of `{0}!` could not be checked")]
    MacroArguments(String),
    /// `#[doc = ...]` or `#[must_use = ...]` with something else than a string literal.
    #[error("`#[{0} = ...]` may hold a string literal only")]
    AttributeValue(String),
    /// An attribute not in the list.
    #[error(
        "the attribute `#[{0}]` is not allowed in solutions (only inline, must_use, doc comments and allow)"
    )]
    Attribute(String),
    /// `#[allow(...)]` of something else than lint names.
    #[error("`#[allow(...)]` must list lints by name")]
    LintList,
    /// `#[allow(lint)]` of a lint not in [`ALLOWED_LINTS`].
    #[error("`#[allow({0})]`: a solution may only allow style lints ({some}, ...)", some = ALLOWED_LINTS[..4].join(", "))]
    Lint(String),
    /// A `const` of a type with interior mutability.
    #[error("a `const` of `{0}`: no state may outlive a call")]
    InteriorConst(String),
    /// An `impl` of a type the region does not declare: its name, if it is a plain one.
    #[error("{}", match .0 {
        Some(name) => format!("`impl` of `{name}`: a solution may implement only the types it declares"),
        None => "`impl` of a type it does not declare: a solution may implement only its own types".to_string(),
    })]
    ForeignImpl(Option<String>),
    /// A `static`.
    #[error("a `static` keeps state between calls: not allowed in solutions")]
    Static,
    /// A `trait` or trait alias.
    #[error("a `trait` is not allowed in solutions")]
    Trait,
    /// A `mod`.
    #[error("a `mod` is not allowed in solutions")]
    Mod,
    /// `macro_rules!`.
    #[error("macro definitions are not allowed in solutions")]
    MacroDefinition,
    /// `extern crate`.
    #[error("`extern crate` is not allowed in solutions")]
    ExternCrate,
    /// An `extern` block.
    #[error("`extern` blocks are not allowed in solutions")]
    ExternBlock,
    /// An `extern` function.
    #[error("`extern` functions are not allowed in solutions")]
    ExternFn,
    /// An `unsafe` block.
    #[error("`unsafe` is not allowed in solutions")]
    Unsafe,
    /// An `unsafe fn`.
    #[error("`unsafe fn` is not allowed in solutions")]
    UnsafeFn,
    /// An `unsafe impl`.
    #[error("`unsafe impl` is not allowed in solutions")]
    UnsafeImpl,
    /// An `unsafe fn` type.
    #[error("`unsafe fn` types are not allowed in solutions")]
    UnsafeFnType,
    /// Code syn reads as verbatim tokens.
    #[error("code syn cannot read is not allowed in solutions")]
    Unreadable,
    /// A literal syn cannot read.
    #[error("a literal syn cannot read is not allowed in solutions")]
    UnreadableLiteral,
}
