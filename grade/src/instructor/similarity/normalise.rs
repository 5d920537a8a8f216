//! A region's text as the tokens that disguise does not change.
//!
//! Read with `syn` (the parser the allow list uses), a region body becomes a sequence of tokens in
//! which:
//! - whitespace, comments and formatting are gone (they are not tokens);
//! - every name bound inside the region (a `let`, a closure's or a match arm's pattern, a nested
//!   `fn`) is the one token `$v`, so renaming changes nothing; the names a student cannot rename
//!   (the function's parameters, fields, methods, types) stay as they are;
//! - a number is its value (`1.0`, `1.`, `1e0`, `1.0_f32` are all `1`), any string `$s`;
//! - a binding's `mut` and a pattern's type annotation are dropped;
//! - in every block, a `let` that binds only names nothing after it uses is dropped (dead code),
//!   and each run of `let` statements is put in one order: by level (how deep in the run's
//!   dependencies it is), then by its normalised text, so independent statements written in any
//!   order read the same. Other statements (`if`, loops, assignments) keep their order.
//!
//! Each token keeps the line of the region it came from, to show the matching spans.

use std::collections::{BTreeSet, HashSet};

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use quote::ToTokens;
use syn::visit::Visit;
use syn::visit_mut::VisitMut;

/// One normalised token and the region line (from 1) it came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    /// Its normalised text.
    pub text: String,
    /// The line of the region body it came from, from 1.
    pub line: usize,
}

/// The normalised tokens of a region `body`. Code that `syn` cannot read as a block is normalised
/// token by token (numbers and strings as above, names as written: which are bound is not known,
/// no dead code or reordering); text that is not even Rust tokens gives none.
pub fn normalise(body: &str) -> Vec<Token> {
    // The body is wrapped in braces on lines of their own: region line = parsed line - 1.
    let wrapped = format!("{{\n{body}\n}}");
    match syn::parse_str::<syn::Block>(&wrapped) {
        Ok(mut block) => {
            let bound = bound_names(&block);
            Canonical { bound: &bound }.visit_block_mut(&mut block);
            let mut out = Vec::new();
            for stmt in &block.stmts {
                emit(stmt.to_token_stream(), &bound, &mut out);
            }
            out
        }
        // Without the braces, on the same lines.
        Err(_) => match format!("\n{body}\n").parse::<TokenStream>() {
            Ok(stream) => {
                let mut out = Vec::new();
                emit(stream, &HashSet::new(), &mut out);
                out
            }
            Err(_) => Vec::new(),
        },
    }
}

/// Every name a pattern or a nested `fn` binds anywhere in `block`. A capitalised name in a
/// pattern (`None`, `EPSILON`) is a variant or a constant, which `syn` cannot tell from a binding:
/// bindings are lower case, so those stay.
pub(super) fn bound_names(block: &syn::Block) -> HashSet<String> {
    struct Binder(HashSet<String>);
    impl Visit<'_> for Binder {
        fn visit_pat_ident(&mut self, p: &syn::PatIdent) {
            let name = p.ident.to_string();
            if !name.starts_with(|c: char| c.is_ascii_uppercase()) {
                self.0.insert(name);
            }
            syn::visit::visit_pat_ident(self, p);
        }
        fn visit_item_fn(&mut self, f: &syn::ItemFn) {
            self.0.insert(f.sig.ident.to_string());
            syn::visit::visit_item_fn(self, f);
        }
    }
    let mut binder = Binder(HashSet::new());
    binder.visit_block(block);
    binder.0
}

/// Drops dead `let`s and orders runs of `let`s in every block, innermost first.
struct Canonical<'a> {
    bound: &'a HashSet<String>,
}

