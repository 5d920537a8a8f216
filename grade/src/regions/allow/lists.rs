//! The lists the checker of solution regions ([`super`]) works from: what a region may name, call
//! and carry.

use std::collections::BTreeMap;

use crate::rubric::Rubric;

/// `std` (and `core`, `alloc`) modules a region may name.
pub const STD_MODULES: &[&str] = &[
    "f32",
    "f64",
    "i8",
    "i16",
    "i32",
    "i64",
    "i128",
    "isize",
    "u8",
    "u16",
    "u32",
    "u64",
    "u128",
    "usize",
    "array",
    "borrow",
    "boxed",
    "char",
    "clone",
    "cmp",
    "collections",
    "convert",
    "default",
    "fmt",
    "hash",
    "iter",
    "marker",
    "mem",
    "num",
    "ops",
    "option",
    "prelude",
    "primitive",
    "result",
    "slice",
    "string",
    "vec",
];

/// Every module of the student API.
pub const ALL_STUDENT_MODULES: &[&str] = &[
    "camera",
    "film",
    "geometry",
    "hemisphere",
    "integrator",
    "light",
    "material",
    "math",
    "rng",
    "sampling",
    "scene",
];

/// The modules of the renderer (`crate::...`) the regions of each checkpoint may name: the
/// rubric's `student_api` for it (the student API its handout works with), or every module of
/// the student API ([`ALL_STUDENT_MODULES`]) where it names none (the extras).
#[derive(Clone, Debug, Default)]
pub struct StudentApi(BTreeMap<u32, Vec<String>>);

impl StudentApi {
    /// The API of every checkpoint of `rubric`.
    pub fn of(rubric: &Rubric) -> StudentApi {
        StudentApi(rubric.checkpoints.iter().filter_map(|c| Some((c.id, c.student_api.clone()?))).collect())
    }

    /// The modules a region of `checkpoint` may name.
    pub fn modules(&self, checkpoint: u32) -> Vec<&str> {
        match self.0.get(&checkpoint) {
            Some(modules) => modules.iter().map(String::as_str).collect(),
            None => ALL_STUDENT_MODULES.to_vec(),
        }
    }
}

/// The renderer's dependencies other than glam: reachable by name in its code, never from a region.
pub const OTHER_CRATES: &[&str] =
    &["clap", "png", "rayon", "serde", "thiserror", "tobj", "toml", "wide", "raylab", "raylab_base"];

/// Names of the harness a region must not name in a path of two or more segments.
pub const HARNESS_NAMES: &[&str] = &[
    // The harness's own split and render's stand-ins.
    "sah",
    "Sah",
    "fallback",
    "Fallbacks",
    "closest_triangle",
    "any_triangle",
    "normal_colour",
    "tracing_every_triangle",
    "Normals",
    // The harness's wide BVH: fast, and not the student's traversal, boxes or triangle test.
    "wide",
    "WideBvh",
    "collapse",
    // The grader's switch between a submission's code and the solution's (see `crate::submission::splice`).
    "graded",
    // Reading and writing files, and rendering whole images.
    "load",
    "from_toml",
    "image_io",
    "read_png",
    "write_png",
    "write_film",
    "write_file_atomic",
    "load_obj",
    "render",
    "render_with",
    "progress",
    "transmute",
    "zeroed",
];

/// Macros a region may call.
pub const MACROS: &[&str] = &[
    "assert",
    "assert_eq",
    "assert_ne",
    "dbg",
    "debug_assert",
    "debug_assert_eq",
    "debug_assert_ne",
    "eprint",
    "eprintln",
    "format",
    "matches",
    "panic",
    "print",
    "println",
    "todo",
    "unimplemented",
    "unreachable",
    "vec",
    "write",
    "writeln",
];

/// A region computes; it does not carry data. More number literals than this in one region...
pub const MAX_NUMBERS: usize = 64;
/// ...or string literals longer than this in all, look like an embedded table (a reference
/// image's pixels, the tile means a noisy scene is graded against) and reject the region. The
/// solution's largest region has 10 number literals and no string (2026-12-02); a test keeps
/// every region below a quarter of both limits.
pub const MAX_TEXT: usize = 512;

/// Lints a region may `allow`: style and unused-code lints only. None of them guards against
/// anything at run time; `long_running_const_eval`, `unconditional_recursion`,
/// `arithmetic_overflow`, `unconditional_panic`, `unsafe_code` and the lint groups are not here.
pub const ALLOWED_LINTS: &[&str] = &[
    "dead_code",
    "non_snake_case",
    "non_upper_case_globals",
    "unused_assignments",
    "unused_imports",
    "unused_mut",
    "unused_parens",
    "unused_variables",
    "clippy::collapsible_else_if",
    "clippy::collapsible_if",
    "clippy::comparison_chain",
    "clippy::excessive_precision",
    "clippy::float_cmp",
    "clippy::many_single_char_names",
    "clippy::manual_range_contains",
    "clippy::needless_range_loop",
    "clippy::needless_return",
    "clippy::neg_cmp_op_on_partial_ord",
    "clippy::nonminimal_bool",
    "clippy::similar_names",
    "clippy::too_many_arguments",
];

/// Types whose values can change behind a shared reference: a `const` of one of them is refused
/// (with a `static`, it would carry state from one call of a region to the next).
pub const INTERIOR_MUTABILITY: &[&str] = &[
    "Cell",
    "RefCell",
    "UnsafeCell",
    "OnceCell",
    "OnceLock",
    "LazyCell",
    "LazyLock",
    "Mutex",
    "RwLock",
    "Condvar",
    "AtomicBool",
    "AtomicI8",
    "AtomicI16",
    "AtomicI32",
    "AtomicI64",
    "AtomicIsize",
    "AtomicPtr",
    "AtomicU8",
    "AtomicU16",
    "AtomicU32",
    "AtomicU64",
    "AtomicUsize",
];

/// A region longer than this is refused before it is parsed...
pub const MAX_REGION_BYTES: usize = 8 * 1024;
/// ...and so is one whose brackets nest deeper than this. The parser recurses once or more per
/// level, so these two bounds keep it within the stack it is given ([`PARSER_STACK_BYTES`]); the
/// solution's largest region has 2,043 bytes and nests 9 deep (2026-12-03) (a test keeps every region below a
/// quarter of both).
pub const MAX_NESTING: usize = 40;
/// The stack of the thread that parses and checks a region. The worst shapes that
/// [`MAX_REGION_BYTES`] can hold (8 KiB of `-`, `!`, `return`, closures, `else if`...; a test
/// parses each) needed between 32 and 64 MiB (2026-12-03, overflowing at 32): four times the
/// most, reserved and not touched unless used.
pub const PARSER_STACK_BYTES: usize = 256 << 20;
