//! The checker's verdicts, construct by construct: the Rust Reference's chapters on paths, use
//! declarations, macros by example and attributes, each form with what a region may do with it.

use super::*;
use crate::regions::markers::find_regions;
use crate::regions::stub::rust_files;

/// [`check_region`] with the student API of the instructor's rubric.
fn check(body: &str, checkpoint: u32) -> Result<(), Rejection> {
    static API: std::sync::OnceLock<StudentApi> = std::sync::OnceLock::new();
    let api = API.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        StudentApi::of(&crate::rubric::Rubric::of_tree(&root).unwrap())
    });
    check_region(body, checkpoint, &api.modules(checkpoint))
}

/// Every region of the reference solution, with its checkpoint.
fn solution_regions() -> Vec<(u32, String)> {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src");
    let mut regions = Vec::new();
    for (_, text) in rust_files(&src).unwrap() {
        let found = find_regions(&text).unwrap();
        regions.extend(found.into_iter().map(|f| (f.checkpoint, text[f.body].to_string())));
    }
    assert!(regions.len() >= 11, "{regions:?}");
    regions
}

#[test]
fn grader_allows_every_region_of_the_solution() {
    for (checkpoint, body) in solution_regions() {
        check(&body, checkpoint).unwrap_or_else(|e| panic!("{e:?} in\n{body}"));
    }
}

/// `Err(substring of the reason)` or `Ok`, for a region of checkpoint 6 (lights, scene,
/// integrators, materials, geometry and maths).
type Verdict = Result<(), &'static str>;

