//! What the code of a solution region may use, checked by parsing it (syn), not by searching its
//! text: comments and strings cannot trip the check, and no alias or macro hides a path from it.
//!
//! A region of a submission is spliced into the instructor's tree only if it passes. Allowed:
//! - names in scope already: locals, parameters, and what the file imports outside the regions
//!   (the instructor's imports), with their associated items (`Vec3::new`, `NodeView::Leaf`);
//! - `glam`, and of `std`/`core`/`alloc` the maths, collections and language modules
//!   ([`STD_MODULES`]);
//! - the renderer's student API: `crate::` paths into the modules the handouts name for the
//!   region's checkpoint ([`student_modules`]);
//! - the macros in [`MACROS`], whose arguments are parsed and checked too (`println!` and friends
//!   print to nobody: no grade reads what a region prints).
//!
//! Rejected, with the line: other macros (`include_bytes!`, `env!`, `asm!`...), other `std`
//! modules (`fs`, `io`, `process`, `env`, `net`, `os`, `thread`, `ptr`...), the renderer's other
//! crates (`tobj`, `rayon`, `png`...), `unsafe`, `extern`, `mod`, macro definitions, attributes but
//! `allow`/`inline`/`doc`/`must_use`, `self::`/`super::` paths, and every name of the harness that
//! a solution must not call ([`HARNESS_NAMES`]: the SAH split, the wide BVH, render's stand-ins, the grader's
//! switch between student and solution code, file loading and writing).

use proc_macro2::{Span, TokenStream};
use syn::parse::Parser;
use syn::punctuated::Punctuated;
use syn::visit::Visit;

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

/// Modules of the renderer (`crate::...`) a region of each checkpoint may name: the student API
/// its handout works with. Geometry (2-4) needs the maths and the geometry types; glass (5) also
/// the materials, the scene and the integrators; direct lighting (6) also the lights;
/// anti-aliasing (7) the maths, the generator, sampling, the camera and the film. A checkpoint
/// not listed (the extras) may name every module of the student API.
pub const STUDENT_API: &[(u32, &[&str])] = &[
    (2, &["math", "geometry"]),
    (3, &["math", "geometry"]),
    (4, &["math", "geometry"]),
    (5, &["math", "geometry", "material", "integrator", "scene"]),
    (6, &["math", "geometry", "material", "integrator", "scene", "light"]),
    (7, &["math", "rng", "sampling", "camera", "film"]),
];

/// Every module of the student API.
const ALL_STUDENT_MODULES: &[&str] = &[
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

/// The modules a region of `checkpoint` may name (see [`STUDENT_API`]).
pub fn student_modules(checkpoint: u32) -> &'static [&'static str] {
    STUDENT_API.iter().find(|(c, _)| *c == checkpoint).map_or(ALL_STUDENT_MODULES, |(_, m)| m)
}

/// The renderer's dependencies other than glam: reachable by name in its code, never from a region.
pub const OTHER_CRATES: &[&str] =
    &["clap", "png", "rayon", "serde", "thiserror", "tobj", "toml", "wide", "raylab"];

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
    // The grader's switch between a submission's code and the solution's (see `crate::splice`).
    "graded",
    // Reading and writing files, and rendering whole images.
    "load",
    "from_toml",
    "image_io",
    "read_png",
    "write_png",
    "write_film",
    "write_file_atomic",
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
const MAX_NUMBERS: usize = 64;
/// ...or string literals longer than this in all, look like an embedded table (a reference
/// image's pixels, the tile means a noisy scene is graded against) and reject the region. The
/// solution's largest region has 10 number literals and no string (2026-12-02); a test keeps
/// every region below a quarter of both limits.
const MAX_TEXT: usize = 512;

/// Attributes a region may carry.
const ATTRIBUTES: &[&str] = &["allow", "doc", "inline", "must_use"];

/// Why a region was rejected: the first thing found, at a line counted from the region's first
/// line (1 is the line after `// BEGIN SOLUTION`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rejection {
    /// Line within the region body, from 1.
    pub line: usize,
    /// One line.
    pub reason: String,
}

/// Checks a region body (the statements of a function body) of `checkpoint`.
pub fn check_region(body: &str, checkpoint: u32) -> Result<(), Rejection> {
    // The body is parsed as a block; "{\n" shifts every line by one.
    let block: syn::Block = syn::parse_str(&format!("{{\n{body}\n}}"))
        .map_err(|e| Rejection { line: line_of(e.span()), reason: format!("does not parse: {e}") })?;
    let mut checker =
        Checker { found: None, modules: student_modules(checkpoint), checkpoint, numbers: 0, text: 0 };
    checker.visit_block(&block);
    checker.found.map_or(Ok(()), Err)
}

