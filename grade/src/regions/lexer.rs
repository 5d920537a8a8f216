//! A small lexer for Rust source: enough to know what is code, what is a comment and what is
//! inside a string, so that solution markers are found only where they are real line comments,
//! and a region's nesting can be measured before a parser that recurses is given it.
//!
//! It splits text into tokens: comments (line and nested block), literals (strings, raw strings,
//! byte and C strings, chars, bytes, numbers), identifiers (raw ones included), lifetimes,
//! brackets and single punctuation characters. It does not check that a literal is well formed,
//! only where it ends; text it cannot split (an unterminated string or block comment) is an
//! error with its byte offset. It reads each byte once, so a hostile file costs linear time.

use std::ops::Range;

/// What a token is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `// ...` up to (not including) the end of the line.
    LineComment,
    /// `/* ... */`, nested ones included.
    BlockComment,
    /// A string, char, byte or number literal, with its prefix and suffix.
    Literal,
    /// An identifier or keyword, `r#raw` ones included.
    Ident,
    /// `'a`: a lifetime or a loop label.
    Lifetime,
    /// `(`, `[` or `{`.
    Open(char),
    /// `)`, `]` or `}`.
    Close(char),
    /// Any other character that is not white space.
    Punct(char),
}

/// One token: its kind and its bytes in the text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    /// What it is.
    pub kind: Kind,
    /// Where it is.
    pub range: Range<usize>,
}

/// Text the lexer cannot split.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LexError {
    /// Where the token that does not end starts.
    pub byte: usize,
    /// What does not end ("string", "block comment", ...).
    pub what: &'static str,
}

impl std::fmt::Display for LexError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a {} that never ends", self.what)
    }
}

/// The tokens of `text`, comments included, white space left out.
pub fn tokens(text: &str) -> Result<Vec<Token>, LexError> {
    let mut lexer = Lexer { bytes: text.as_bytes(), text, at: 0 };
    let mut out = Vec::new();
    while let Some(token) = lexer.next_token()? {
        out.push(token);
    }
    Ok(out)
}

/// The deepest nesting of brackets in `tokens`, and whether every bracket closes the one it
/// should.
pub fn nesting(tokens: &[Token]) -> (usize, bool) {
    let (mut stack, mut deepest) = (Vec::new(), 0);
    for token in tokens {
        match token.kind {
            Kind::Open(c) => {
                stack.push(c);
                deepest = deepest.max(stack.len());
            }
            Kind::Close(c) if stack.pop() != Some(opening(c)) => return (deepest, false),
            _ => {}
        }
    }
    (deepest, stack.is_empty())
}

/// The bracket that `close` closes.
pub fn opening(close: char) -> char {
    match close {
        ')' => '(',
        ']' => '[',
        _ => '{',
    }
}

