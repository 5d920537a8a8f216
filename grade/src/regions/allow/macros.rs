//! What an allowed macro call's arguments are, parsed, so the checker can check them as code:
//! comma-separated expressions, `vec![x; n]`, and `matches!(expr, pattern if guard)`.

use proc_macro2::TokenStream;
use syn::parse::Parser;
use syn::punctuated::Punctuated;

/// What a macro call's tokens hold, once parsed.
pub(super) enum MacroArgument {
    /// An expression.
    Expr(syn::Expr),
    /// A pattern (`matches!`'s second argument).
    Pat(syn::Pat),
}

/// Parses the arguments of an allowed macro: comma-separated expressions; `vec![x; n]`;
/// `matches!(expr, pattern if guard)`. `None` if they do not parse that way.
pub(super) fn parse_macro_arguments(name: &str, tokens: TokenStream) -> Option<Vec<MacroArgument>> {
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
