use super::*;

/// The normalised text of `body`, tokens joined by spaces.
fn text(body: &str) -> String {
    normalise(body).into_iter().map(|t| t.text).collect::<Vec<_>>().join(" ")
}

const ORIGINAL: &str = "
    let edge1 = p1 - p0;
    let edge2 = p2 - p0;
    let pvec = ray.dir.cross(edge2);
    let det = edge1.dot(pvec);
    if det.abs() < 1e-8 {
        return None;
    }
    let inv = 1.0 / det;
    Some(inv)
";

#[test]
fn similarity_normalising_forgets_names_bound_in_the_region_and_keeps_the_others() {
    let renamed = ORIGINAL.replace("edge1", "first_edge").replace("pvec", "p").replace("inv", "reciprocal");
    assert_eq!(text(ORIGINAL), text(&renamed));
    // A parameter, a field and a method are not the region's to rename.
    assert!(text(ORIGINAL).contains("ray . dir . cross"), "{}", text(ORIGINAL));
    assert_ne!(text(ORIGINAL), text(&ORIGINAL.replace("cross", "dot")));
    // A range's end is a name like any other, a field is not.
    assert_eq!(
        text("let n = 3; for i in 0..n { f(i); } let m = x.n; m"),
        text("let k = 3; for j in 0..k { f(j); } let q = x.n; q")
    );
    assert_ne!(text("let n = 3; let m = x.n; m + n"), text("let k = 3; let q = x.k; q + k"));
}

#[test]
fn similarity_normalising_forgets_layout_comments_and_literal_spelling() {
    let disguised = "let edge1=p1-p0; // the first edge
        /* the second */ let edge2 = p2
            - p0;
        let pvec = ray.dir.cross(edge2); let det = edge1.dot(pvec);
        if det.abs() < 0.000_000_01_f32 { return None; }
        let inv = 1.0_f32 / det; Some(inv)";
    assert_eq!(text(ORIGINAL), text(disguised));
    // A number's value is kept: another epsilon is another program.
    assert_ne!(text(ORIGINAL), text(&ORIGINAL.replace("1e-8", "1e-6")));
}

#[test]
fn similarity_normalising_puts_independent_statements_in_one_order() {
    let swapped = ORIGINAL.replace(
        "let edge1 = p1 - p0;\n    let edge2 = p2 - p0;",
        "let edge2 = p2 - p0;\n    let edge1 = p1 - p0;",
    );
    assert_ne!(swapped, ORIGINAL);
    assert_eq!(text(ORIGINAL), text(&swapped));
    // A statement never moves before the one whose name it uses.
    let t = text(ORIGINAL);
    assert!(t.find("cross").unwrap() < t.find("dot").unwrap(), "{t}");
}

#[test]
fn similarity_normalising_drops_lets_nothing_uses() {
    let padded = ORIGINAL
        .replace("let det", "let unused = edge1 * 2.0;\n    let _ = (&ray, &p0);\n    let det")
        .replace("Some(inv)", "let twice = inv + inv;\n    let _also = twice;\n    Some(inv)");
    assert_eq!(text(ORIGINAL), text(&padded));
    // Inner blocks too.
    let inner = ORIGINAL.replace("return None;", "let waste = det * det;\n        return None;");
    assert_eq!(text(ORIGINAL), text(&inner));
}

#[test]
fn similarity_normalising_keeps_each_token_s_region_line() {
    let tokens = normalise(ORIGINAL);
    let det = tokens.iter().find(|t| t.text == "abs").unwrap();
    assert_eq!(det.line, 6, "`det.abs()` is on the region's sixth line");
}

#[test]
fn similarity_normalising_reads_what_does_not_parse_token_by_token() {
    assert_eq!(text("let x = 1.0 +; foo(x"), "");
    assert_eq!(text("let x = 1.0 + ; y"), "let x = 1 + ; y");
    assert!(text("\"unterminated").is_empty());
}

#[test]
fn similarity_normalising_gives_one_order_whichever_valid_order_was_written() {
    // `p` and `q` read alike; `r` needs `q`. Written p q r or q p r, one text.
    let a = "let p = v1 - v0; let q = v2 - v0; let r = q * 2.0; p + r";
    let b = "let q = v2 - v0; let p = v1 - v0; let r = q * 2.0; p + r";
    assert_eq!(text(a), text(b));
}

#[test]
fn similarity_normalising_drops_mut_and_type_annotations_and_keeps_variants() {
    assert_eq!(text("let mut x: f32 = a; x += 1.0; x"), text("let mut y = a; y += 1.0; y"));
    assert_eq!(text("let t = |k: f32| k * 2.0; t(a)"), text("let t = |k| k * 2.0; t(a)"));
    // `None` in a pattern is a variant, not a binding: it is not `$v`.
    let t = text("match h { None => 0.0, Some(hit) => hit.t }");
    assert!(t.contains("None") && t.contains("Some ( $v )"), "{t}");
}

#[test]
fn similarity_normalising_reads_a_long_run_of_lets() {
    // Two thousand `let`s kept alive by one sum: one pass for the dead, one sort for the order
    // (a rescan of the run per statement took hours on such a body).
    let lets: String = (0..2000).map(|i| format!("let v{i} = a * {i}.0;\n")).collect();
    let sum: Vec<String> = (0..2000).map(|i| format!("v{i}")).collect();
    let body = format!("{lets}{}", sum.join(" + "));
    assert_eq!(normalise(&body).iter().filter(|t| t.text == "let").count(), 2000);
}
