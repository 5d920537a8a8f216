//! The checker of solution regions: what the code of a region may use, read from its syntax (syn),
//! not searched for in its text.
//!
//! It does not resolve names as rustc does; it rejects what it cannot see through. A region of a
//! submission is spliced into the instructor's tree only if it passes. Allowed:
//! - names in scope already: locals, parameters, and what the file imports outside the regions
//!   (the instructor's imports), with their associated items (`Vec3::new`, `NodeView::Leaf`);
//! - `glam`, and of `std`/`core`/`alloc` the maths, collections and language modules
//!   ([`STD_MODULES`]);
//! - the renderer's student API: `crate::` paths into the modules the handouts name for the
//!   region's checkpoint (the rubric's `student_api`, [`StudentApi`]);
//! - the macros in [`MACROS`], called by their own names, whose arguments are parsed and checked
//!   too (`println!` and friends print to nobody: no grade reads what a region prints);
//! - items that act only inside the function: nested `fn`s, `struct`s and `enum`s, `impl`s of
//!   types the region declares, `const`s without interior mutability, `use` of single names;
//! - the attributes `inline`, `must_use`, doc comments, and `allow` of the lints in
//!   [`ALLOWED_LINTS`].
//!
//! Rejected, each with its line and a reason: raw identifiers (`r#std` is `std` to rustc), `use
//! ... as ...` and glob imports, a macro a `use` brought in, qualified paths (`<T>::item`) whose
//! item would be rejected after a type, other macros, other `std` modules, the renderer's other
//! crates, `self::`/`super::` paths, every name of the harness ([`HARNESS_NAMES`]), `unsafe` in
//! every form, `extern`, `mod`, `trait`, `static`, macro definitions, an `impl` of a type declared
//! elsewhere (an `impl Drop for Bvh` would run in every checkpoint's build), any other attribute or
//! any expression in one, and data: more than [`MAX_NUMBERS`] number literals or [`MAX_TEXT`]
//! bytes of strings, chars, bytes and doc text. Before syn parses a region, its size and nesting
//! are bounded ([`MAX_REGION_BYTES`], [`MAX_NESTING`]) and it is parsed on a thread with a stack
//! sized for the worst shape those allow, so no region can crash the grader.
//!
//! The checker is the first of three walls, the one that explains itself; the compiler
//! (`#![deny(unsafe_code)]` in the renderer, privacy) and the operating system are the others.

mod lists;
mod macros;
mod refusal;
#[cfg(test)]
mod tests;
mod visit;

use std::collections::BTreeSet;

pub use lists::*;
use macros::{parse_macro_arguments, MacroArgument};
use proc_macro2::Span;
pub use refusal::Refusal;
use syn::parse::Parser;
use syn::punctuated::Punctuated;
use syn::visit::Visit;

use crate::regions::lexer::{line_at, nesting, tokens, Kind};

/// Why a region was rejected: the first thing found, at a line counted from the region's first
/// line (1 is the line after `// BEGIN SOLUTION`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rejection {
    /// Line within the region body, from 1.
    pub line: usize,
    /// What was refused.
    pub reason: Refusal,
}

/// Checks a region body (the statements of a function body) of `checkpoint`, which may name the
/// renderer's `modules`.
pub fn check_region(body: &str, checkpoint: u32, modules: &[&str]) -> Result<(), Rejection> {
    let at = |line: usize, reason: Refusal| Rejection { line, reason };
    if body.len() > MAX_REGION_BYTES {
        return Err(at(1, Refusal::TooLong));
    }
    let tokens = tokens(body).map_err(|e| at(line_at(body, e.byte), Refusal::DoesNotParse(e.to_string())))?;
    if let Some(raw) =
        tokens.iter().find(|t| t.kind == Kind::Ident && body[t.range.clone()].starts_with("r#"))
    {
        let name = body[raw.range.clone()].to_string();
        return Err(at(line_at(body, raw.range.start), Refusal::RawIdentifier(name)));
    }
    match nesting(&tokens) {
        (_, false) => return Err(at(1, Refusal::Unbalanced)),
        (depth, _) if depth > MAX_NESTING => return Err(at(1, Refusal::TooDeep(depth))),
        _ => {}
    }
    // syn recurses on nested syntax (and so does dropping the tree): a stack of its own.
    std::thread::scope(|scope| {
        let checking = std::thread::Builder::new()
            .stack_size(PARSER_STACK_BYTES)
            .spawn_scoped(scope, || check_parsed(body, checkpoint, modules));
        match checking.map(|thread| thread.join()) {
            Ok(Ok(verdict)) => verdict,
            _ => Err(at(1, Refusal::Unchecked)),
        }
    })
}

