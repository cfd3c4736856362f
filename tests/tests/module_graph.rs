//! The workspace's module graph has no circles: no module imports from a
//! module that (directly or through others) imports from it.
//!
//! Each library crate's module tree is read from its `mod` declarations,
//! starting at `lib.rs`. A file depends on a module when it names a path
//! into it (`use` trees, and inline `crate::` / `super::` / `self::` paths
//! in code; comments and `#[cfg(test)]` modules are left out): the edge goes
//! to the deepest module the path names. Circles are the strongly connected
//! components of more than one file (Tarjan's algorithm).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One module file: its path in the crate and the paths it names.
struct ModuleFile {
    path: PathBuf,
    module: Vec<String>,
    children: Vec<String>,
    code: String,
}

/// Drops `//` comments (line and trailing, not inside string literals) and
/// everything from a `#[cfg(test)]` that opens a `mod`.
fn code_of(source: &str) -> String {
    let mut out = String::new();
    let mut lines = source.lines().peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim();
        if trimmed == "#[cfg(test)]"
            && lines
                .peek()
                .is_some_and(|next| next.trim_start().starts_with("mod "))
        {
            break;
        }
        let mut in_string = false;
        let mut kept = String::new();
        let bytes: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < bytes.len() {
            let c = bytes[i];
            if c == '"' && (i == 0 || bytes[i - 1] != '\\') {
                in_string = !in_string;
            }
            if !in_string && c == '/' && bytes.get(i + 1) == Some(&'/') {
                break;
            }
            kept.push(c);
            i += 1;
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// The names of `mod name;` declarations (child modules in their own files).
fn declared_children(code: &str) -> Vec<String> {
    code.lines()
        .filter_map(|l| {
            let l = l.trim();
            let l = l
                .strip_prefix("pub(crate) ")
                .or_else(|| l.strip_prefix("pub "))
                .unwrap_or(l);
            let name = l.strip_prefix("mod ")?.strip_suffix(';')?;
            Some(name.trim().to_string())
        })
        .collect()
}

/// Every module file of the crate whose root file is `root` (`lib.rs`).
fn crate_modules(root: &Path) -> Vec<ModuleFile> {
    let mut out = Vec::new();
    let mut queue = vec![(root.to_path_buf(), Vec::<String>::new())];
    while let Some((path, module)) = queue.pop() {
        let source =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let code = code_of(&source);
        let children = declared_children(&code);
        // Children of lib.rs and mod.rs sit beside them; of a.rs, in a/.
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default();
        let dir = if stem == "lib" || stem == "mod" || stem == "main" {
            path.parent().unwrap().to_path_buf()
        } else {
            path.parent().unwrap().join(stem)
        };
        for child in &children {
            let flat = dir.join(format!("{child}.rs"));
            let nested = dir.join(child).join("mod.rs");
            let file = if flat.exists() { flat } else { nested };
            assert!(file.exists(), "{}: mod {child} has no file", path.display());
            let mut m = module.clone();
            m.push(child.clone());
            queue.push((file, m));
        }
        out.push(ModuleFile {
            path,
            module,
            children,
            code,
        });
    }
    out
}

/// The paths of one `use` tree (`a::{b, c::d as e, self}` -> a::b, a::c::d, a).
fn expand_use_tree(tree: &str) -> Vec<Vec<String>> {
    fn parse(tokens: &[String], pos: &mut usize, prefix: &[String], out: &mut Vec<Vec<String>>) {
        let mut path = prefix.to_vec();
        while *pos < tokens.len() {
            let t = tokens[*pos].as_str();
            match t {
                "{" => {
                    *pos += 1;
                    loop {
                        parse(tokens, pos, &path, out);
                        match tokens.get(*pos).map(String::as_str) {
                            Some(",") => *pos += 1,
                            _ => break,
                        }
                        if tokens.get(*pos).map(String::as_str) == Some("}") {
                            break;
                        }
                    }
                    *pos += 1; // the closing brace
                    return;
                }
                "," | "}" => break,
                "::" => *pos += 1,
                "as" => *pos += 2,
                "self" if path.len() > prefix.len() || !prefix.is_empty() => *pos += 1,
                _ => {
                    path.push(t.to_string());
                    *pos += 1;
                }
            }
        }
        out.push(path);
    }
    let mut tokens = Vec::new();
    let mut word = String::new();
    let chars: Vec<char> = tree.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let flush = |word: &mut String, tokens: &mut Vec<String>| {
            if !word.is_empty() {
                tokens.push(std::mem::take(word));
            }
        };
        if c == ':' && chars.get(i + 1) == Some(&':') {
            flush(&mut word, &mut tokens);
            tokens.push("::".into());
            i += 2;
            continue;
        }
        if c == '{' || c == '}' || c == ',' {
            flush(&mut word, &mut tokens);
            tokens.push(c.to_string());
        } else if c.is_whitespace() {
            flush(&mut word, &mut tokens);
        } else {
            word.push(c);
        }
        i += 1;
    }
    if !word.is_empty() {
        tokens.push(word);
    }
    let mut out = Vec::new();
    let mut pos = 0;
    parse(&tokens, &mut pos, &[], &mut out);
    out
}

/// Every path a file's code names: its `use` trees, and inline paths that
/// start with `crate`, `super` or `self`.
fn named_paths(code: &str) -> Vec<(Vec<String>, bool)> {
    let mut out = Vec::new();
    let mut rest = code;
    let mut outside_use = String::new();
    while let Some(at) = rest.find("use ") {
        let boundary = at == 0
            || !rest.as_bytes()[at - 1].is_ascii_alphanumeric() && rest.as_bytes()[at - 1] != b'_';
        if !boundary {
            outside_use.push_str(&rest[..at + 4]);
            rest = &rest[at + 4..];
            continue;
        }
        outside_use.push_str(&rest[..at]);
        let Some(end) = rest[at..].find(';') else {
            break;
        };
        for path in expand_use_tree(&rest[at + 4..at + end]) {
            out.push((path, true));
        }
        rest = &rest[at + end + 1..];
    }
    outside_use.push_str(rest);
    let chars: Vec<char> = outside_use.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts = |w: &str| outside_use[char_offset(&chars, i)..].starts_with(w);
        let boundary = i == 0
            || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_' || chars[i - 1] == ':');
        if boundary && (starts("crate::") || starts("super::") || starts("self::")) {
            let mut j = i;
            while j < chars.len()
                && (chars[j].is_alphanumeric() || chars[j] == '_' || chars[j] == ':')
            {
                j += 1;
            }
            let text: String = chars[i..j].iter().collect();
            out.push((
                text.split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect(),
                false,
            ));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn char_offset(chars: &[char], i: usize) -> usize {
    chars[..i].iter().map(|c| c.len_utf8()).sum()
}

/// The module a path names from `module` (the deepest existing one), or
/// `None` for a path into another crate.
fn resolve(
    path: &[String],
    in_use: bool,
    module: &[String],
    children: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<Vec<String>> {
    let mut at: Vec<String>;
    let mut segments = path.iter().peekable();
    match segments.peek().map(|s| s.as_str()) {
        Some("crate") => {
            at = Vec::new();
            segments.next();
        }
        Some("super") | Some("self") => {
            at = module.to_vec();
            while let Some(s) = segments.peek() {
                match s.as_str() {
                    "super" => {
                        at.pop();
                    }
                    "self" => {}
                    _ => break,
                }
                segments.next();
            }
        }
        Some(first) if in_use && children.iter().any(|c| c == first) => at = module.to_vec(),
        _ => return None,
    }
    for s in segments {
        let mut next = at.clone();
        next.push(s.clone());
        if modules.contains(&next) {
            at = next;
        } else {
            break;
        }
    }
    Some(at)
}

/// Strongly connected components of more than one node (Tarjan).
fn circles(edges: &BTreeMap<usize, BTreeSet<usize>>, nodes: usize) -> Vec<Vec<usize>> {
    struct Tarjan<'a> {
        edges: &'a BTreeMap<usize, BTreeSet<usize>>,
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    impl Tarjan<'_> {
        fn visit(&mut self, v: usize) {
            self.index[v] = Some(self.next);
            self.low[v] = self.next;
            self.next += 1;
            self.stack.push(v);
            self.on_stack[v] = true;
            for &w in self.edges.get(&v).into_iter().flatten() {
                match self.index[w] {
                    None => {
                        self.visit(w);
                        self.low[v] = self.low[v].min(self.low[w]);
                    }
                    Some(i) if self.on_stack[w] => self.low[v] = self.low[v].min(i),
                    Some(_) => {}
                }
            }
            if Some(self.low[v]) == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    self.out.push(component);
                }
            }
        }
    }
    let mut t = Tarjan {
        edges,
        index: vec![None; nodes],
        low: vec![0; nodes],
        on_stack: vec![false; nodes],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..nodes {
        if t.index[v].is_none() {
            t.visit(v);
        }
    }
    t.out
}

/// The circles of files in the crate at `root` (its `lib.rs`), each as a
/// list of files with what they import from the others.
fn file_circles(root: &Path) -> Vec<String> {
    let files = crate_modules(root);
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| f.module.clone()).collect();
    let by_module: BTreeMap<Vec<String>, usize> = files
        .iter()
        .enumerate()
        .map(|(i, f)| (f.module.clone(), i))
        .collect();
    let mut edges: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
    for (i, f) in files.iter().enumerate() {
        for (path, in_use) in named_paths(&f.code) {
            if let Some(target) = resolve(&path, in_use, &f.module, &f.children, &modules) {
                let j = by_module[&target];
                if j != i {
                    edges.entry(i).or_default().insert(j);
                }
            }
        }
    }
    circles(&edges, files.len())
        .into_iter()
        .map(|c| {
            let mut names: Vec<String> = c
                .iter()
                .map(|&i| files[i].path.display().to_string())
                .collect();
            names.sort();
            names.join(" <-> ")
        })
        .collect()
}

/// The edges of the crate at `root` that point from a room (a module
/// declared in `lib.rs`) to a room declared after it: `lib.rs` lists its
/// rooms from the bottom up, and a room may import only from rooms above
/// it in that list.
fn room_back_arrows(root: &Path) -> Vec<String> {
    let files = crate_modules(root);
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| f.module.clone()).collect();
    let lib = files
        .iter()
        .find(|f| f.module.is_empty())
        .expect("the crate root is read");
    let rank: BTreeMap<&str, usize> = lib
        .children
        .iter()
        .enumerate()
        .map(|(i, room)| (room.as_str(), i))
        .collect();
    let mut found = BTreeSet::new();
    for f in &files {
        let Some(from) = f.module.first() else {
            continue;
        };
        for (path, in_use) in named_paths(&f.code) {
            let Some(target) = resolve(&path, in_use, &f.module, &f.children, &modules) else {
                continue;
            };
            if let Some(to) = target.first() {
                if rank[to.as_str()] > rank[from.as_str()] {
                    found.insert(format!(
                        "{} (room {from}) imports {} (room {to}, declared after it)",
                        f.path.display(),
                        target.join("::")
                    ));
                }
            }
        }
    }
    found.into_iter().collect()
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn no_module_of_any_crate_imports_from_a_module_that_imports_from_it() {
    let mut found = Vec::new();
    for krate in ["shared", "sim", "host", "firmware", "tests", "python"] {
        let root = workspace_root().join(krate).join("src").join("lib.rs");
        found.extend(file_circles(&root));
    }
    assert!(found.is_empty(), "circles of files:\n{}", found.join("\n"));
}

#[test]
fn the_checker_finds_a_circle_through_a_re_export() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::write(
        src.join("lib.rs"),
        "pub mod a;\npub mod b;\npub use a::A;\n",
    )
    .unwrap();
    std::fs::write(src.join("a.rs"), "use crate::b::B;\npub struct A(B);\n").unwrap();
    std::fs::write(
        src.join("b.rs"),
        "// use crate::A; is only a comment\npub struct B;\n",
    )
    .unwrap();
    assert!(file_circles(&src.join("lib.rs")).is_empty());
    std::fs::write(src.join("b.rs"), "pub struct B(Box<crate::A>);\n").unwrap();
    let found = file_circles(&src.join("lib.rs"));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].contains("a.rs") && found[0].contains("lib.rs") && found[0].contains("b.rs"),
        "{found:?}"
    );
    // A nested use tree with self and a rename.
    std::fs::write(
        src.join("b.rs"),
        "use super::{a::{self as x, A}};\npub struct B;\n",
    )
    .unwrap();
    assert_eq!(file_circles(&src.join("lib.rs")).len(), 1);
}

