use super::*;
use crate::instructor::similarity::normalise::normalise;

const BODY: &str = "
    // the two edges
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let s = ray.origin - p0;
    let det = e1.dot(ray.dir.cross(e2));
    if det.abs() < 1e-8 {
        return None;
    }
    let u = s.dot(ray.dir.cross(e2)) / det;
    let hits = [0.5f32, 2.0];
    let inside = (0.0..=1.0).contains(&u) && Vec3::ZERO.x >= -1.0;
    Some((u, hits[1]))
";

fn normalised(body: &str) -> Vec<String> {
    normalise(body).into_iter().map(|t| t.text).collect()
}

#[test]
fn similarity_each_disguise_changes_the_text_and_keeps_it_rust() {
    for d in Disguise::ALL {
        let text = disguise(BODY, &[d], 7);
        assert_ne!(text, BODY, "{} changed nothing", d.name());
        assert!(syn::parse_str::<syn::Block>(&format!("{{\n{text}\n}}")).is_ok(), "{}:\n{text}", d.name());
    }
}

#[test]
fn similarity_disguises_do_what_they_say() {
    let renamed = disguise(BODY, &[Disguise::Rename], 1);
    assert!(renamed.contains("let renamed_1 = p1 - p0") && renamed.contains("ray.origin"), "{renamed}");
    assert!(renamed.contains("(0.0..=1.0).contains(&renamed_6)"), "a range's bound is renamed: {renamed}");
    let respelled = disguise(BODY, &[Disguise::Literals], 1);
    assert!(
        respelled.contains("0.00000001") && respelled.contains("5e-1f32") && respelled.contains("[0x1]"),
        "{respelled}"
    );
    let commented = disguise(BODY, &[Disguise::Comments], 1);
    assert!(!commented.contains("the two edges") && commented.contains("// step"), "{commented}");
    let laid_out = disguise(BODY, &[Disguise::Layout], 1);
    assert!(laid_out.contains("let e1 = p1 - p0 ;\n"), "{laid_out}");
    let padded = disguise(BODY, &[Disguise::DeadCode], 1);
    assert!(padded.contains("let unused_0") && padded.contains("let unused_1"), "{padded}");
    // Reordered: the same statements, the `let`s before `if` in some other order, `det` after
    // the edges it uses.
    let orders: HashSet<String> = (0..20).map(|seed| disguise(BODY, &[Disguise::Reorder], seed)).collect();
    assert!(orders.len() > 1, "twenty seeds, one order");
    for text in &orders {
        assert!(text.find("let det").unwrap() > text.find("let e2").unwrap(), "{text}");
        assert!(text.find("let u").unwrap() > text.find("if det").unwrap(), "{text}");
    }
}

#[test]
fn similarity_normalising_undoes_every_disguise_alone_and_combined() {
    let original = normalised(BODY);
    for d in Disguise::ALL {
        for seed in 0..5 {
            assert_eq!(normalised(&disguise(BODY, &[d], seed)), original, "{} (seed {seed})", d.name());
        }
    }
    for combination in Disguise::COMBINATIONS {
        assert_eq!(normalised(&disguise(BODY, combination, 3)), original, "{combination:?}");
    }
}