fn line_of(span: Span) -> usize {
    span.start().line.saturating_sub(1).max(1)
}

struct Checker {
    found: Option<Rejection>,
    /// The `crate::` modules this region may name.
    modules: &'static [&'static str],
    checkpoint: u32,
    /// Number literals so far, and bytes of string literals.
    numbers: usize,
    text: usize,
}

impl Checker {
    fn reject(&mut self, span: Span, reason: String) {
        if self.found.is_none() {
            self.found = Some(Rejection { line: line_of(span), reason });
        }
    }

    /// The rules for one path, given as its segments.
    fn check_segments(&mut self, span: Span, segments: &[String]) {
        let text = segments.join("::");
        // A name alone is a local or one of the instructor's imports (a student may call a
        // variable `load`); through a path it is the harness's item.
        let harness = segments.iter().find(|s| HARNESS_NAMES.contains(&s.as_str()));
        if let Some(name) = harness.filter(|_| segments.len() > 1) {
            return self.reject(span, format!("`{text}`: `{name}` is the harness's, not for solutions"));
        }
        let (Some(first), second) = (segments.first(), segments.get(1)) else { return };
        let reason = match first.as_str() {
            "std" | "core" | "alloc" => match second {
                Some(m) if STD_MODULES.contains(&m.as_str()) => return,
                _ => format!("`{text}`: only maths, collections and language items of std may be used"),
            },
            "crate" => match second {
                Some(m) if self.modules.contains(&m.as_str()) => return,
                Some(m) if ALL_STUDENT_MODULES.contains(&m.as_str()) => format!(
                    "`{text}`: checkpoint {} works with crate::{{{}}}, not `{m}`",
                    self.checkpoint,
                    self.modules.join(", ")
                ),
                _ => format!("`{text}`: not part of the student API"),
            },
            "self" | "super" if segments.len() > 1 => {
                format!("`{text}`: use the names imported outside the region, or a `crate::` path")
            }
            c if OTHER_CRATES.contains(&c) && segments.len() > 1 => {
                format!("`{text}`: the crate `{c}` is not for solutions")
            }
            _ => return,
        };
        self.reject(span, reason)
    }

    fn check_path(&mut self, path: &syn::Path) {
        let segments: Vec<String> = path.segments.iter().map(|s| s.ident.to_string()).collect();
        self.check_segments(span_of(path), &segments);
    }

    /// A use tree, flattened into every path it imports.
    fn check_use(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.check_use(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.check_full(prefix, n.ident.to_string(), n.ident.span()),
            syn::UseTree::Rename(r) => self.check_full(prefix, r.ident.to_string(), r.ident.span()),
            syn::UseTree::Glob(g) => {
                let span = g.star_token.span;
                self.check_full(prefix, "*".to_string(), span)
            }
            syn::UseTree::Group(g) => g.items.iter().for_each(|t| self.check_use(prefix, t)),
        }
    }

    fn check_full(&mut self, prefix: &[String], last: String, span: Span) {
        let mut segments = prefix.to_vec();
        segments.push(last);
        // `use std;` or `use tobj;` alone names a whole crate.
        if segments.len() == 1
            && ["std", "core", "alloc"].iter().chain(OTHER_CRATES).any(|c| *c == segments[0])
        {
            return self.reject(span, format!("`use {}`: name the items, not the crate", segments[0]));
        }
        self.check_segments(span, &segments);
    }

    fn check_macro(&mut self, mac: &syn::Macro) {
        let span = span_of(&mac.path);
        let segments: Vec<String> = mac.path.segments.iter().map(|s| s.ident.to_string()).collect();
        let name = segments.last().cloned().unwrap_or_default();
        let qualified_ok =
            segments.len() == 1 || (segments.len() == 2 && ["std", "core"].contains(&segments[0].as_str()));
        if !MACROS.contains(&name.as_str()) || !qualified_ok {
            return self
                .reject(span, format!("the macro `{}!` is not allowed in solutions", segments.join("::")));
        }
        match parse_macro_arguments(&name, mac.tokens.clone()) {
            Some(arguments) => arguments.iter().for_each(|a| self.visit_macro_argument(a)),
            None => self.reject(span, format!("the arguments of `{name}!` could not be checked")),
        }
    }

    fn visit_macro_argument(&mut self, argument: &MacroArgument) {
        match argument {
            MacroArgument::Expr(e) => self.visit_expr(e),
            MacroArgument::Pat(p) => self.visit_pat(p),
        }
    }
}