impl VisitMut for Canonical<'_> {
    fn visit_block_mut(&mut self, block: &mut syn::Block) {
        syn::visit_mut::visit_block_mut(self, block);
        drop_dead_lets(&mut block.stmts);
        order_lets(&mut block.stmts, self.bound);
    }

    /// A binding's `mut` and a pattern's type annotation (`let mut x: f32`) say nothing a
    /// copier could not add or drop: both go.
    fn visit_pat_mut(&mut self, pat: &mut syn::Pat) {
        if let syn::Pat::Type(typed) = pat {
            *pat = (*typed.pat).clone();
        }
        if let syn::Pat::Ident(ident) = pat {
            ident.mutability = None;
        }
        syn::visit_mut::visit_pat_mut(self, pat);
    }
}

/// The names a `let` binds (none for any other statement).
pub(super) fn binds(stmt: &syn::Stmt) -> BTreeSet<String> {
    struct Names(BTreeSet<String>);
    impl Visit<'_> for Names {
        fn visit_pat_ident(&mut self, p: &syn::PatIdent) {
            self.0.insert(p.ident.to_string());
            syn::visit::visit_pat_ident(self, p);
        }
    }
    let mut names = Names(BTreeSet::new());
    if let syn::Stmt::Local(local) = stmt {
        names.visit_pat(&local.pat);
    }
    names.0
}

/// Every identifier written in `stmt` but those after a `.` (fields and methods, which no binding
/// can be): a superset of the names it uses.
pub(super) fn mentions(stmt: &syn::Stmt) -> HashSet<String> {
    fn walk(stream: TokenStream, out: &mut HashSet<String>) {
        let mut dots = Dots::default();
        for tree in stream {
            match &tree {
                TokenTree::Ident(i) if !dots.after_member() => {
                    out.insert(i.to_string());
                }
                TokenTree::Group(g) => walk(g.stream(), out),
                _ => {}
            }
            dots.see(matches!(&tree, TokenTree::Punct(p) if p.as_char() == '.'));
        }
    }
    let mut out = HashSet::new();
    walk(stmt.to_token_stream(), &mut out);
    out
}

/// Removes every `let` none of whose names a later statement that stays mentions: one pass from
/// the end, a dead `let`'s own mentions not counted, so a chain of dead `let`s goes at once.
fn drop_dead_lets(stmts: &mut Vec<syn::Stmt>) {
    let mut later: HashSet<String> = HashSet::new();
    let mut dead = vec![false; stmts.len()];
    for (i, stmt) in stmts.iter().enumerate().rev() {
        if matches!(stmt, syn::Stmt::Local(_)) && binds(stmt).iter().all(|name| !later.contains(name)) {
            dead[i] = true;
        } else {
            later.extend(mentions(stmt));
        }
    }
    let mut i = 0;
    stmts.retain(|_| {
        i += 1;
        !dead[i - 1]
    });
}

/// Puts each run of consecutive `let`s in one order that keeps every name defined before it is
/// used (and never moves a `let` past another binding the same name): by level (a `let` is one
/// level above the deepest it must follow), then by normalised text. Levels and texts do not
/// depend on which valid order the run was written in, so neither does the result.
fn order_lets(stmts: &mut [syn::Stmt], bound: &HashSet<String>) {
    let mut start = 0;
    while start < stmts.len() {
        let end =
            (start..stmts.len()).find(|&i| !matches!(stmts[i], syn::Stmt::Local(_))).unwrap_or(stmts.len());
        if end - start > 1 {
            let run: Vec<syn::Stmt> = stmts[start..end].to_vec();
            let order = canonical_order(&run, bound);
            for (slot, i) in order.into_iter().enumerate() {
                stmts[start + slot] = run[i].clone();
            }
        }
        start = end + 1;
    }
}