fn check_parsed(body: &str, checkpoint: u32, modules: &[&str]) -> Result<(), Rejection> {
    // The body is parsed as a block; "{\n" shifts every line by one.
    let block: syn::Block = syn::parse_str(&format!("{{\n{body}\n}}"))
        .map_err(|e| Rejection { line: line_of(e.span()), reason: Refusal::DoesNotParse(e.to_string()) })?;
    let mut declared = Declared::default();
    declared.visit_block(&block);
    let mut checker = Checker::new(checkpoint, modules, declared);
    checker.visit_block(&block);
    checker.finish();
    checker.found.map_or(Ok(()), Err)
}

fn line_of(span: Span) -> usize {
    span.start().line.saturating_sub(1).max(1)
}

/// What a region declares, wherever in it: the types its `impl`s may be of, and the names its
/// `use`s bring in.
#[derive(Default)]
struct Declared {
    types: BTreeSet<String>,
    imported: BTreeSet<String>,
}

impl<'ast> Visit<'ast> for Declared {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        match item {
            syn::Item::Struct(s) => _ = self.types.insert(s.ident.to_string()),
            syn::Item::Enum(e) => _ = self.types.insert(e.ident.to_string()),
            syn::Item::Union(u) => _ = self.types.insert(u.ident.to_string()),
            _ => {}
        }
        syn::visit::visit_item(self, item);
    }

    fn visit_use_name(&mut self, name: &'ast syn::UseName) {
        self.imported.insert(name.ident.to_string());
    }

    fn visit_use_rename(&mut self, rename: &'ast syn::UseRename) {
        self.imported.insert(rename.rename.to_string());
    }
}

struct Checker<'a> {
    found: Option<Rejection>,
    /// The `crate::` modules this region may name.
    modules: &'a [&'a str],
    checkpoint: u32,
    declared: Declared,
    /// Number literals so far, and bytes of text (strings, chars, bytes, doc comments).
    numbers: usize,
    text: usize,
}

