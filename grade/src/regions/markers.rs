//! Solution regions found by their markers, read as Rust tokens rather than searched for as text.
//!
//! A region is the whole body of one function, between two line comments each alone on its
//! line: `// BEGIN SOLUTION checkpointN` and `// END SOLUTION`. Found with [`super::lexer`], a
//! marker inside a string, a block comment or a doc comment is no marker; one that is not at the
//! top level of a function body (inside a nested block, between items) marks nothing; an END
//! counts only in the same block as its BEGIN, with every bracket between them closed. Line
//! endings may be `\n` or `\r\n`.

use std::ops::Range;
use std::path::PathBuf;

use crate::regions::lexer::{tokens, Kind, LexError, Token};

/// One solution region of the instructor's tree, as the grader names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// The file, relative to the tree.
    pub file: PathBuf,
    /// Its checkpoint.
    pub checkpoint: u32,
    /// The function whose body it is.
    pub function: String,
}

/// One region of a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Found {
    /// Its checkpoint.
    pub checkpoint: u32,
    /// The function whose body it is.
    pub function: String,
    /// Its body: from the line after the BEGIN marker to the start of the END marker's line.
    pub body: Range<usize>,
}

const BEGIN: &str = "// BEGIN SOLUTION checkpoint";
const END: &str = "// END SOLUTION";

/// The checkpoints with regions in `text`, each once, in order: the markers say which
/// checkpoints a file has, not a list kept beside them.
pub fn checkpoints_in(text: &str) -> Vec<u32> {
    let mut ids: Vec<u32> = find_regions(text).unwrap_or_default().iter().map(|f| f.checkpoint).collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// Every region of `text`, in order.
pub fn find_regions(text: &str) -> Result<Vec<Found>, LexError> {
    let tokens = tokens(text)?;
    // One entry per open bracket: the bracket, and the name of the function whose body it opens.
    let mut open: Vec<(char, Option<String>)> = Vec::new();
    // Per bracket level (and the top one), the first token of the item or statement now read.
    let mut item_start = vec![0];
    // A BEGIN marker waiting for its END: checkpoint, bracket depth, function, body start.
    let mut pending: Option<(u32, usize, String, usize)> = None;
    let mut found = Vec::new();
    for (i, token) in tokens.iter().enumerate() {
        match token.kind {
            Kind::Open(c) => {
                let function =
                    (c == '{').then(|| function_name(text, &tokens[item_start[open.len()]..i])).flatten();
                open.push((c, function));
                item_start.push(i + 1);
            }
            Kind::Close(c) => {
                if pending.as_ref().is_some_and(|p| p.1 == open.len()) {
                    pending = None; // the block ends before its END marker
                }
                open.pop();
                item_start.pop();
                // A block ends an item or a statement; a `)` or `]` ends neither.
                match item_start.last_mut() {
                    Some(start) if c == '}' => *start = i + 1,
                    _ => {}
                }
            }
            Kind::Punct(';') => {
                if let Some(start) = item_start.last_mut() {
                    *start = i + 1;
                }
            }
            Kind::LineComment if alone_on_its_line(text, token) => {
                let comment = text[token.range.clone()].trim_end();
                let in_function = open.last().and_then(|(_, f)| f.clone());
                if let Some(checkpoint) = comment.strip_prefix(BEGIN).and_then(|n| n.parse().ok()) {
                    pending =
                        in_function.map(|f| (checkpoint, open.len(), f, line_end(text, token.range.end)));
                } else if comment == END {
                    if let Some((checkpoint, depth, function, start)) = pending.take() {
                        if depth == open.len() {
                            let end = text[..token.range.start].rfind('\n').map_or(0, |n| n + 1).max(start);
                            found.push(Found { checkpoint, function, body: start..end });
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(found)
}

/// The name after the first `fn` followed by a name in an item's tokens before its `{`.
fn function_name(text: &str, item: &[Token]) -> Option<String> {
    item.windows(2).find_map(|pair| {
        let [keyword, name] = pair else { return None };
        (keyword.kind == Kind::Ident && &text[keyword.range.clone()] == "fn" && name.kind == Kind::Ident)
            .then(|| text[name.range.clone()].to_string())
    })
}

fn alone_on_its_line(text: &str, token: &Token) -> bool {
    let line_start = text[..token.range.start].rfind('\n').map_or(0, |n| n + 1);
    text[line_start..token.range.start].trim().is_empty()
}

/// The byte after the end of the line holding byte `byte`.
fn line_end(text: &str, byte: usize) -> usize {
    text[byte..].find('\n').map_or(text.len(), |n| byte + n + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Markers are assembled so that the starter generator does not take them for regions.
    fn file(body: &str) -> String {
        format!("impl A {{\n    /// Docs.\n    pub fn f(&self, x: [u8; 2]) -> u32 {{\n    // BEGIN{} SOLUTION checkpoint2\n{body}    // END SOLUTION\n    }}\n}}\n", "")
    }

    fn bodies(text: &str) -> Vec<(u32, String, String)> {
        find_regions(text)
            .unwrap()
            .into_iter()
            .map(|f| (f.checkpoint, f.function, text[f.body].to_string()))
            .collect()
    }

    #[test]
    fn grader_finds_a_region_and_its_function() {
        let text = file("        let y = { x[0] };\n        y as u32\n");
        assert_eq!(
            bodies(&text),
            [(2, "f".to_string(), "        let y = { x[0] };\n        y as u32\n".to_string())]
        );
        let crlf = text.replace('\n', "\r\n");
        assert_eq!(bodies(&crlf)[0].2, "        let y = { x[0] };\r\n        y as u32\r\n");
    }

    #[test]
    fn grader_finds_no_marker_in_strings_comments_or_nested_blocks() {
        let begin = concat!("// BEGIN", " SOLUTION checkpoint3");
        for text in [
            format!("fn g() -> &'static str {{\n    \"\n    {begin}\n    // END SOLUTION\n    \"\n}}\n"),
            format!("fn g() {{\n    /*\n    {begin}\n    // END SOLUTION\n    */\n}}\n"),
            format!("fn g() {{\n    if true {{\n    {begin}\n    }}\n    // END SOLUTION\n}}\n"),
            format!("fn g() {{\n    let a = 1; {begin}\n    // END SOLUTION\n}}\n"),
            format!("{begin}\nfn g() {{}}\n// END SOLUTION\n"),
            format!("fn g() {{\n    {begin}\n    let a = (1,\n    // END SOLUTION\n    2);\n}}\n"),
        ] {
            assert_eq!(bodies(&text), [], "{text}");
        }
    }

    #[test]
    fn grader_finds_regions_of_several_functions_and_types_of_parameters() {
        let text = concat!(
            "fn a(f: impl Fn(u32) -> u32, g: fn(u8)) -> u32 {\n    // BEGIN",
            " SOLUTION checkpoint4\n    f(1)\n    // END SOLUTION\n}\n",
            "struct S { x: u32 }\nfn b() {\n    // BEGIN",
            " SOLUTION checkpoint5\n    // END SOLUTION\n}\n",
        );
        let found = bodies(text);
        assert_eq!(found.iter().map(|f| (f.0, f.1.as_str())).collect::<Vec<_>>(), [(4, "a"), (5, "b")]);
        assert_eq!(found[1].2, "");
    }
}