fn span_of(path: &syn::Path) -> Span {
    path.segments.first().map_or_else(Span::call_site, |s| s.ident.span())
}

/// What a macro call's tokens hold, once parsed.
enum MacroArgument {
    Expr(syn::Expr),
    Pat(syn::Pat),
}

/// Parses the arguments of an allowed macro: comma-separated expressions; `vec![x; n]`;
/// `matches!(expr, pattern if guard)`. `None` if they do not parse that way.
fn parse_macro_arguments(name: &str, tokens: TokenStream) -> Option<Vec<MacroArgument>> {
    let exprs = |t: TokenStream| Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated.parse2(t).ok();
    if name == "matches" {
        let parser = |input: syn::parse::ParseStream| {
            let e: syn::Expr = input.parse()?;
            input.parse::<syn::Token![,]>()?;
            let p = syn::Pat::parse_multi_with_leading_vert(input)?;
            let guard = if input.peek(syn::Token![if]) {
                input.parse::<syn::Token![if]>()?;
                Some(input.parse::<syn::Expr>()?)
            } else {
                None
            };
            let _ = input.parse::<Option<syn::Token![,]>>()?;
            Ok((e, p, guard))
        };
        let (e, p, guard) = parser.parse2(tokens).ok()?;
        let mut out = vec![MacroArgument::Expr(e), MacroArgument::Pat(p)];
        out.extend(guard.map(MacroArgument::Expr));
        return Some(out);
    }
    if let Some(list) = exprs(tokens.clone()) {
        return Some(list.into_iter().map(MacroArgument::Expr).collect());
    }
    if name == "vec" {
        let parser = |input: syn::parse::ParseStream| {
            let e: syn::Expr = input.parse()?;
            input.parse::<syn::Token![;]>()?;
            let n: syn::Expr = input.parse()?;
            Ok((e, n))
        };
        let (e, n) = parser.parse2(tokens).ok()?;
        return Some(vec![MacroArgument::Expr(e), MacroArgument::Expr(n)]);
    }
    None
}

impl<'ast> Visit<'ast> for Checker {
    fn visit_path(&mut self, path: &'ast syn::Path) {
        self.check_path(path);
        syn::visit::visit_path(self, path);
    }

    fn visit_item_use(&mut self, item: &'ast syn::ItemUse) {
        self.check_use(&mut Vec::new(), &item.tree);
        for attribute in &item.attrs {
            self.visit_attribute(attribute);
        }
    }

    fn visit_macro(&mut self, mac: &'ast syn::Macro) {
        self.check_macro(mac);
    }

    fn visit_attribute(&mut self, attribute: &'ast syn::Attribute) {
        let name =
            attribute.path().segments.iter().map(|s| s.ident.to_string()).collect::<Vec<_>>().join("::");
        if !ATTRIBUTES.contains(&name.as_str()) {
            self.reject(
                span_of(attribute.path()),
                format!("the attribute `#[{name}]` is not allowed in solutions"),
            );
        }
    }

    fn visit_lit(&mut self, lit: &'ast syn::Lit) {
        match lit {
            syn::Lit::Int(_) | syn::Lit::Float(_) => self.numbers += 1,
            syn::Lit::Str(s) => self.text += s.value().len(),
            syn::Lit::ByteStr(s) => self.text += s.value().len(),
            syn::Lit::CStr(s) => self.text += s.value().as_bytes().len(),
            _ => {}
        }
        if self.numbers > MAX_NUMBERS || self.text > MAX_TEXT {
            self.reject(
                lit.span(),
                format!(
                    "more than {MAX_NUMBERS} numbers or {MAX_TEXT} bytes of text: a solution computes, it does not embed data"
                ),
            );
        }
    }

    fn visit_expr_unsafe(&mut self, e: &'ast syn::ExprUnsafe) {
        self.reject(e.unsafe_token.span, "`unsafe` is not allowed in solutions".to_string());
    }

    fn visit_signature(&mut self, sig: &'ast syn::Signature) {
        if let Some(token) = &sig.unsafety {
            self.reject(token.span, "`unsafe fn` is not allowed in solutions".to_string());
        }
        if let Some(abi) = &sig.abi {
            self.reject(abi.extern_token.span, "`extern` functions are not allowed in solutions".to_string());
        }
        syn::visit::visit_signature(self, sig);
    }

    fn visit_item_impl(&mut self, item: &'ast syn::ItemImpl) {
        if let Some(token) = &item.unsafety {
            self.reject(token.span, "`unsafe impl` is not allowed in solutions".to_string());
        }
        syn::visit::visit_item_impl(self, item);
    }