impl<'a> Checker<'a> {
    fn new(checkpoint: u32, modules: &'a [&'a str], declared: Declared) -> Self {
        Checker { found: None, modules, checkpoint, declared, numbers: 0, text: 0 }
    }

    fn reject(&mut self, span: Span, reason: Refusal) {
        if self.found.is_none() {
            self.found = Some(Rejection { line: line_of(span), reason });
        }
    }

    /// The data limits, once every literal has been counted.
    fn finish(&mut self) {
        if self.found.is_none() && (self.numbers > MAX_NUMBERS || self.text > MAX_TEXT) {
            let reason = Refusal::TooMuchData { numbers: self.numbers, text: self.text };
            self.found = Some(Rejection { line: 1, reason });
        }
    }

    /// The rules for one path, given as its segments.
    fn check_segments(&mut self, span: Span, segments: &[String]) {
        let text = segments.join("::");
        // A name alone is a local or one of the instructor's imports (a student may call a
        // variable `load`); through a path it is the harness's item.
        let harness = segments.iter().find(|s| HARNESS_NAMES.contains(&s.as_str()));
        if let Some(name) = harness.filter(|_| segments.len() > 1) {
            return self.reject(span, Refusal::Harness { path: text, name: name.clone() });
        }
        let (Some(first), second) = (segments.first(), segments.get(1)) else { return };
        let reason = match first.as_str() {
            "std" | "core" | "alloc" => match second {
                Some(m) if STD_MODULES.contains(&m.as_str()) => return,
                _ => Refusal::StdModule(text),
            },
            "crate" => match second {
                Some(m) if self.modules.contains(&m.as_str()) => return,
                Some(m) if ALL_STUDENT_MODULES.contains(&m.as_str()) => Refusal::OtherCheckpointModule {
                    path: text,
                    checkpoint: self.checkpoint,
                    modules: self.modules.iter().map(|m| m.to_string()).collect(),
                    module: m.clone(),
                },
                _ => Refusal::NotStudentApi(text),
            },
            "self" | "super" if segments.len() > 1 => Refusal::SelfOrSuper(text),
            c if OTHER_CRATES.contains(&c) && segments.len() > 1 => {
                Refusal::OtherCrate { path: text, krate: c.to_string() }
            }
            _ => return,
        };
        self.reject(span, reason)
    }

    fn check_path(&mut self, path: &syn::Path) {
        self.check_segments(span_of(path), &names(path));
    }

    /// `<T>::item` and `<T as Trait>::item`: the type is checked as a type (by the visitor),
    /// the trait as a path, and the item as if named after a type (`Scene::load`).
    fn check_qualified(&mut self, qself: &syn::QSelf, path: &syn::Path) {
        let item = names(path).split_off(qself.position.min(path.segments.len()));
        let segments: Vec<String> = std::iter::once("<_>".to_string()).chain(item).collect();
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
            syn::UseTree::Rename(r) => self.reject(
                r.as_token.span,
                Refusal::UseAs { name: r.ident.to_string(), rename: r.rename.to_string() },
            ),
            syn::UseTree::Glob(g) => self.reject(g.star_token.span, Refusal::Glob(prefix.join("::"))),
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
            return self.reject(span, Refusal::WholeCrate(segments[0].clone()));
        }
        self.check_segments(span, &segments);
    }

    fn check_macro(&mut self, mac: &syn::Macro) {
        let span = span_of(&mac.path);
        let segments = names(&mac.path);
        let name = segments.last().cloned().unwrap_or_default();
        if segments.len() == 1 && self.declared.imported.contains(&name) {
            return self.reject(span, Refusal::ImportedMacro(name));
        }
        let qualified_ok =
            segments.len() == 1 || (segments.len() == 2 && ["std", "core"].contains(&segments[0].as_str()));
        if !MACROS.contains(&name.as_str()) || !qualified_ok {
            return self.reject(span, Refusal::Macro(segments.join("::")));
        }
        match parse_macro_arguments(&name, mac.tokens.clone()) {
            Some(arguments) => arguments.iter().for_each(|a| self.visit_macro_argument(a)),
            None => self.reject(span, Refusal::MacroArguments(name)),
        }
    }

    fn visit_macro_argument(&mut self, argument: &MacroArgument) {
        match argument {
            MacroArgument::Expr(e) => self.visit_expr(e),
            MacroArgument::Pat(p) => self.visit_pat(p),
        }
    }

    /// `inline`, `must_use`, `doc` with a string, `allow` of listed lints: nothing else, and no
    /// expression anywhere in an attribute.
    fn check_attribute(&mut self, attribute: &syn::Attribute) {
        let name = names(attribute.path()).join("::");
        let span = span_of(attribute.path());
        let string = |value: &syn::Expr| match value {
            syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Str(s), attrs }) if attrs.is_empty() => {
                Some(s.value())
            }
            _ => None,
        };
        let verdict = match (name.as_str(), &attribute.meta) {
            ("inline" | "must_use", syn::Meta::Path(_)) => Ok(()),
            ("inline", syn::Meta::List(list))
                if ["always", "never"].contains(&list.tokens.to_string().as_str()) =>
            {
                Ok(())
            }
            ("doc" | "must_use", syn::Meta::NameValue(nv)) => match string(&nv.value) {
                Some(text) => {
                    self.text += text.len();
                    Ok(())
                }
                None => Err(Refusal::AttributeValue(name.clone())),
            },
            ("allow", syn::Meta::List(list)) => self.check_lints(list),
            _ => Err(Refusal::Attribute(name.clone())),
        };
        if let Err(reason) = verdict {
            self.reject(span, reason);
        }
    }

    fn check_lints(&mut self, list: &syn::MetaList) -> Result<(), Refusal> {
        let lints = Punctuated::<syn::Path, syn::Token![,]>::parse_terminated
            .parse2(list.tokens.clone())
            .map_err(|_| Refusal::LintList)?;
        match lints.iter().map(|l| names(l).join("::")).find(|l| !ALLOWED_LINTS.contains(&l.as_str())) {
            Some(lint) => Err(Refusal::Lint(lint)),
            None => Ok(()),
        }
    }

    /// Items inside a region act inside its function only, or not at all.
    fn check_item(&mut self, item: &syn::Item) -> Result<(), (Span, Refusal)> {
        let why = match item {
            syn::Item::Fn(_) | syn::Item::Struct(_) | syn::Item::Enum(_) | syn::Item::Union(_) => {
                return Ok(())
            }
            syn::Item::Use(_) | syn::Item::Type(_) => return Ok(()),
            syn::Item::Macro(m) if m.ident.is_none() => return Ok(()),
            syn::Item::Const(c) => match interior_mutability(&c.ty) {
                Some(name) => Refusal::InteriorConst(name.to_string()),
                None => return Ok(()),
            },
            syn::Item::Impl(i) => match &*i.self_ty {
                syn::Type::Path(p) if p.qself.is_none() && p.path.segments.len() == 1 => {
                    let name = p.path.segments[0].ident.to_string();
                    // `impl<X> Drop for X` is for every type, whatever the region declares.
                    let generic = i.generics.type_params().any(|t| t.ident == name);
                    if self.declared.types.contains(&name) && !generic {
                        return Ok(());
                    }
                    Refusal::ForeignImpl(Some(name))
                }
                _ => Refusal::ForeignImpl(None),
            },
            syn::Item::Static(_) => Refusal::Static,
            syn::Item::Trait(_) | syn::Item::TraitAlias(_) => Refusal::Trait,
            syn::Item::Mod(_) => Refusal::Mod,
            syn::Item::Macro(_) => Refusal::MacroDefinition,
            syn::Item::ExternCrate(_) => Refusal::ExternCrate,
            syn::Item::ForeignMod(_) => Refusal::ExternBlock,
            _ => Refusal::Unreadable,
        };
        Err((item_span(item), why))
    }
}

