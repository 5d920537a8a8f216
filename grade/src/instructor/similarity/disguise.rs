//! The disguises a student puts on copied code, applied to a region body: the engine's test set is
//! every independent implementation disguised by each of them alone and in combinations.
//!
//! Each works on the text as a person would edit it, not on the engine's normalised tokens:
//! renaming the names bound in the region, respelling numbers (`1.0` as `1e0`, `2` as `0x2`),
//! re-laying out the code, replacing the comments, reordering independent `let`s (a random order
//! that keeps every name defined before its use) and adding `let`s nothing uses. Code `syn`
//! cannot read is left as it is by the two that need its structure.

use std::collections::HashSet;
use std::ops::Range;

use proc_macro2::TokenTree;
use quote::ToTokens;
use raylab_base::rng::Rng;

use crate::instructor::similarity::normalise::{binds, bound_names, mentions, Dots};
use crate::regions::lexer::{tokens, Kind};

/// One disguise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Disguise {
    /// Every name bound in the region renamed.
    Rename,
    /// Every number spelled another way.
    Literals,
    /// Another layout: one token after another, a line break after `;`, `{` and `}`.
    Layout,
    /// The comments removed, others added.
    Comments,
    /// Runs of independent `let`s in another order.
    Reorder,
    /// `let`s that nothing uses, added between statements.
    DeadCode,
}

impl Disguise {
    /// Every disguise, alone.
    pub const ALL: [Disguise; 6] = [
        Disguise::Rename,
        Disguise::Literals,
        Disguise::Layout,
        Disguise::Comments,
        Disguise::Reorder,
        Disguise::DeadCode,
    ];

    /// The three combinations measured: the surface (what a find-and-replace and a formatter
    /// do), the structure (names, order, padding), and everything.
    pub const COMBINATIONS: [&'static [Disguise]; 3] = [
        &[Disguise::Rename, Disguise::Literals, Disguise::Layout, Disguise::Comments],
        &[Disguise::Rename, Disguise::Reorder, Disguise::DeadCode],
        &Disguise::ALL,
    ];

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Disguise::Rename => "rename",
            Disguise::Literals => "literals",
            Disguise::Layout => "layout",
            Disguise::Comments => "comments",
            Disguise::Reorder => "reorder",
            Disguise::DeadCode => "dead code",
        }
    }
}

/// `body` with `disguises` applied (the structural ones first), drawn from `seed`.
pub fn disguise(body: &str, disguises: &[Disguise], seed: u64) -> String {
    let mut rng = Rng::new(seed, 0x5eed);
    let mut text = body.to_string();
    for step in [
        Disguise::Reorder,
        Disguise::DeadCode,
        Disguise::Rename,
        Disguise::Literals,
        Disguise::Comments,
        Disguise::Layout,
    ] {
        if disguises.contains(&step) {
            text = match step {
                Disguise::Reorder => reorder(&text, &mut rng),
                Disguise::DeadCode => dead_code(&text, &mut rng),
                Disguise::Rename => rename(&text),
                Disguise::Literals => respell(&text),
                Disguise::Comments => recomment(&text),
                Disguise::Layout => relayout(&text),
            };
        }
    }
    text
}

/// The top-level statements of `body`, each as its byte range in `body`; `None` if `syn` cannot
/// read it.
fn statements(body: &str) -> Option<(syn::Block, Vec<Range<usize>>)> {
    let block: syn::Block = syn::parse_str(&format!("{{\n{body}\n}}")).ok()?;
    let ranges = block
        .stmts
        .iter()
        .map(|s| {
            let trees: Vec<TokenTree> = s.to_token_stream().into_iter().collect();
            let start = trees.first().map_or(0, |t| t.span().byte_range().start);
            let end = trees.last().map_or(0, |t| t.span().byte_range().end);
            // Less the `{\n` the body was wrapped in.
            start.saturating_sub(2)..end.saturating_sub(2)
        })
        .collect();
    Some((block, ranges))
}

/// Runs of consecutive top-level `let`s put in a random order that keeps each name defined
/// before it is used.
fn reorder(body: &str, rng: &mut Rng) -> String {
    let Some((block, ranges)) = statements(body) else { return body.to_string() };
    let is_let: Vec<bool> = block.stmts.iter().map(|s| matches!(s, syn::Stmt::Local(_))).collect();
    let mut order: Vec<usize> = (0..ranges.len()).collect();
    let mut start = 0;
    while start < ranges.len() {
        let end = (start..ranges.len()).find(|&i| !is_let[i]).unwrap_or(ranges.len());
        let run: Vec<usize> = (start..end).collect();
        let mut placed: Vec<usize> = Vec::new();
        while placed.len() < run.len() {
            let ready: Vec<usize> = run
                .iter()
                .copied()
                .filter(|&j| !placed.contains(&j))
                .filter(|&j| {
                    (start..j).all(|i| placed.contains(&i) || independent(&block.stmts[i], &block.stmts[j]))
                })
                .collect();
            placed.push(ready[rng.next_u32() as usize % ready.len()]);
        }
        order[start..end].copy_from_slice(&placed);
        start = end + 1;
    }
    let mut out = body.to_string();
    // Replace from the last statement back, so earlier ranges stay valid.
    for slot in (0..ranges.len()).rev() {
        out.replace_range(ranges[slot].clone(), &body[ranges[order[slot]].clone()]);
    }
    out
}

