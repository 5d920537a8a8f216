//! Which syntax the region checker looks at: every path, `use`, macro, attribute and literal it
//! checks, and each form of `unsafe` and `extern` it refuses on sight; every other node is only
//! walked through.

use proc_macro2::Span;
use syn::visit::Visit;

use super::{Checker, Refusal};

impl<'ast> Visit<'ast> for Checker<'_> {
    fn visit_path(&mut self, path: &'ast syn::Path) {
        self.check_path(path);
        syn::visit::visit_path(self, path);
    }

    fn visit_expr_path(&mut self, e: &'ast syn::ExprPath) {
        if let Some(qself) = &e.qself {
            self.check_qualified(qself, &e.path);
        }
        syn::visit::visit_expr_path(self, e);
    }

    fn visit_type_path(&mut self, t: &'ast syn::TypePath) {
        if let Some(qself) = &t.qself {
            self.check_qualified(qself, &t.path);
        }
        syn::visit::visit_type_path(self, t);
    }

    fn visit_item_use(&mut self, item: &'ast syn::ItemUse) {
        self.check_use(&mut Vec::new(), &item.tree);
        item.attrs.iter().for_each(|a| self.visit_attribute(a));
    }

    fn visit_macro(&mut self, mac: &'ast syn::Macro) {
        self.check_macro(mac);
    }

    fn visit_attribute(&mut self, attribute: &'ast syn::Attribute) {
        self.check_attribute(attribute);
    }

    fn visit_lit(&mut self, lit: &'ast syn::Lit) {
        match lit {
            syn::Lit::Int(_) | syn::Lit::Float(_) => self.numbers += 1,
            syn::Lit::Str(s) => self.text += s.value().len(),
            syn::Lit::ByteStr(s) => self.text += s.value().len(),
            syn::Lit::CStr(s) => self.text += s.value().as_bytes().len(),
            syn::Lit::Char(c) => self.text += c.value().len_utf8(),
            syn::Lit::Byte(_) => self.text += 1,
            syn::Lit::Bool(_) => {}
            other => self.reject(other.span(), Refusal::UnreadableLiteral),
        }
    }

    fn visit_expr_unsafe(&mut self, e: &'ast syn::ExprUnsafe) {
        self.reject(e.unsafe_token.span, Refusal::Unsafe);
    }

    fn visit_signature(&mut self, sig: &'ast syn::Signature) {
        if let Some(token) = &sig.unsafety {
            self.reject(token.span, Refusal::UnsafeFn);
        }
        if let Some(abi) = &sig.abi {
            self.reject(abi.extern_token.span, Refusal::ExternFn);
        }
        syn::visit::visit_signature(self, sig);
    }

    fn visit_item_impl(&mut self, item: &'ast syn::ItemImpl) {
        if let Some(token) = &item.unsafety {
            self.reject(token.span, Refusal::UnsafeImpl);
        }
        syn::visit::visit_item_impl(self, item);
    }

    fn visit_type_bare_fn(&mut self, t: &'ast syn::TypeBareFn) {
        if let Some(token) = &t.unsafety {
            self.reject(token.span, Refusal::UnsafeFnType);
        }
        syn::visit::visit_type_bare_fn(self, t);
    }

    fn visit_item(&mut self, item: &'ast syn::Item) {
        match self.check_item(item) {
            Ok(()) => syn::visit::visit_item(self, item),
            Err((span, reason)) => self.reject(span, reason),
        }
    }

    fn visit_expr(&mut self, e: &'ast syn::Expr) {
        match e {
            syn::Expr::Verbatim(tokens) => {
                let span = tokens.clone().into_iter().next().map_or_else(Span::call_site, |t| t.span());
                self.reject(span, Refusal::Unreadable);
            }
            _ => syn::visit::visit_expr(self, e),
        }
    }
}