    fn visit_item_trait(&mut self, item: &'ast syn::ItemTrait) {
        if let Some(token) = &item.unsafety {
            self.reject(token.span, "`unsafe trait` is not allowed in solutions".to_string());
        }
        syn::visit::visit_item_trait(self, item);
    }

    fn visit_item_mod(&mut self, item: &'ast syn::ItemMod) {
        item.attrs.iter().for_each(|a| self.visit_attribute(a));
        self.reject(item.mod_token.span, "a `mod` is not allowed in solutions".to_string());
    }

    fn visit_item_macro(&mut self, item: &'ast syn::ItemMacro) {
        match &item.ident {
            Some(ident) => {
                self.reject(ident.span(), "macro definitions are not allowed in solutions".to_string())
            }
            None => self.check_macro(&item.mac),
        }
    }

    fn visit_item_extern_crate(&mut self, item: &'ast syn::ItemExternCrate) {
        self.reject(item.extern_token.span, "`extern crate` is not allowed in solutions".to_string());
    }

    fn visit_item_foreign_mod(&mut self, item: &'ast syn::ItemForeignMod) {
        self.reject(item.abi.extern_token.span, "`extern` blocks are not allowed in solutions".to_string());
    }

    fn visit_item_static(&mut self, item: &'ast syn::ItemStatic) {
        if matches!(item.mutability, syn::StaticMutability::Mut(_)) {
            self.reject(item.ident.span(), "`static mut` is not allowed in solutions".to_string());
        }
        syn::visit::visit_item_static(self, item);
    }

    fn visit_item(&mut self, item: &'ast syn::Item) {
        match item {
            syn::Item::Verbatim(tokens) => self.reject_verbatim(tokens),
            _ => syn::visit::visit_item(self, item),
        }
    }

    fn visit_expr(&mut self, e: &'ast syn::Expr) {
        match e {
            syn::Expr::Verbatim(tokens) => self.reject_verbatim(tokens),
            _ => syn::visit::visit_expr(self, e),
        }
    }
}