/// Whether neither statement mentions a name the other binds.
fn independent(a: &syn::Stmt, b: &syn::Stmt) -> bool {
    let (ba, bb, ma, mb) = (binds(a), binds(b), mentions(a), mentions(b));
    ba.iter().all(|n| !mb.contains(n)) && bb.iter().all(|n| !ma.contains(n))
}

/// Two unused `let`s inserted after random top-level statements (not after the last, which may
/// be the block's value).
fn dead_code(body: &str, rng: &mut Rng) -> String {
    let Some((_, ranges)) = statements(body) else { return body.to_string() };
    if ranges.len() < 2 {
        return body.to_string();
    }
    let mut cuts: Vec<usize> =
        (0..2).map(|_| ranges[rng.next_u32() as usize % (ranges.len() - 1)].end).collect();
    cuts.sort_unstable();
    let mut out = body.to_string();
    for (k, at) in cuts.into_iter().enumerate().rev() {
        let value = 1 + rng.next_u32() % 9;
        out.insert_str(at, &format!("\n    let unused_{k} = {value}.5 * 2.0;"));
    }
    out
}

/// Every name bound in the region renamed `renamed_N`, fields and methods (after a `.`) left.
fn rename(body: &str) -> String {
    let Ok(block) = syn::parse_str::<syn::Block>(&format!("{{\n{body}\n}}")) else { return body.to_string() };
    let bound: HashSet<String> = bound_names(&block);
    let mut names: Vec<&String> = bound.iter().collect();
    names.sort();
    edit_tokens(body, |kind, text, after_member| match kind {
        Kind::Ident if !after_member => names.iter().position(|n| *n == text).map(|i| format!("renamed_{i}")),
        _ => None,
    })
}

/// Numbers spelled another way: a float with an exponent as a decimal and the others with one,
/// an integer in hexadecimal.
fn respell(body: &str) -> String {
    edit_tokens(body, |kind, text, _| {
        if kind != Kind::Literal || !text.starts_with(|c: char| c.is_ascii_digit()) || text.starts_with("0x")
        {
            return None;
        }
        let digits: String = text.chars().filter(|&c| c != '_').collect();
        let (number, suffix) = match digits.find(|c: char| c.is_ascii_alphabetic() && c != 'e') {
            Some(at) => digits.split_at(at),
            None => (digits.as_str(), ""),
        };
        if number.contains(['.', 'e']) || suffix.starts_with('f') {
            let value: f64 = number.parse().ok()?;
            let spelled = match format!("{value}") {
                decimal if number.contains('e') && decimal.contains('.') => decimal,
                decimal if number.contains('e') => format!("{decimal}.0"),
                _ => format!("{value:e}"),
            };
            Some(format!("{spelled}{suffix}"))
        } else {
            let value: u64 = number.parse().ok()?;
            Some(format!("{value:#x}{suffix}"))
        }
    })
}

/// The comments removed, and a comment of its own before every third line.
fn recomment(body: &str) -> String {
    let without = edit_tokens(body, |kind, _, _| {
        matches!(kind, Kind::LineComment | Kind::BlockComment).then(String::new)
    });
    let mut out = String::new();
    for (i, line) in without.lines().enumerate() {
        if i % 3 == 1 {
            out.push_str(&format!("    // step {i}\n"));
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// One token after another with single spaces, a line break after `;`, `{`, `}` and comments;
/// punctuation written together stays together (`::`, `..=`, `->`).
fn relayout(body: &str) -> String {
    let Ok(tokens) = tokens(body) else { return body.to_string() };
    let mut out = String::new();
    for (i, token) in tokens.iter().enumerate() {
        out.push_str(&body[token.range.clone()]);
        let joined = tokens.get(i + 1).is_some_and(|next| {
            matches!((token.kind, next.kind), (Kind::Punct(_), Kind::Punct(_)))
                && next.range.start == token.range.end
        });
        let breaks =
            matches!(token.kind, Kind::LineComment | Kind::Open('{') | Kind::Close('}') | Kind::Punct(';'));
        if breaks {
            out.push('\n');
        } else if !joined {
            out.push(' ');
        }
    }
    out
}

/// `body` with each token `edit(kind, text, whether it follows a member's dot)` returns replaced.
fn edit_tokens(body: &str, mut edit: impl FnMut(Kind, &str, bool) -> Option<String>) -> String {
    let Ok(tokens) = tokens(body) else { return body.to_string() };
    let mut out = String::new();
    let mut at = 0;
    let mut dots = Dots::default();
    for token in &tokens {
        let text = &body[token.range.clone()];
        out.push_str(&body[at..token.range.start]);
        out.push_str(&edit(token.kind, text, dots.after_member()).unwrap_or_else(|| text.to_string()));
        at = token.range.end;
        if !matches!(token.kind, Kind::LineComment | Kind::BlockComment) {
            dots.see(token.kind == Kind::Punct('.'));
        }
    }
    out.push_str(&body[at..]);
    out
}

#[cfg(test)]
mod tests;
