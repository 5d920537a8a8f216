//! Layers: each crate's modules, drawn from the paths its code names, must point one way.
//!
//! A module is a file (`a/b.rs` or `a/b/mod.rs` is `a::b`). Module `S` *names* module `T` when
//! its code (a `use` or any path in an item, type or expression) starts with `crate::`, `super::`
//! or `self::` and resolves to `T` or an item in it; test-only code (`#[cfg(test)]`) is left out,
//! because what a test reads says nothing about the layering of what ships.
//!
//! The rule is per folder: inside each module, its direct submodules are the layers, and the
//! graph "some file under `X` names something under `Y`" between siblings `X` and `Y` must have
//! no cycle. A module naming its own parent or children is containment, not layering (a
//! `mod.rs` re-exports its parts, a part uses the types its parent defines). The layers of a
//! folder are then listed bottom first: a sibling comes after everything it names.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use syn::visit::Visit;

/// A module's path from its crate root (`[]` is the root itself).
type ModPath = Vec<String>;

/// One crate: its root folder and the modules found under it.
pub struct Crate {
    name: String,
    modules: BTreeMap<ModPath, PathBuf>,
    /// (naming module, named module, file of the naming module).
    edges: Vec<(ModPath, ModPath, PathBuf)>,
}

/// A cycle between sibling modules, each link with a file that makes it.
#[derive(Debug)]
pub struct Cycle {
    /// The folder (module) whose parts form the cycle.
    pub folder: String,
    /// The parts in order; the last names the first.
    pub parts: Vec<String>,
    /// For each link (part i names part i + 1), a file that does it.
    pub evidence: Vec<PathBuf>,
}

impl Crate {
    /// Reads a crate whose root module is `root/lib.rs` or `root/main.rs`; `src/bin` holds other
    /// crates and is left out.
    pub fn read(name: &str, root: &Path) -> Result<Crate, String> {
        let mut files = Vec::new();
        collect_rs(root, root, &mut files)?;
        let mut parsed = Vec::new();
        for file in files {
            let text = fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let ast = syn::parse_file(&text).map_err(|e| format!("{}: {e}", file.display()))?;
            parsed.push((module_path(root, &file), file, ast));
        }
        let test_only: BTreeSet<ModPath> =
            parsed.iter().flat_map(|(path, _, ast)| test_only_children(path, ast)).collect();
        parsed.retain(|(path, _, _)| !test_only.iter().any(|t| path.starts_with(t)));
        let modules: BTreeMap<ModPath, PathBuf> =
            parsed.iter().map(|(path, file, _)| (path.clone(), file.clone())).collect();
        let reexports = parsed.iter().flat_map(|(path, _, ast)| reexports(path, ast)).collect();
        let resolver = Resolver { modules, reexports };
        let mut edges = Vec::new();
        for (path, file, ast) in &parsed {
            let mut names = Names { here: path, resolver: &resolver, found: BTreeSet::new() };
            names.visit_file(ast);
            edges.extend(names.found.into_iter().map(|to| (path.clone(), to, file.clone())));
        }
        Ok(Crate { name: name.to_string(), modules: resolver.modules, edges })
    }

    /// Every folder's sibling graph: folder -> (part -> (named part -> a file that names it)).
    fn sibling_graphs(&self) -> BTreeMap<ModPath, BTreeMap<String, BTreeMap<String, PathBuf>>> {
        let mut graphs: BTreeMap<ModPath, BTreeMap<String, BTreeMap<String, PathBuf>>> = BTreeMap::new();
        for (folder, children) in self.folders() {
            let graph = graphs.entry(folder).or_default();
            for child in children {
                graph.entry(child).or_default();
            }
        }
        for (from, to, file) in &self.edges {
            let common = from.iter().zip(to).take_while(|(a, b)| a == b).count();
            if common == from.len() || common == to.len() {
                continue; // a module and its own ancestor or descendant
            }
            let graph = graphs.entry(from[..common].to_vec()).or_default();
            let named = graph.entry(from[common].clone()).or_default();
            named.entry(to[common].clone()).or_insert_with(|| file.clone());
        }
        graphs
    }