impl Checker {
    fn reject_verbatim(&mut self, tokens: &TokenStream) {
        let span = tokens.clone().into_iter().next().map_or_else(Span::call_site, |t| t.span());
        self.reject(span, "code syn cannot read is not allowed in solutions".to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stub::{region_bodies, rust_files};

    #[test]
    fn grader_allows_every_region_of_the_solution() {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src");
        for (_, text) in rust_files(&src).unwrap() {
            for checkpoint in 1..=9 {
                for r in region_bodies(&text, checkpoint) {
                    check_region(&text[r.clone()], checkpoint)
                        .unwrap_or_else(|e| panic!("{e:?} in\n{}", &text[r]));
                }
            }
        }
    }

    fn rejected(body: &str) -> Rejection {
        check_region(body, 6).expect_err(body)
    }

    #[test]
    fn grader_rejects_reaching_outside_the_student_api_however_it_is_spelled() {
        for (body, reason) in [
            ("let b = std::fs::read(\"reference/cornell.png\");", "std::fs::read"),
            ("use std::fs as f;\nlet b = f::read(\"x\");", "std::fs"),
            ("use std::{collections::HashMap, process};", "std::process"),
            ("use std::*;", "std::*"),
            ("::std::process::exit(0)", "std::process::exit"),
            ("core::ptr::null::<u8>();", "core::ptr"),
            ("let b = include_bytes!(\"../../reference/cornell.png\");", "include_bytes"),
            ("println!(\"{:?}\", std::env::var(\"HOME\"));", "std::env::var"),
            ("let v = vec![std::process::id(); 3];", "std::process::id"),
            ("let m = matches!(x, Some(_) if std::thread::panicking());", "std::thread::panicking"),
            ("unsafe { *(0 as *const u8) }", "unsafe"),
            ("#[no_mangle]\nfn main() {}", "no_mangle"),
            ("#[path = \"x.rs\"]\nmod m;", "path"),
            ("macro_rules! m { () => {} }", "macro definitions"),
            ("extern \"C\" { fn abort(); }", "extern"),
            ("let s = crate::geometry::bvh::sah::split(prims);", "sah"),
            ("return crate::geometry::WideBvh::collapse(self).traverse(ray, any_hit, stats);", "WideBvh"),
            ("let w = World::wide(world.scene());", "wide"),
            ("let s = Scene::load(path);", "load"),
            ("crate::fallback::closest_triangle(t, ray)", "fallback"),
            ("if crate::graded::student(2) { 1 } else { 2 }", "graded"),
            ("tobj::load_obj(\"x.obj\", &tobj::LoadOptions::default())", "load"),
            ("rayon::spawn(|| loop {});", "rayon"),
            ("super::super::fallback::Fallbacks::default()", "fallback"),
            ("super::NodeView::Leaf", "super::NodeView"),
        ] {
            let r = rejected(body);
            assert!(r.reason.contains(reason), "{body}: {r:?}");
        }
    }

    #[test]
    fn grader_is_not_tripped_by_comments_strings_or_printing() {
        for body in [
            "// std::fs::read would be cheating\nlet s = \"std::process::exit\";\nprintln!(\"{s}\");\nNone",
            "let v: Vec<f32> = vec![0.0; 3];\nlet m = std::collections::HashMap::<u32, f32>::new();\nv.len()",
            "let (a, b) = (1.0f32, 2.0f32);\nlet c = a.min(b).max(f32::EPSILON) * std::f32::consts::PI;\nc",
            "use std::mem::swap;\nlet (mut a, mut b) = (1, 2);\nswap(&mut a, &mut b);\ndbg!(a + b)",
            "matches!(self.view(), NodeView::Leaf { .. })",
            "#[allow(clippy::needless_range_loop)]\nfor i in 0..3 { debug_assert!(i < 3, \"{i}\"); }",
        ] {
            check_region(body, 4).unwrap_or_else(|e| panic!("{body}: {e:?}"));
        }
    }

    #[test]
    fn grader_knows_every_crate_the_renderer_depends_on() {
        let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.toml");
        let manifest: toml::Table = toml::from_str(&std::fs::read_to_string(manifest).unwrap()).unwrap();
        for name in manifest["dependencies"].as_table().unwrap().keys().filter(|n| *n != "glam") {
            assert!(OTHER_CRATES.contains(&name.as_str()), "{name} is missing from OTHER_CRATES");
        }
    }

    #[test]
    fn grader_lets_a_local_variable_share_a_harness_name() {
        check_region("let load = 0.5f32;\nlet render = load * 2.0;\nrender", 2).unwrap();
    }

    /// Each checkpoint names the modules its handout works with: the triangle test reaches no
    /// light, and anti-aliasing no geometry; every module is open to the extras.
    #[test]
    fn grader_allows_each_region_the_student_api_of_its_checkpoint() {
        let light = "let i = crate::light::PointLight::intensity;";
        assert!(check_region(light, 6).is_ok());
        let reason = check_region(light, 2).unwrap_err().reason;
        assert!(reason.contains("checkpoint 2 works with crate::{math, geometry}"), "{reason}");
        assert!(check_region("let b = crate::geometry::Aabb::new;", 7).is_err());
        assert!(check_region("let s = crate::sampling::estimate_pixel;", 7).is_ok());
        assert!(check_region(light, 8).is_ok());
    }

    /// A table of values (here 300 tile means, as a region copying a noisy scene's reference
    /// would hold) is rejected, in numbers or in text; the solution's regions stay far below the
    /// limits.
    #[test]
    fn grader_rejects_a_region_that_embeds_a_table_of_data() {
        let table: Vec<String> = (0..300).map(|i| format!("{:.4}", i as f32 / 300.0)).collect();
        let numbers = format!("const T: [f32; 300] = [{}];\nT[0]", table.join(", "));
        assert!(rejected(&numbers).reason.contains("does not embed data"));
        let text = format!("let t = \"{}\";\nt.len()", table.join(","));
        assert!(rejected(&text).reason.contains("does not embed data"));
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src");
        let (mut numbers, mut text) = (0, 0);
        for (_, file) in rust_files(&src).unwrap() {
            for checkpoint in 1..=9 {
                for r in region_bodies(&file, checkpoint) {
                    let block: syn::Block = syn::parse_str(&format!("{{\n{}\n}}", &file[r])).unwrap();
                    let mut checker = Checker {
                        found: None,
                        modules: student_modules(checkpoint),
                        checkpoint,
                        numbers: 0,
                        text: 0,
                    };
                    checker.visit_block(&block);
                    (numbers, text) = (checker.numbers.max(numbers), checker.text.max(text));
                }
            }
        }
        assert!(
            numbers <= MAX_NUMBERS / 4 && text <= MAX_TEXT / 4,
            "the solution's largest region: {numbers} numbers, {text} bytes"
        );
    }

    #[test]
    fn grader_reports_the_line_of_the_rejected_code() {
        assert_eq!(rejected("let a = 1;\n\nlet b = std::fs::read(\"x\");").line, 3);
    }
}