fn check_table(table: &[(&str, Verdict)]) {
    let mut wrong = Vec::new();
    for (body, want) in table {
        let got = check(body, 6);
        let right = match (want, &got) {
            (Ok(()), Ok(())) => true,
            (Err(reason), Err(r)) => r.reason.to_string().contains(reason),
            _ => false,
        };
        if !right {
            wrong.push(format!("{body:?}: expected {want:?}, got {got:?}"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The Reference's "Paths": simple paths, paths in expressions and types, qualified paths,
/// `crate`/`self`/`super`, and raw identifiers in any of them.
#[test]
fn grader_checks_every_kind_of_path() {
    check_table(&[
        ("let v = Vec3::new(1.0, 2.0, 3.0);", Ok(())),
        ("let v: Vec<f32> = Vec::with_capacity(3);", Ok(())),
        ("let p = std::f32::consts::PI;", Ok(())),
        ("let m = ::std::cmp::max(1, 2);", Ok(())),
        ("let x = core::mem::swap::<u8>;", Ok(())),
        ("let i = crate::light::PointLight::intensity;", Ok(())),
        ("let b = std::fs::read(\"reference/cornell.png\");", Err("std::fs::read")),
        ("::std::process::exit(0)", Err("std::process::exit")),
        ("core::ptr::null::<u8>();", Err("core::ptr")),
        ("let t: std::thread::JoinHandle<()> = todo!();", Err("std::thread")),
        ("let s = crate::image_io::write_png;", Err("image_io")),
        ("let s = Scene::load(path);", Err("load")),
        ("let m = TriangleMesh::load_obj(path);", Err("load_obj")),
        ("let w = World::wide(world.scene());", Err("wide")),
        ("if crate::graded::student(2) { 1 } else { 2 }", Err("graded")),
        ("super::NodeView::Leaf", Err("super::NodeView")),
        ("self::helper()", Err("self::helper")),
        ("tobj::load_obj(\"x.obj\", &tobj::LoadOptions::default())", Err("load")),
        ("rayon::spawn(|| loop {});", Err("rayon")),
        ("raylab_base::image_io::write_file_atomic(p, b\"x\")", Err("raylab_base")),
        // Qualified paths: the item is judged as if it followed a type.
        ("let s = <Scene>::load(path);", Err("load")),
        ("let s = <Scene as Default>::default();", Ok(())),
        ("let n = <f32 as std::ops::Neg>::neg(1.0);", Ok(())),
        ("let n = <f32 as std::os::Foo>::neg(1.0);", Err("std::os")),
        ("let f = <std::fs::File>::open(\"x\");", Err("std::fs::File")),
        ("let x: <Vec<u8> as IntoIterator>::Item = 0;", Ok(())),
        ("let b = <World>::wide;", Err("wide")),
        // Raw identifiers are what rustc reads without the `r#`.
        ("r#std::process::exit(0)", Err("raw identifiers")),
        ("let s = Scene::r#load(path);", Err("`r#load`")),
        ("let r#type = 1;", Err("raw identifiers")),
        ("println!(\"{}\", r#std::env::var(\"HOME\").is_ok());", Err("raw identifiers")),
    ]);
}

/// The Reference's "Use declarations": single names, groups, nested groups, globs, renames,
/// leading `::`, `self`, `super`, `crate`.
#[test]
fn grader_checks_every_kind_of_use_declaration() {
    check_table(&[
        ("use std::mem::swap;\nlet (mut a, mut b) = (1, 2);\nswap(&mut a, &mut b);", Ok(())),
        ("use std::{cmp::max, f32::consts::PI};\nmax(1, 2) as f32 * PI", Ok(())),
        ("use crate::math::spawn_ray;", Ok(())),
        ("use std::{collections::HashMap, process};", Err("std::process")),
        ("use std::fs as f;\nlet b = f::read(\"x\");", Err("as f")),
        ("use std::cmp::max as biggest;", Err("own names")),
        ("use std::*;", Err("use std::*")),
        ("use std::collections::*;", Err("one by one")),
        ("use crate::geometry::*;", Err("one by one")),
        ("use ::std::process::exit;", Err("std::process::exit")),
        ("use self::helper;", Err("self::helper")),
        ("use super::Bvh;", Err("super::Bvh")),
        ("use std;", Err("name the items")),
        ("use tobj;", Err("name the items")),
        ("use crate::fallback::Fallbacks;", Err("fallback")),
        ("use std::prelude::v1::include_bytes as vec;\nvec!(\"x\")", Err("as vec")),
        ("use std::prelude::v1::vec;\nlet v = vec![1];", Err("brought in by a `use`")),
        ("let v = vec![1];\nuse std::prelude::v1::vec;", Err("brought in by a `use`")),
    ]);
}

/// The Reference's "Macros by example": definitions, invocations by path and with each
/// delimiter, and what the allowed macros' arguments hold.
#[test]
fn grader_checks_every_kind_of_macro_use() {
    check_table(&[
        ("let v = vec![0.0f32; 3];\nassert_eq!(v.len(), 3);", Ok(())),
        ("let s = format!(\"{} {x}\", 1, x = 2);", Ok(())),
        ("let v = std::vec![1, 2];", Ok(())),
        ("core::panic!(\"no\")", Ok(())),
        ("matches!(self.view(), NodeView::Leaf { .. })", Ok(())),
        ("debug_assert!{ true }", Ok(())),
        ("macro_rules! m { () => {} }", Err("macro definitions")),
        ("let b = include_bytes!(\"../../reference/cornell.png\");", Err("include_bytes")),
        ("let s = include_str!(\"x\");", Err("include_str")),
        ("let h = env!(\"HOME\");", Err("env")),
        ("let h = option_env!(\"HOME\");", Err("option_env")),
        ("std::arch::asm!(\"nop\");", Err("std::arch")),
        ("let x = concat!(\"a\", \"b\");", Err("concat")),
        ("let v = std::prelude::v1::vec![1];", Err("std::prelude::v1::vec")),
        ("let v = crate::vec![1];", Err("crate::vec")),
        ("println!(\"{:?}\", std::env::var(\"HOME\"));", Err("std::env::var")),
        ("let v = vec![std::process::id(); 3];", Err("std::process::id")),
        ("let m = matches!(x, Some(_) if std::thread::panicking());", Err("std::thread::panicking")),
        ("assert!(true, \"{}\", include_str!(\"x\"));", Err("include_str")),
        ("println!(concat!(\"a\", \"{}\"), 1);", Err("concat")),
        ("let x = vec!{ 1 => 2 };", Err("could not be checked")),
    ]);
}

/// The Reference's "Attributes": outer and inner, built-in ones of every group, tool
/// attributes, values that are expressions or macros.
#[test]
fn grader_checks_every_kind_of_attribute() {
    check_table(&[
        ("#[allow(clippy::needless_range_loop)]\nfor i in 0..3 { debug_assert!(i < 3, \"{i}\"); }", Ok(())),
        ("#[allow(unused_variables, unused_mut)]\nlet mut a = 1;", Ok(())),
        ("#[inline]\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("#[inline(always)]\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("#[must_use]\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("#[must_use = \"the hit\"]\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("/// The helper.\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("#[doc = \"The helper.\"]\nfn f() -> u32 { 1 }\nf()", Ok(())),
        ("#[doc = include_str!(\"/etc/passwd\")]\nfn f() {}", Err("string literal only")),
        ("#[must_use = concat!(\"a\", \"b\")]\nfn f() {}", Err("string literal only")),
        ("#[doc = \"a\"]\n#[doc(hidden)]\nfn f() {}", Err("#[doc]")),
        (
            "#[allow(long_running_const_eval)]\nconst X: u64 = { let mut i = 0; loop { i += 1 } };",
            Err("long_running_const_eval"),
        ),
        ("#[allow(unconditional_recursion)]\nfn f() { f() }", Err("unconditional_recursion")),
        ("#[allow(unsafe_code)]\nlet a = 1;", Err("unsafe_code")),
        ("#[allow(warnings)]\nlet a = 1;", Err("warnings")),
        ("#[allow(unused)]\nlet a = 1;", Err("unused")),
        ("#[allow(clippy::all)]\nlet a = 1;", Err("clippy::all")),
        ("#[allow(include_str!(\"x\"))]\nlet a = 1;", Err("lints by name")),
        ("#[warn(dead_code)]\nlet a = 1;", Err("#[warn]")),
        ("#[deny(dead_code)]\nlet a = 1;", Err("#[deny]")),
        ("#[forbid(dead_code)]\nlet a = 1;", Err("#[forbid]")),
        ("#[expect(dead_code)]\nlet a = 1;", Err("#[expect]")),
        ("#[no_mangle]\nfn main() {}", Err("no_mangle")),
        ("#[export_name = \"main\"]\nfn f() {}", Err("export_name")),
        ("#[link_section = \".init_array\"]\nfn f() {}", Err("link_section")),
        ("#[used]\nconst X: u8 = 1;", Err("used")),
        ("#[path = \"x.rs\"]\nmod m;", Err("`mod`")),
        ("#[path = \"x.rs\"]\nfn f() {}", Err("#[path]")),
        ("#[cfg(test)]\nfn f() {}", Err("cfg")),
        ("#[cfg_attr(all(), no_mangle)]\nfn f() {}", Err("cfg_attr")),
        ("#[derive(Clone)]\nstruct P;", Err("derive")),
        ("#[track_caller]\nfn f() {}", Err("track_caller")),
        ("#[rustfmt::skip]\nlet a = 1;", Err("rustfmt::skip")),
        ("#![allow(dead_code)]\nlet a = 1;", Err("")),
        ("let a = #[allow(unused_parens)] (1);", Ok(())),
        ("let a = #[cfg(any())] 1;", Err("cfg")),
    ]);
}

/// Items that would act outside the region's function: impls of the renderer's types, state
/// that outlives a call, modules, traits, foreign code; and `unsafe` however it is reached.
#[test]
fn grader_checks_items_and_unsafe() {
    check_table(&[
        ("struct Loud;\nimpl Drop for Loud { fn drop(&mut self) {} }\nlet _l = Loud;", Ok(())),
        ("enum Side { In, Out }\nimpl Side { fn flip(self) -> Self { self } }\nSide::In.flip();", Ok(())),
        ("struct P<T>(T);\nimpl<T: Copy> Clone for P<T> { fn clone(&self) -> Self { P(self.0) } }", Ok(())),
        ("const N: usize = 3;\nlet a = [0.0f32; N];", Ok(())),
        ("type Pair = (f32, f32);\nlet p: Pair = (1.0, 2.0);", Ok(())),
        ("fn helper(x: f32) -> f32 { x * 2.0 }\nhelper(1.0)", Ok(())),
        ("impl Drop for Bvh { fn drop(&mut self) {} }", Err("`impl` of `Bvh`")),
        ("impl crate::geometry::Bvh { fn x(&self) {} }", Err("only its own types")),
        ("type B = Bvh;\nimpl Drop for B { fn drop(&mut self) {} }", Err("`impl` of `B`")),
        ("trait T { fn t(&self) {} }\nimpl<X> T for X {}", Err("`trait`")),
        ("struct X;\nimpl<X> Clone for X { fn clone(&self) -> Self { todo!() } }", Err("`impl` of `X`")),
        ("impl<T> From<T> for Vec3 { fn from(_: T) -> Self { todo!() } }", Err("`impl` of `Vec3`")),
        ("trait Hit {}", Err("`trait`")),
        ("static COUNT: u32 = 0;", Err("`static`")),
        ("static mut COUNT: u32 = 0;", Err("`static`")),
        ("const C: std::cell::Cell<u32> = std::cell::Cell::new(0);", Err("`Cell`")),
        ("const M: Option<std::sync::Mutex<u8>> = None;", Err("`Mutex`")),
        ("const A: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);", Err("AtomicU32")),
        ("mod m {}", Err("`mod`")),
        ("extern crate std as s;", Err("`extern crate`")),
        ("extern \"C\" { fn abort(); }", Err("`extern` blocks")),
        ("extern \"C\" fn f() {}", Err("`extern` functions")),
        ("unsafe { *(0 as *const u8) }", Err("`unsafe`")),
        ("unsafe fn f() {}", Err("`unsafe fn`")),
        ("struct S;\nunsafe impl Send for S {}", Err("`unsafe impl`")),
        ("let f: unsafe fn() = todo!();", Err("`unsafe fn` types")),
        ("fn g() { let x = || unsafe { 1 }; }", Err("`unsafe`")),
    ]);
}

/// Literals of every kind count towards the data limits: a table of values (here 300 tile
/// means, as a region copying a noisy scene's reference would hold) is rejected in numbers,
/// strings, chars, bytes or doc text; the solution's regions stay far below the limits.
#[test]
fn grader_rejects_a_region_that_embeds_a_table_of_data() {
    let table: Vec<String> = (0..300).map(|i| format!("{:.4}", i as f32 / 300.0)).collect();
    let chars: String = (0..600).map(|i| format!("'{}',", (b'a' + (i % 26) as u8) as char)).collect();
    let bytes: String = (0..600).map(|i| format!("b'{}',", (b'a' + (i % 26) as u8) as char)).collect();
    for body in [
        format!("const T: [f32; 300] = [{}];\nT[0]", table.join(", ")),
        format!("let t = \"{}\";\nt.len()", table.join(",")),
        format!("let t = [{chars}];\nt.len()"),
        format!("let t = [{bytes}];\nt.len()"),
        format!("/// {}\nfn t() {{}}", table.join(",")),
        format!("let t = [{}];", "u8::MAX, ".repeat(0) + &"1, ".repeat(65)),
    ] {
        let r = check(&body, 6).expect_err(&body);
        assert!(r.reason.to_string().contains("does not embed data"), "{r:?}");
    }
    let (mut numbers, mut text) = (0, 0);
    for (checkpoint, body) in solution_regions() {
        let block: syn::Block = syn::parse_str(&format!("{{\n{body}\n}}")).unwrap();
        let mut declared = Declared::default();
        declared.visit_block(&block);
        let mut checker = Checker::new(checkpoint, ALL_STUDENT_MODULES, declared);
        checker.visit_block(&block);
        (numbers, text) = (checker.numbers.max(numbers), checker.text.max(text));
    }
    assert!(
        numbers <= MAX_NUMBERS / 4 && text <= MAX_TEXT / 4,
        "the solution's largest region: {numbers} numbers, {text} bytes"
    );
}

/// Size and nesting are bounded before syn parses, and the worst shapes within the bounds are
/// parsed without overflowing the checker's stack; the solution stays far below both.
#[test]
fn grader_checks_any_shape_of_region_without_crashing() {
    let deep = format!("{}1{}", "(".repeat(3000), ")".repeat(3000));
    assert_eq!(check(&deep, 6).unwrap_err().reason, Refusal::TooDeep(3000));
    let long = "let a = 1;\n".repeat(2000);
    assert_eq!(check(&long, 6).unwrap_err().reason, Refusal::TooLong);
    assert_eq!(check("let a = (1;", 6).unwrap_err().reason, Refusal::Unbalanced);
    assert!(check("let s = \"open;", 6).unwrap_err().reason.to_string().contains("never ends"));
    // Chains that syn parses by recursion, as long as the size limit allows.
    let fill = |unit: &str, end: &str| unit.repeat((MAX_REGION_BYTES - end.len()) / unit.len()) + end;
    for body in [
        fill("-", "1"),
        fill("!", "true"),
        fill("&", "1"),
        fill("*", "x"),
        fill("return ", "1"),
        fill("|| ", "1"),
        fill("if a {} else ", "{}"),
        fill("a = ", "1"),
        fill("x.0.", "0"),
        fill("f()", ""),
        fill("a as ", "u8"),
        fill("..", "1"),
        fill("'a: loop { break 'a ", "}"),
    ] {
        let _ = check(&body, 6);
    }
    let (mut size, mut depth) = (0, 0);
    for (_, body) in solution_regions() {
        size = size.max(body.len());
        depth = depth.max(nesting(&tokens(&body).unwrap()).0);
    }
    assert!(
        size <= MAX_REGION_BYTES / 4 && depth <= MAX_NESTING / 4,
        "largest {size} bytes, deepest {depth}"
    );
}

#[test]
fn grader_is_not_tripped_by_comments_strings_or_printing() {
    for body in [
        "// std::fs::read would be cheating\nlet s = \"std::process::exit\";\nprintln!(\"{s}\");\nNone",
        "/* r#std::process */ let s = \"r#std\";\ns.len()",
        "let v: Vec<f32> = vec![0.0; 3];\nlet m = std::collections::HashMap::<u32, f32>::new();\nv.len()",
        "let (a, b) = (1.0f32, 2.0f32);\nlet c = a.min(b).max(f32::EPSILON) * std::f32::consts::PI;\nc",
    ] {
        check(body, 4).unwrap_or_else(|e| panic!("{body}: {e:?}"));
    }
}

#[test]
fn grader_knows_every_crate_the_renderer_depends_on() {
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.toml");
    let manifest: toml::Table = toml::from_str(&std::fs::read_to_string(manifest).unwrap()).unwrap();
    for name in manifest["dependencies"].as_table().unwrap().keys().filter(|n| *n != "glam") {
        // As a path names it: `raylab-base` is `raylab_base::`.
        let name = name.replace('-', "_");
        assert!(OTHER_CRATES.contains(&name.as_str()), "{name} is missing from OTHER_CRATES");
    }
}

#[test]
fn grader_lets_a_local_variable_share_a_harness_name() {
    check("let load = 0.5f32;\nlet render = load * 2.0;\nrender", 2).unwrap();
}

/// Each checkpoint names the modules its handout works with: the triangle test reaches no
/// light, and anti-aliasing no geometry; every module is open to the extras.
#[test]
fn grader_allows_each_region_the_student_api_of_its_checkpoint() {
    let light = "let i = crate::light::PointLight::intensity;";
    assert!(check(light, 6).is_ok());
    let reason = check(light, 2).unwrap_err().reason.to_string();
    assert!(reason.contains("checkpoint 2 works with crate::{math, geometry}"), "{reason}");
    assert!(check("let b = crate::geometry::Aabb::new;", 7).is_err());
    assert!(check("let s = crate::sampling::estimate_pixel;", 7).is_ok());
    assert!(check(light, 8).is_ok());
}

#[test]
fn grader_reports_the_line_of_the_rejected_code() {
    let line = |body: &str| check(body, 6).unwrap_err().line;
    assert_eq!(line("let a = 1;\n\nlet b = std::fs::read(\"x\");"), 3);
    assert_eq!(line("let a = 1;\nlet b = r#std::fs::read(\"x\");"), 2);
    assert_eq!(line("let a = 1;\n#[no_mangle]\nfn f() {}"), 2);
    assert_eq!(line("let a = 1;\n#[doc = include_str!(\"x\")]\nlet b = 2;"), 2);
}

/// The compiler is the second wall: the renderer denies `unsafe` code, and only the harness's
/// SIMD module, which holds no region, allows it.
#[test]
fn grader_has_the_compiler_refuse_unsafe_code_in_every_region_file() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    assert!(lib.lines().any(|l| l == "#![deny(unsafe_code)]"), "src/lib.rs must deny unsafe code");
    let mut allowed = Vec::new();
    for (path, text) in rust_files(&src).unwrap() {
        let lines: Vec<&str> = text.lines().collect();
        for (i, _) in lines.iter().enumerate().filter(|(_, l)| l.contains("allow(unsafe_code)")) {
            let next = lines.get(i + 1).map(|l| l.to_string());
            allowed.push((path.strip_prefix(&src).unwrap().display().to_string(), next));
        }
    }
    assert_eq!(allowed, [("geometry/mod.rs".to_string(), Some("pub mod wide;".to_string()))]);
    let wide: Vec<_> = rust_files(&src.join("geometry/wide")).unwrap();
    assert!(wide.iter().all(|(_, text)| find_regions(text).unwrap().is_empty()));
}