/// The 1-based line of byte `byte` of `text`.
pub fn line_at(text: &str, byte: usize) -> usize {
    text.as_bytes()[..byte.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

struct Lexer<'a> {
    text: &'a str,
    bytes: &'a [u8],
    at: usize,
}

impl Lexer<'_> {
    fn peek(&self, ahead: usize) -> Option<u8> {
        self.bytes.get(self.at + ahead).copied()
    }

    fn next_token(&mut self) -> Result<Option<Token>, LexError> {
        while self.peek(0).is_some_and(|b| b.is_ascii_whitespace()) {
            self.at += 1;
        }
        let start = self.at;
        let Some(first) = self.text[start..].chars().next() else { return Ok(None) };
        let kind = match first {
            '/' if self.peek(1) == Some(b'/') => {
                self.at = self.text[start..].find('\n').map_or(self.text.len(), |i| start + i);
                Kind::LineComment
            }
            '/' if self.peek(1) == Some(b'*') => self.block_comment()?,
            '"' => self.string(start, None)?,
            '\'' => self.quote(start)?,
            '0'..='9' => self.number(),
            c if c == '_' || c.is_alphabetic() => self.word(start)?,
            '(' | '[' | '{' => self.single(first, Kind::Open(first)),
            ')' | ']' | '}' => self.single(first, Kind::Close(first)),
            c => self.single(c, Kind::Punct(c)),
        };
        Ok(Some(Token { kind, range: start..self.at }))
    }

    fn single(&mut self, c: char, kind: Kind) -> Kind {
        self.at += c.len_utf8();
        kind
    }

    fn block_comment(&mut self) -> Result<Kind, LexError> {
        let start = self.at;
        let mut depth = 0usize;
        while self.at < self.bytes.len() {
            match (self.bytes[self.at], self.peek(1)) {
                (b'/', Some(b'*')) => (depth, self.at) = (depth + 1, self.at + 2),
                (b'*', Some(b'/')) => {
                    (depth, self.at) = (depth - 1, self.at + 2);
                    if depth == 0 {
                        return Ok(Kind::BlockComment);
                    }
                }
                _ => self.at += 1,
            }
        }
        Err(LexError { byte: start, what: "block comment" })
    }

    /// A string whose opening quote is at `self.at`, the token starting at `start`; `raw` holds
    /// the number of `#`s of a raw string, `None` for a string with escapes.
    fn string(&mut self, start: usize, raw: Option<usize>) -> Result<Kind, LexError> {
        self.at += 1;
        let closing: Vec<u8> =
            std::iter::once(b'"').chain(std::iter::repeat_n(b'#', raw.unwrap_or(0))).collect();
        while self.at < self.bytes.len() {
            if raw.is_none() && self.bytes[self.at] == b'\\' {
                self.at += 2;
            } else if self.bytes[self.at..].starts_with(&closing) {
                self.at += closing.len();
                self.suffix();
                return Ok(Kind::Literal);
            } else {
                self.at += 1;
            }
        }
        Err(LexError { byte: start, what: "string" })
    }

    /// A char literal (`'a'`, `'\n'`, `b'x'`) or a lifetime (`'a`), at the quote.
    fn quote(&mut self, start: usize) -> Result<Kind, LexError> {
        self.at += 1;
        let Some(c) = self.text[self.at..].chars().next() else {
            return Err(LexError { byte: start, what: "character literal" });
        };
        if c == '\\' {
            // The escaped character (which may be a quote) is never the closing one.
            let never_ends = LexError { byte: start, what: "character literal" };
            let escaped = self.text[self.at + 1..].chars().next().ok_or(never_ends.clone())?;
            let from = self.at + 1 + escaped.len_utf8();
            self.at = from + self.text[from..].find('\'').ok_or(never_ends)? + 1;
            self.suffix();
            return Ok(Kind::Literal);
        }
        if self.text[self.at + c.len_utf8()..].starts_with('\'') {
            self.at += c.len_utf8() + 1;
            self.suffix();
            return Ok(Kind::Literal);
        }
        self.identifier_chars();
        Ok(Kind::Lifetime)
    }

    fn number(&mut self) -> Kind {
        let hex = self.text[self.at..].starts_with("0x");
        while let Some(b) = self.peek(0) {
            let fraction = b == b'.' && self.peek(1).is_some_and(|d| d.is_ascii_digit());
            let signed_exponent = !hex
                && matches!(b, b'e' | b'E')
                && matches!(self.peek(1), Some(b'+' | b'-'))
                && self.peek(2).is_some_and(|d| d.is_ascii_digit());
            if signed_exponent {
                self.at += 2;
            } else if b.is_ascii_alphanumeric() || b == b'_' || fraction {
                self.at += 1;
            } else {
                break;
            }
        }
        Kind::Literal
    }

    /// An identifier, or a literal with a prefix (`b"`, `br#"`, `c"`, `b'`), or `r#ident`.
    fn word(&mut self, start: usize) -> Result<Kind, LexError> {
        let prefix = |p: &str| self.text[start..].starts_with(p);
        if prefix("r#") && self.text[start + 2..].starts_with(|c: char| c == '_' || c.is_alphabetic()) {
            self.at += 2;
            self.identifier_chars();
            return Ok(Kind::Ident);
        }
        for raw in ["r", "br", "cr"].into_iter().filter(|raw| prefix(raw)) {
            let after = &self.text[start + raw.len()..];
            let hashes = after.bytes().take_while(|&b| b == b'#').count();
            if after[hashes..].starts_with('"') {
                self.at = start + raw.len() + hashes;
                return self.string(start, Some(hashes));
            }
        }
        if prefix("b\"") || prefix("c\"") {
            self.at += 1;
            return self.string(start, None);
        }
        if prefix("b'") {
            self.at += 1;
            return self.quote(start);
        }
        self.identifier_chars();
        Ok(Kind::Ident)
    }

    fn identifier_chars(&mut self) {
        let rest = &self.text[self.at..];
        self.at += rest.find(|c: char| !(c == '_' || c.is_alphanumeric())).unwrap_or(rest.len());
    }

    /// A literal's suffix (`1.0f32`, `"a"suffix`).
    fn suffix(&mut self) {
        if self.text[self.at..].starts_with(|c: char| c == '_' || c.is_alphabetic()) {
            self.identifier_chars();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<(Kind, &str)> {
        tokens(text).unwrap().into_iter().map(|t| (t.kind, &text[t.range])).collect()
    }

    #[test]
    fn grader_lexer_tells_comments_and_strings_from_code() {
        let text = "let s = \"// not a comment\"; // a comment\n/* a /* nested */ one */ x";
        assert_eq!(
            kinds(text),
            [
                (Kind::Ident, "let"),
                (Kind::Ident, "s"),
                (Kind::Punct('='), "="),
                (Kind::Literal, "\"// not a comment\""),
                (Kind::Punct(';'), ";"),
                (Kind::LineComment, "// a comment"),
                (Kind::BlockComment, "/* a /* nested */ one */"),
                (Kind::Ident, "x"),
            ]
        );
    }

    #[test]
    fn grader_lexer_reads_every_literal_to_its_end() {
        for literal in [
            r#""a \" quote and a \\""#,
            r###"r#"a "raw" string"#"###,
            r#"br"bytes""#,
            r#"b"\x00""#,
            r#"c"text""#,
            "'a'",
            "'\\''",
            "'\\\\'",
            "'\\u{1F600}'",
            "'é'",
            "b'x'",
            "1.5e-3f32",
            "0xff_u8",
            "\"multi\nline\"",
        ] {
            let text = format!("{literal} }}");
            assert_eq!(kinds(&text), [(Kind::Literal, literal), (Kind::Close('}'), "}")], "{literal}");
        }
    }

    #[test]
    fn grader_lexer_tells_lifetimes_raw_identifiers_and_ranges_apart() {
        assert_eq!(
            kinds("'outer: for i in 0..n { r#std }"),
            [
                (Kind::Lifetime, "'outer"),
                (Kind::Punct(':'), ":"),
                (Kind::Ident, "for"),
                (Kind::Ident, "i"),
                (Kind::Ident, "in"),
                (Kind::Literal, "0"),
                (Kind::Punct('.'), "."),
                (Kind::Punct('.'), "."),
                (Kind::Ident, "n"),
                (Kind::Open('{'), "{"),
                (Kind::Ident, "r#std"),
                (Kind::Close('}'), "}"),
            ]
        );
    }

    #[test]
    fn grader_lexer_names_what_never_ends() {
        assert_eq!(tokens("x /* open").unwrap_err(), LexError { byte: 2, what: "block comment" });
        assert_eq!(tokens("let s = \"open").unwrap_err(), LexError { byte: 8, what: "string" });
        assert_eq!(tokens("r##\"open\"#").unwrap_err(), LexError { byte: 0, what: "string" });
    }

    #[test]
    fn grader_lexer_measures_nesting() {
        assert_eq!(nesting(&tokens("f(a[1], { b })").unwrap()), (2, true));
        assert_eq!(nesting(&tokens("f(a]").unwrap()), (1, false));
        assert_eq!(nesting(&tokens("((").unwrap()), (2, false));
        let deep = format!("{}{}", "(".repeat(5000), ")".repeat(5000));
        assert_eq!(nesting(&tokens(&deep).unwrap()), (5000, true));
    }
}