#[test]
fn each_room_of_the_simulator_imports_only_from_the_rooms_below_it() {
    let root = workspace_root().join("sim").join("src").join("lib.rs");
    let found = room_back_arrows(&root);
    assert!(found.is_empty(), "back arrows:\n{}", found.join("\n"));
}

#[test]
fn the_simulator_keeps_at_most_twelve_entries_at_its_top_level() {
    let src = workspace_root().join("sim").join("src");
    let entries: Vec<String> = std::fs::read_dir(&src)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        entries.len() <= 12,
        "sim/src has {} entries: {entries:?}",
        entries.len()
    );
}

#[test]
fn the_room_checker_finds_an_import_from_a_later_room() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::write(src.join("lib.rs"), "pub mod low;\npub mod high;\n").unwrap();
    std::fs::write(
        src.join("high.rs"),
        "use crate::low::L;\npub struct H(L);\n",
    )
    .unwrap();
    std::fs::write(src.join("low.rs"), "pub struct L;\n").unwrap();
    assert!(room_back_arrows(&src.join("lib.rs")).is_empty());
    std::fs::write(src.join("low.rs"), "pub struct L(Box<crate::high::H>);\n").unwrap();
    let found = room_back_arrows(&src.join("lib.rs"));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].contains("room low") && found[0].contains("room high"),
        "{found:?}"
    );
}