    /// Each module that has submodules, with the names of its direct submodules.
    fn folders(&self) -> BTreeMap<ModPath, BTreeSet<String>> {
        let mut folders: BTreeMap<ModPath, BTreeSet<String>> = BTreeMap::new();
        for path in self.modules.keys().filter(|p| !p.is_empty()) {
            let (last, parent) = path.split_last().expect("not the root");
            folders.entry(parent.to_vec()).or_default().insert(last.clone());
        }
        folders
    }

    /// The cycles between siblings, one per strongly connected group.
    pub fn cycles(&self) -> Vec<Cycle> {
        let mut cycles = Vec::new();
        for (folder, graph) in self.sibling_graphs() {
            for group in strongly_connected(&graph).into_iter().filter(|g| g.len() > 1) {
                let parts = cycle_through(&graph, &group);
                let evidence = (0..parts.len())
                    .map(|i| graph[&parts[i]][&parts[(i + 1) % parts.len()]].clone())
                    .collect();
                cycles.push(Cycle { folder: self.display(&folder), parts, evidence });
            }
        }
        cycles
    }

    /// A folder's parts in layers, bottom first: a part's layer is one above the highest part it
    /// names (the bottom layer names no sibling). Parts in a cycle are left out: `cycles` reports them.
    pub fn layers(&self, folder: &[&str]) -> Vec<Vec<String>> {
        let folder: ModPath = folder.iter().map(|s| s.to_string()).collect();
        let graphs = self.sibling_graphs();
        let Some(graph) = graphs.get(&folder) else { return Vec::new() };
        let mut level: BTreeMap<&String, usize> = BTreeMap::new();
        while level.len() < graph.len() {
            let ready: Vec<(&String, usize)> = graph
                .iter()
                .filter(|(part, named)| {
                    !level.contains_key(part) && named.keys().all(|n| level.contains_key(n))
                })
                .map(|(part, named)| (part, named.keys().map(|n| level[n] + 1).max().unwrap_or(0)))
                .collect();
            if ready.is_empty() {
                break;
            }
            level.extend(ready);
        }
        let mut layers: Vec<Vec<String>> = vec![Vec::new(); level.values().map(|l| l + 1).max().unwrap_or(0)];
        for (part, l) in level {
            layers[l].push(part.clone());
        }
        layers
    }

    /// One line per folder with two or more parts: `crate::folder: bottom, ..., top`.
    pub fn folder_lines(&self) -> Vec<String> {
        let folders = self.folders();
        let multi = folders.iter().filter(|(_, parts)| parts.len() > 1);
        multi
            .map(|(folder, _)| {
                let names: Vec<&str> = folder.iter().map(String::as_str).collect();
                let layers: Vec<String> = self.layers(&names).iter().map(|l| l.join(" ")).collect();
                format!("{}: {}", self.display(folder), layers.join(" < "))
            })
            .collect()
    }

    fn display(&self, path: &[String]) -> String {
        std::iter::once(self.name.as_str())
            .chain(path.iter().map(String::as_str))
            .collect::<Vec<_>>()
            .join("::")
    }
}