/// Where an item that is refused starts: its keyword.
fn item_span(item: &syn::Item) -> Span {
    match item {
        syn::Item::Const(c) => c.const_token.span,
        syn::Item::Impl(i) => i.impl_token.span,
        syn::Item::Static(s) => s.static_token.span,
        syn::Item::Trait(t) => t.trait_token.span,
        syn::Item::TraitAlias(t) => t.trait_token.span,
        syn::Item::Mod(m) => m.mod_token.span,
        syn::Item::Macro(m) => span_of(&m.mac.path),
        syn::Item::ExternCrate(e) => e.extern_token.span,
        syn::Item::ForeignMod(f) => f.abi.extern_token.span,
        syn::Item::Verbatim(tokens) => {
            tokens.clone().into_iter().next().map_or_else(Span::call_site, |t| t.span())
        }
        _ => Span::call_site(),
    }
}

/// A path's segments as written (raw identifiers never get here: they are refused first).
fn names(path: &syn::Path) -> Vec<String> {
    path.segments.iter().map(|s| s.ident.to_string()).collect()
}

fn span_of(path: &syn::Path) -> Span {
    path.segments.first().map_or_else(Span::call_site, |s| s.ident.span())
}

/// The first type with interior mutability that `ty` names, anywhere in it.
fn interior_mutability(ty: &syn::Type) -> Option<String> {
    struct Find(Option<String>);
    impl<'ast> Visit<'ast> for Find {
        fn visit_path_segment(&mut self, segment: &'ast syn::PathSegment) {
            let name = segment.ident.to_string();
            if INTERIOR_MUTABILITY.contains(&name.as_str()) {
                self.0.get_or_insert(name);
            }
            syn::visit::visit_path_segment(self, segment);
        }
    }
    let mut find = Find(None);
    find.visit_type(ty);
    find.0
}