/// The order of `run` (indices): by level, then by normalised text.
fn canonical_order(run: &[syn::Stmt], bound: &HashSet<String>) -> Vec<usize> {
    let names: Vec<BTreeSet<String>> = run.iter().map(binds).collect();
    let used: Vec<HashSet<String>> = run.iter().map(mentions).collect();
    // j must stay after i (i < j) when one mentions what the other binds.
    let after = |i: usize, j: usize| {
        names[i].iter().any(|n| used[j].contains(n)) || names[j].iter().any(|n| used[i].contains(n))
    };
    let mut level = vec![0usize; run.len()];
    for j in 0..run.len() {
        level[j] = (0..j).filter(|&i| after(i, j)).map(|i| level[i] + 1).max().unwrap_or(0);
    }
    let key: Vec<String> = run
        .iter()
        .map(|s| {
            let mut tokens = Vec::new();
            emit(s.to_token_stream(), bound, &mut tokens);
            tokens.into_iter().map(|t| t.text).collect::<Vec<_>>().join(" ")
        })
        .collect();
    let mut order: Vec<usize> = (0..run.len()).collect();
    order.sort_by(|&a, &b| level[a].cmp(&level[b]).then_with(|| key[a].cmp(&key[b])).then(a.cmp(&b)));
    order
}

/// Appends the normalised tokens of `stream` to `out`.
fn emit(stream: TokenStream, bound: &HashSet<String>, out: &mut Vec<Token>) {
    let mut dots = Dots::default();
    for tree in stream {
        let line = tree.span().start().line.saturating_sub(1).max(1);
        let text = match &tree {
            TokenTree::Group(g) => {
                let (open, close) = match g.delimiter() {
                    Delimiter::Parenthesis => ("(", ")"),
                    Delimiter::Brace => ("{", "}"),
                    Delimiter::Bracket => ("[", "]"),
                    Delimiter::None => ("", ""),
                };
                if !open.is_empty() {
                    out.push(Token { text: open.to_string(), line });
                }
                emit(g.stream(), bound, out);
                if !close.is_empty() {
                    let line = g.span_close().start().line.saturating_sub(1).max(1);
                    out.push(Token { text: close.to_string(), line });
                }
                dots.see(false);
                continue;
            }
            TokenTree::Ident(i) => {
                let name = i.to_string();
                if !dots.after_member() && bound.contains(&name) {
                    "$v".to_string()
                } else {
                    name
                }
            }
            TokenTree::Punct(p) => p.as_char().to_string(),
            TokenTree::Literal(l) => literal(&l.to_string()),
        };
        dots.see(text == ".");
        out.push(Token { text, line });
    }
}

/// Whether a token follows a member's `.` (`a.b`: a field or a method, never a binding), not a
/// range's `..`: the count of dots just seen.
#[derive(Default)]
pub(super) struct Dots(u8);

impl Dots {
    /// Whether the last token was a lone `.`.
    pub(super) fn after_member(&self) -> bool {
        self.0 == 1
    }

    /// Counts one more token, a dot or not.
    pub(super) fn see(&mut self, dot: bool) {
        self.0 = if dot { self.0.saturating_add(1) } else { 0 };
    }
}

/// A literal as its value: numbers by value whatever their spelling (decimal, exponent, hex,
/// octal, binary, suffix, underscores), strings and chars as `$s`.
fn literal(text: &str) -> String {
    if !text.starts_with(|c: char| c.is_ascii_digit()) {
        return "$s".to_string();
    }
    let digits: String = text.chars().filter(|&c| c != '_').collect();
    let radix =
        [("0x", 16), ("0o", 8), ("0b", 2)].iter().find_map(|(p, r)| digits.strip_prefix(p).map(|n| (n, *r)));
    let value = match radix {
        // `f32` is hex digits (`0x2f32` is one number): only integer suffixes end a hex literal.
        Some((number, radix)) => {
            let number = number.find(['u', 'i']).map_or(number, |at| &number[..at]);
            u64::from_str_radix(number, radix).ok().map(|v| v as f64)
        }
        None => {
            let number = digits
                .find(|c: char| c.is_ascii_alphabetic() && !matches!(c, 'e' | 'E'))
                .map_or(&*digits, |at| &digits[..at]);
            number.parse::<f64>().ok()
        }
    };
    value.map_or(digits, |v| format!("{v}"))
}

#[cfg(test)]
mod tests;