/// The `.rs` files under `dir`, leaving out `root/bin` (each binary is a crate of its own).
fn collect_rs(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
    let entries = fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for entry in entries {
        let path = entry.map_err(|e| format!("{}: {e}", dir.display()))?.path();
        if path.is_dir() && path != root.join("bin") {
            collect_rs(root, &path, out)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    Ok(())
}

/// `a/b.rs` and `a/b/mod.rs` are `[a, b]`; the crate root file is `[]`.
fn module_path(root: &Path, file: &Path) -> ModPath {
    let relative = file.strip_prefix(root).expect("under the root").with_extension("");
    let mut parts: ModPath = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod")) || parts.len() == 1 && is_root_file(&parts[0])
    {
        parts.pop();
    }
    parts
}

fn is_root_file(stem: &str) -> bool {
    stem == "lib" || stem == "main"
}

fn is_test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test"))
}

/// The submodules a file declares under `#[cfg(test)]` (`#[cfg(test)] mod tests;`).
fn test_only_children(here: &ModPath, ast: &syn::File) -> Vec<ModPath> {
    ast.items
        .iter()
        .filter_map(|item| match item {
            syn::Item::Mod(m) if is_test_only(&m.attrs) => {
                Some(here.iter().cloned().chain([m.ident.to_string()]).collect())
            }
            _ => None,
        })
        .collect()
}

/// What a path names: the modules, and the items each module re-exports (`pub use`).
struct Resolver {
    modules: BTreeMap<ModPath, PathBuf>,
    /// (module, name it re-exports) -> (that module, the path of its `pub use`).
    reexports: BTreeMap<(ModPath, String), (ModPath, Vec<String>)>,
}

impl Resolver {
    /// The module a path reaches from `here`: it starts with `crate`, `super`, `self` or a
    /// submodule of `here`, goes down the modules it names, and follows a re-exported item to the
    /// module that defines it. `None` for a path that starts anywhere else (a crate, a local).
    fn resolve(&self, here: &ModPath, segments: &[String], depth: usize) -> Option<ModPath> {
        let mut at: ModPath = match segments.first()?.as_str() {
            "crate" => Vec::new(),
            "self" | "super" => here.clone(),
            first if self.modules.contains_key(&child(here, first)) => here.clone(),
            _ => return None,
        };
        let mut rest = segments.iter().peekable();
        while let Some(s) = rest.next_if(|s| matches!(s.as_str(), "crate" | "self" | "super")) {
            if s == "super" {
                at.pop()?;
            }
        }
        for s in rest {
            if self.modules.contains_key(&child(&at, s)) {
                at.push(s.clone());
            } else {
                match self.reexports.get(&(at.clone(), s.clone())) {
                    Some((from, path)) if depth < 8 => return self.resolve(from, path, depth + 1),
                    _ => break,
                }
            }
        }
        Some(at)
    }
}

fn child(parent: &ModPath, name: &str) -> ModPath {
    parent.iter().cloned().chain([name.to_string()]).collect()
}

/// One re-export: (module, name) and (module, path), as [`Resolver::reexports`] holds them.
type Reexport = ((ModPath, String), (ModPath, Vec<String>));

/// The items a file re-exports by name (`pub use a::B;`, `pub use a::B as C;`), outside tests.
fn reexports(here: &ModPath, ast: &syn::File) -> Vec<Reexport> {
    let mut found = Vec::new();
    for item in &ast.items {
        if let syn::Item::Use(u) = item {
            if matches!(u.vis, syn::Visibility::Public(_) | syn::Visibility::Restricted(_))
                && !is_test_only(&u.attrs)
            {
                let mut leaves = Vec::new();
                use_leaves(&u.tree, Vec::new(), &mut leaves);
                for (path, name) in leaves.into_iter().filter_map(|(p, n)| n.map(|n| (p, n))) {
                    found.push(((here.clone(), name), (here.clone(), path)));
                }
            }
        }
    }
    found
}

/// Collects the modules a file's code names, outside test-only code.
struct Names<'a> {
    here: &'a ModPath,
    resolver: &'a Resolver,
    found: BTreeSet<ModPath>,
}

impl Names<'_> {
    fn name(&mut self, segments: Vec<String>) {
        if let Some(target) = self.resolver.resolve(self.here, &segments, 0) {
            if &target != self.here {
                self.found.insert(target);
            }
        }
    }
}

impl<'ast> Visit<'ast> for Names<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test_only(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test_only(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if !is_test_only(&u.attrs) {
            let mut leaves = Vec::new();
            use_leaves(&u.tree, Vec::new(), &mut leaves);
            for (leaf, _) in leaves {
                self.name(leaf);
            }
        }
    }

    fn visit_path(&mut self, path: &'ast syn::Path) {
        self.name(path.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, path);
    }
}

/// Every full path a `use` tree imports, with the name it is known by (`None` for a glob):
/// `a::{b, c::d as e}` gives `a::b` (`b`) and `a::c::d` (`e`).
fn use_leaves(tree: &syn::UseTree, prefix: Vec<String>, out: &mut Vec<(Vec<String>, Option<String>)>) {
    let with = |name: &syn::Ident| prefix.iter().cloned().chain([name.to_string()]).collect();
    match tree {
        syn::UseTree::Path(p) => use_leaves(&p.tree, with(&p.ident), out),
        syn::UseTree::Name(n) if n.ident == "self" => {
            let name = prefix.last().cloned();
            out.push((prefix, name));
        }
        syn::UseTree::Name(n) => out.push((with(&n.ident), Some(n.ident.to_string()))),
        syn::UseTree::Rename(r) => out.push((with(&r.ident), Some(r.rename.to_string()))),
        syn::UseTree::Glob(_) => out.push((prefix, None)),
        syn::UseTree::Group(g) => g.items.iter().for_each(|t| use_leaves(t, prefix.clone(), out)),
    }
}

type Graph = BTreeMap<String, BTreeMap<String, PathBuf>>;

/// The strongly connected groups of a graph (Tarjan's algorithm, recursive: folders are small).
fn strongly_connected(graph: &Graph) -> Vec<Vec<String>> {
    struct State<'g> {
        graph: &'g Graph,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        groups: Vec<Vec<String>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g str) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        for w in s.graph[v].keys() {
            if !s.index.contains_key(w.as_str()) {
                visit(s, w);
                s.low.insert(v, s.low[v].min(s.low[w.as_str()]));
            } else if s.stack.contains(&w.as_str()) {
                s.low.insert(v, s.low[v].min(s.index[w.as_str()]));
            }
        }
        if s.low[v] == s.index[v] {
            let at = s.stack.iter().rposition(|&x| x == v).expect("on the stack");
            s.groups.push(s.stack.split_off(at).into_iter().map(String::from).collect());
        }
    }
    let mut s =
        State { graph, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), groups: Vec::new() };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.groups
}

/// One cycle through a strongly connected group: a path from its first part back to it.
fn cycle_through(graph: &Graph, group: &[String]) -> Vec<String> {
    let start = group.iter().min().expect("a non-empty group").clone();
    // Breadth first from `start` inside the group, until an edge back to `start`.
    let mut came_from: BTreeMap<String, String> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start.clone()]);
    while let Some(v) = queue.pop_front() {
        for w in graph[&v].keys().filter(|w| group.contains(w)) {
            if *w == start {
                let mut path = vec![v.clone()];
                while let Some(p) = came_from.get(path.last().expect("not empty")) {
                    path.push(p.clone());
                }
                path.reverse();
                return path;
            }
            if !came_from.contains_key(w) && *w != start {
                came_from.insert(w.clone(), v.clone());
                queue.push_back(w.clone());
            }
        }
    }
    group.to_vec()
}

/// The workspace's crates: each library, and each binary that has modules of its own.
pub fn workspace(repo: &Path) -> Result<Vec<Crate>, String> {
    [
        ("raylab", "src"),
        ("raylab_base", "base/src"),
        ("raylab_grade", "grade/src"),
        ("grader", "grade/src/bin/grader"),
        ("raylab_bench", "bench/src"),
        ("xtask", "xtask/src"),
    ]
    .iter()
    .map(|(name, dir)| Crate::read(name, &repo.join(dir)))
    .collect()
}

/// `cargo xtask layers`: every folder's layers, bottom first, or the cycles.
pub fn layers() -> Result<(), String> {
    let crates = workspace(crate::repository())?;
    for krate in &crates {
        for line in krate.folder_lines() {
            println!("{line}");
        }
    }
    let cycles: Vec<String> = crates.iter().flat_map(Crate::cycles).map(|c| c.to_string()).collect();
    match cycles.is_empty() {
        true => Ok(()),
        false => Err(format!("cycles between sibling modules:\n{}", cycles.join("\n"))),
    }
}

impl std::fmt::Display for Cycle {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let links: Vec<String> = self
            .parts
            .iter()
            .zip(&self.evidence)
            .map(|(part, file)| format!("{part} (named in {})", file.display()))
            .collect();
        write!(f, "{}: {} -> back to {}", self.folder, links.join(" -> "), self.parts[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn repo() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    #[test]
    fn no_crate_has_a_cycle_between_sibling_modules() {
        let cycles: Vec<String> = workspace(&repo())
            .expect("the workspace parses")
            .iter()
            .flat_map(Crate::cycles)
            .map(|c| c.to_string())
            .collect();
        assert!(cycles.is_empty(), "cycles between sibling modules:\n{}", cycles.join("\n"));
    }

    /// ARCHITECTURE.md's list of layers is what `cargo xtask layers` prints for the tree today.
    #[test]
    fn the_layers_below_are_the_trees() {
        let text = fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
        let block = text.split("<!-- cargo xtask layers -->\n```\n").nth(1).expect("the marked block");
        let listed: Vec<&str> = block.split("```").next().unwrap().lines().collect();
        let crates = workspace(&repo()).unwrap();
        let now: Vec<String> = crates.iter().flat_map(Crate::folder_lines).collect();
        assert_eq!(listed, now, "run `cargo xtask layers` and paste its output into ARCHITECTURE.md");
    }

    /// Writes a small crate into a scratch folder: (relative file, text) pairs.
    fn scratch_crate(name: &str, files: &[(&str, &str)]) -> Crate {
        let root = std::env::temp_dir().join(format!("raylab-layers-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&root);
        for (file, text) in files {
            let path = root.join(file);
            fs::create_dir_all(path.parent().unwrap()).unwrap();
            fs::write(path, text).unwrap();
        }
        let krate = Crate::read(name, &root).unwrap();
        fs::remove_dir_all(&root).unwrap();
        krate
    }

    /// A cycle is found however it is written: a `use`, a path in code, through `super::`, or
    /// through a parent's re-export; test-only code and a module's own parent do not count.
    #[test]
    fn a_cycle_between_siblings_is_found_through_uses_paths_and_reexports() {
        let lib = "mod a;\nmod b;\npub mod c;\npub use c::inner::Deep;\n";
        let direct = scratch_crate(
            "direct",
            &[
                ("lib.rs", lib),
                ("a.rs", "use crate::b::B;\n"),
                ("b.rs", "fn f() { super::a::g(); }\n"),
                ("c/mod.rs", "pub mod inner;\n"),
                ("c/inner.rs", ""),
            ],
        );
        let cycles = direct.cycles();
        assert_eq!(cycles.len(), 1, "{cycles:?}");
        assert_eq!(
            (cycles[0].folder.as_str(), cycles[0].parts.clone()),
            ("direct", vec!["a".into(), "b".into()])
        );

        let through_reexport = scratch_crate(
            "reexport",
            &[
                ("lib.rs", lib),
                ("a.rs", "fn f(_: crate::Deep) {}\n"),
                ("b.rs", ""),
                ("c/mod.rs", "pub mod inner;\n"),
                ("c/inner.rs", "fn g() { crate::a::f; }\n"),
            ],
        );
        assert_eq!(through_reexport.cycles().len(), 1, "a -> c (through lib's re-export) -> a");

        let fine = scratch_crate(
            "fine",
            &[
                ("lib.rs", lib),
                ("a.rs", "use crate::b::B;\n"),
                ("b.rs", "use super::Root;\n#[cfg(test)]\nmod tests { use crate::a::X; }\n"),
                ("c/mod.rs", "pub mod inner;\n"),
                ("c/inner.rs", "use super::super::c::Thing;\n"),
            ],
        );
        assert!(fine.cycles().is_empty(), "{:?}", fine.cycles());
        assert_eq!(fine.layers(&[]), vec![vec!["b".to_string(), "c".to_string()], vec!["a".to_string()]]);
    }
}
