//! No import circle between the source files of the engine (`sim/src`), the SIL runner
//! (`sim/sil/src`) and the command line (`sim/cli/src`).
//!
//! Each crate's files are read as plain text (no compiler, no cargo): the module tree from its
//! root's `mod x;` declarations (`mod` is not an import), then every `use` item and every path
//! in code that starts with `crate::`, `super::`, `self::` or a child module's name, resolved
//! to the file that *defines* the item: a `use` or `pub use` of the module the path passes
//! through is followed transparently (a re-export in a `mod.rs` or `lib.rs` is not where an
//! item lives). The files and those edges make a graph; every strongly connected component of
//! more than one file (Tarjan) is an import circle, and the test lists them all, with the
//! paths that make each edge.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The crates checked: their source folders, relative to the `sim` package.
const SOURCE_DIRS: [&str; 3] = ["src", "sil/src", "cli/src"];

/// The source files of a crate, by path.
type Files = BTreeMap<PathBuf, String>;

// ---------------------------------------------------------------------------------------------
// Lexing: comments and literals blanked, then identifiers, `::` and punctuation.

#[derive(Clone, Debug, PartialEq, Eq)]
enum Token {
    Ident(String),
    PathSep,
    Punct(char),
}

/// `source` with comments, string and character literals replaced by spaces (lifetimes kept).
fn blank_comments_and_literals(source: &str) -> Vec<char> {
    let c: Vec<char> = source.chars().collect();
    let mut out = Vec::with_capacity(c.len());
    let mut i = 0;
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    while i < c.len() {
        if at(i) == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if at(i) == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            loop {
                if i >= c.len() {
                    break;
                }
                if at(i) == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if at(i) == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if let Some(len) = raw_string_len(&c, i) {
            i += len;
            out.push(' ');
        } else if at(i) == '"' || (at(i) == 'b' && at(i + 1) == '"' && !ident_char(prev(&c, i))) {
            i += if at(i) == 'b' { 2 } else { 1 };
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push(' ');
        } else if at(i) == '\'' && at(i + 1) == '\\' {
            i += 2;
            while i < c.len() && c[i] != '\'' {
                i += 1;
            }
            i += 1;
            out.push(' ');
        } else if at(i) == '\'' && at(i + 2) == '\'' {
            i += 3;
            out.push(' ');
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn prev(c: &[char], i: usize) -> char {
    if i == 0 {
        '\0'
    } else {
        c[i - 1]
    }
}

fn ident_char(ch: char) -> bool {
    ch.is_alphanumeric() || ch == '_'
}

/// The length of a raw (byte) string literal starting at `i` (`r"…"`, `r#"…"#`, `br"…"`).
fn raw_string_len(c: &[char], i: usize) -> Option<usize> {
    if ident_char(prev(c, i)) {
        return None;
    }
    let mut j = i;
    if c.get(j) == Some(&'b') {
        j += 1;
    }
    if c.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let mut hashes = 0;
    while c.get(j) == Some(&'#') {
        hashes += 1;
        j += 1;
    }
    if c.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < c.len() {
        if c[j] == '"' && (1..=hashes).all(|k| c.get(j + k) == Some(&'#')) {
            return Some(j + 1 + hashes - i);
        }
        j += 1;
    }
    Some(c.len() - i)
}

fn tokens(source: &str) -> Vec<Token> {
    let c = blank_comments_and_literals(source);
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch == 'r' && c.get(i + 1) == Some(&'#') && c.get(i + 2).is_some_and(|&n| ident_char(n)) {
            i += 2;
            continue;
        }
        if ident_char(ch) {
            let start = i;
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            out.push(Token::Ident(c[start..i].iter().collect()));
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            out.push(Token::PathSep);
            i += 2;
        } else {
            if !ch.is_whitespace() {
                out.push(Token::Punct(ch));
            }
            i += 1;
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// One file's declarations: modules, items, `use` trees and paths, per (inline) module.

/// One leaf of a `use` tree: the path and the name it binds (`None` for a glob).
#[derive(Clone, Debug, PartialEq, Eq)]
struct UseLeaf {
    path: Vec<String>,
    binds: Option<String>,
}

/// A path a module's text refers to.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Reference {
    path: Vec<String>,
    /// A re-export (`pub use`) is no dependency of the module that states it unless its own
    /// code names what it binds: this name (`None`: a private `use` or a path in code, always
    /// a dependency).
    only_if_named: Option<String>,
}

/// What one module (a file, or an inline `mod x { … }` in it) declares.
#[derive(Clone, Debug, Default)]
struct ModuleText {
    /// `mod x;` declarations (modules in their own files).
    file_children: BTreeSet<String>,
    /// `mod x { … }` declarations (inline modules, in the same file).
    inline_children: BTreeSet<String>,
    /// Items defined at the module's top level (fn, struct, enum, trait, type, const, …).
    items: BTreeSet<String>,
    /// `use` leaves at the module's top level (they bind names in the module).
    scope: Vec<UseLeaf>,
    /// Every path this module's text refers to: all `use` leaves (also those in function
    /// bodies), and paths in code that start with `crate`, `super`, `self` or a child
    /// module.
    references: Vec<Reference>,
    /// The identifiers of the module's code outside `use` items.
    code_idents: BTreeSet<String>,
    /// Compiled for tests only (`#[cfg(test)] mod …`): its imports are the tests', not the
    /// file's.
    cfg_test: bool,
}

/// A file's modules, keyed by the inline path inside the file (`[]`: the file's module).
type FileText = BTreeMap<Vec<String>, ModuleText>;

const ITEM_KEYWORDS: [&str; 8] = [
    "fn", "struct", "enum", "trait", "type", "const", "static", "union",
];

fn ident(t: Option<&Token>) -> Option<&str> {
    match t {
        Some(Token::Ident(s)) => Some(s),
        _ => None,
    }
}

/// Parses a `use` tree at `tokens[*i]` under `prefix`, appending its leaves.
fn use_tree(tokens: &[Token], i: &mut usize, prefix: Vec<String>, out: &mut Vec<UseLeaf>) {
    let mut path = prefix;
    if tokens.get(*i) == Some(&Token::PathSep) {
        *i += 1;
        path.push("::".into());
    }
    loop {
        match tokens.get(*i) {
            Some(Token::Ident(s)) if s != "as" => {
                path.push(s.clone());
                *i += 1;
                if tokens.get(*i) == Some(&Token::PathSep) {
                    *i += 1;
                    continue;
                }
                break;
            }
            Some(Token::Punct('{')) => {
                *i += 1;
                loop {
                    match tokens.get(*i) {
                        None => return,
                        Some(Token::Punct('}')) => {
                            *i += 1;
                            return;
                        }
                        Some(Token::Punct(',')) => *i += 1,
                        _ => {
                            let before = *i;
                            use_tree(tokens, i, path.clone(), out);
                            if *i == before {
                                *i += 1;
                            }
                        }
                    }
                }
            }
            Some(Token::Punct('*')) => {
                *i += 1;
                out.push(UseLeaf { path, binds: None });
                return;
            }
            _ => break,
        }
    }
    if path.last().is_some_and(|s| s == "self") {
        path.pop();
    }
    let mut binds = path.last().cloned();
    if ident(tokens.get(*i)) == Some("as") {
        binds = ident(tokens.get(*i + 1)).map(str::to_string);
        *i += 2;
    }
    if binds.as_deref() == Some("_") {
        binds = None;
    }
    if !path.is_empty() {
        out.push(UseLeaf { path, binds });
    }
}

/// Whether the item whose keyword is at `tokens[i]` (after its visibility) has a
/// `#[cfg(test)]` attribute.
fn is_cfg_test(tokens: &[Token], i: usize) -> bool {
    let mut j = i;
    // Over the visibility: `pub`, `pub(crate)`, `pub(super)`, `pub(in …)`.
    if j >= 1 && tokens[j - 1] == Token::Punct(')') {
        while j >= 1 && tokens[j - 1] != Token::Punct('(') {
            j -= 1;
        }
        j = j.saturating_sub(1);
    }
    if j >= 1 && ident(tokens.get(j - 1)) == Some("pub") {
        j -= 1;
    }
    // Over the attributes `#[…]`, last first.
    while j >= 1 && tokens[j - 1] == Token::Punct(']') {
        let end = j - 1;
        let mut k = end;
        let mut depth = 0;
        loop {
            match tokens[k] {
                Token::Punct(']') => depth += 1,
                Token::Punct('[') => depth -= 1,
                _ => {}
            }
            if depth == 0 || k == 0 {
                break;
            }
            k -= 1;
        }
        let attribute: Vec<&Token> = tokens[k + 1..end].iter().collect();
        let cfg_test = [
            Token::Ident("cfg".into()),
            Token::Punct('('),
            Token::Ident("test".into()),
            Token::Punct(')'),
        ];
        if attribute.iter().copied().eq(cfg_test.iter()) {
            return true;
        }
        if k == 0 || tokens[k - 1] != Token::Punct('#') {
            return false;
        }
        j = k - 1;
    }
    false
}

/// Whether the `use` at `tokens[i]` is `pub` or `pub(…)`.
fn is_public(tokens: &[Token], i: usize) -> bool {
    let mut j = i;
    if j >= 1 && tokens[j - 1] == Token::Punct(')') {
        while j >= 1 && tokens[j - 1] != Token::Punct('(') {
            j -= 1;
        }
        j = j.saturating_sub(1);
    }
    j >= 1 && ident(tokens.get(j - 1)) == Some("pub")
}

/// The modules, items, `use` leaves and paths of one file's text.
fn parse_file(source: &str) -> FileText {
    let t = tokens(source);
    let mut file = FileText::new();
    file.insert(Vec::new(), ModuleText::default());
    // (inline module path, brace depth of its body) innermost last.
    let mut stack: Vec<(Vec<String>, usize)> = vec![(Vec::new(), 0)];
    let mut depth = 0usize;
    let mut i = 0;
    while i < t.len() {
        let (module, body_depth) = stack.last().cloned().unwrap();
        let top_level = depth == body_depth;
        match &t[i] {
            Token::Punct('{') => {
                depth += 1;
                i += 1;
            }
            Token::Punct('}') => {
                if depth == body_depth && stack.len() > 1 {
                    stack.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
            }
            Token::Ident(k) if k == "mod" && ident(t.get(i + 1)).is_some() => {
                let name = ident(t.get(i + 1)).unwrap().to_string();
                let cfg_test = is_cfg_test(&t, i) || file[&module].cfg_test;
                let entry = file.get_mut(&module).unwrap();
                if t.get(i + 2) == Some(&Token::Punct('{')) {
                    entry.inline_children.insert(name.clone());
                    let mut inner = module.clone();
                    inner.push(name);
                    file.entry(inner.clone()).or_default().cfg_test = cfg_test;
                    depth += 1;
                    stack.push((inner, depth));
                    i += 3;
                } else {
                    if !cfg_test {
                        entry.file_children.insert(name);
                    }
                    i += 2;
                }
            }
            Token::Ident(k) if k == "use" && is_cfg_test(&t, i) => i += 1,
            Token::Ident(k) if k == "use" => {
                let public = is_public(&t, i);
                i += 1;
                let mut leaves = Vec::new();
                use_tree(&t, &mut i, Vec::new(), &mut leaves);
                let entry = file.get_mut(&module).unwrap();
                entry.references.extend(leaves.iter().map(|l| Reference {
                    path: l.path.clone(),
                    only_if_named: public.then(|| l.binds.clone().unwrap_or_else(|| "*".into())),
                }));
                if top_level {
                    entry.scope.extend(leaves);
                }
            }
            Token::Ident(k) if top_level && ITEM_KEYWORDS.contains(&k.as_str()) => {
                if let Some(name) = ident(t.get(i + 1)) {
                    file.get_mut(&module)
                        .unwrap()
                        .items
                        .insert(name.to_string());
                }
                i += 1;
            }
            Token::Ident(k) if k == "macro_rules" && t.get(i + 1) == Some(&Token::Punct('!')) => {
                if let Some(name) = ident(t.get(i + 2)) {
                    file.get_mut(&module)
                        .unwrap()
                        .items
                        .insert(name.to_string());
                }
                i += 2;
            }
            Token::Ident(first)
                if t.get(i + 1) == Some(&Token::PathSep)
                    && t.get(i.wrapping_sub(1)) != Some(&Token::PathSep) =>
            {
                let entry = file.get_mut(&module).unwrap();
                let relevant = matches!(first.as_str(), "crate" | "super" | "self")
                    || entry.file_children.contains(first)
                    || entry.inline_children.contains(first);
                let mut path = vec![first.clone()];
                i += 1;
                while t.get(i) == Some(&Token::PathSep) {
                    match ident(t.get(i + 1)) {
                        Some(s) => {
                            path.push(s.to_string());
                            i += 2;
                        }
                        None => break,
                    }
                }
                entry.code_idents.extend(path.iter().cloned());
                if relevant {
                    entry.references.push(Reference {
                        path,
                        only_if_named: None,
                    });
                }
            }
            Token::Ident(name) => {
                file.get_mut(&module)
                    .unwrap()
                    .code_idents
                    .insert(name.clone());
                i += 1;
            }
            _ => i += 1,
        }
    }
    file
}

// ---------------------------------------------------------------------------------------------
// A crate: its module tree, and paths resolved to the files that define their items.

struct Module {
    file: PathBuf,
    text: ModuleText,
}

struct Crate {
    modules: HashMap<Vec<String>, Module>,
}

/// The file of module `name` declared in `parent` (`mod name;`): `name.rs` or
/// `name/mod.rs` beside a `mod.rs`, `lib.rs` or `main.rs`, else in the folder named after
/// `parent` (with the inline modules between as folders).
fn child_file(files: &Files, parent: &Path, inline: &[String], name: &str) -> Option<PathBuf> {
    let stem = parent.file_stem()?.to_str()?;
    let mut dir = parent.parent()?.to_path_buf();
    if !matches!(stem, "mod" | "lib" | "main") {
        dir.push(stem);
    }
    for m in inline {
        dir.push(m);
    }
    [
        dir.join(format!("{name}.rs")),
        dir.join(name).join("mod.rs"),
    ]
    .into_iter()
    .find(|p| files.contains_key(p))
}

impl Crate {
    /// The crate rooted at `root` (a `lib.rs` or `main.rs` among `files`).
    fn load(files: &Files, root: &Path) -> Self {
        let mut modules = HashMap::new();
        let mut pending = vec![(Vec::<String>::new(), root.to_path_buf())];
        while let Some((path, file)) = pending.pop() {
            let Some(source) = files.get(&file) else {
                continue;
            };
            for (inline, text) in parse_file(source) {
                if text.cfg_test {
                    continue;
                }
                for child in &text.file_children {
                    if let Some(f) = child_file(files, &file, &inline, child) {
                        let mut p = path.clone();
                        p.extend(inline.iter().cloned());
                        p.push(child.clone());
                        pending.push((p, f));
                    }
                }
                let mut p = path.clone();
                p.extend(inline);
                modules.insert(
                    p,
                    Module {
                        file: file.clone(),
                        text,
                    },
                );
            }
        }
        Self { modules }
    }

    fn is_module(&self, m: &[String]) -> bool {
        self.modules.contains_key(m)
    }

    /// The file that defines what `path` (written in module `context`) names, or `None` for
    /// another crate's item.
    fn resolve(&self, context: &[String], path: &[String], depth: usize) -> Option<PathBuf> {
        if depth > 32 || path.is_empty() {
            return None;
        }
        let mut module: Vec<String> = context.to_vec();
        let mut rest = path;
        match rest[0].as_str() {
            "::" => return None,
            "crate" => {
                module.clear();
                rest = &rest[1..];
            }
            "self" => rest = &rest[1..],
            "super" => {
                while rest.first().is_some_and(|s| s == "super") {
                    module.pop()?;
                    rest = &rest[1..];
                }
            }
            _ => {}
        }
        self.lookup(&module, rest, depth)
    }

    /// The file defining `rest` looked up in `module`.
    fn lookup(&self, module: &[String], rest: &[String], depth: usize) -> Option<PathBuf> {
        let m = self.modules.get(module)?;
        let Some((name, after)) = rest.split_first() else {
            return Some(m.file.clone());
        };
        let mut child = module.to_vec();
        child.push(name.clone());
        if !after.is_empty() && self.is_module(&child) {
            return self.lookup(&child, after, depth + 1);
        }
        if m.text.items.contains(name) {
            return Some(m.file.clone());
        }
        for leaf in &m.text.scope {
            if leaf.binds.as_ref() == Some(name) {
                let mut p = leaf.path.clone();
                p.extend(after.iter().cloned());
                return self.resolve(module, &p, depth + 1);
            }
        }
        if self.is_module(&child) {
            return self.lookup(&child, after, depth + 1);
        }
        // Globs of this crate's modules only (another crate's glob cannot name our items).
        for leaf in m.text.scope.iter().filter(|l| {
            l.binds.is_none()
                && l.path.first().is_some_and(|s| {
                    matches!(s.as_str(), "crate" | "self" | "super")
                        || self.is_module(&[module, std::slice::from_ref(s)].concat())
                })
        }) {
            let mut p = leaf.path.clone();
            p.extend(rest.iter().cloned());
            let target = self.resolve(module, &p, depth + 1);
            if target.is_some() {
                return target;
            }
        }
        None
    }

    /// Every edge `(from file, to file)` of the crate, with the first path that made it.
    fn edges(&self) -> BTreeMap<(PathBuf, PathBuf), String> {
        let mut out = BTreeMap::new();
        for (path, m) in &self.modules {
            for r in &m.text.references {
                if let Some(name) = &r.only_if_named {
                    if !m.text.code_idents.contains(name) {
                        continue;
                    }
                }
                // (A glob is a dependency on the module it reads.)
                if let Some(to) = self.resolve(path, &r.path, 0) {
                    if to != m.file {
                        out.entry((m.file.clone(), to))
                            .or_insert_with(|| r.path.join("::"));
                    }
                }
            }
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// Tarjan's strongly connected components.

/// The strongly connected components of more than one node of the graph `edges`.
fn cycles(edges: &BTreeMap<(PathBuf, PathBuf), String>) -> Vec<Vec<PathBuf>> {
    let mut nodes: Vec<&PathBuf> = edges.keys().flat_map(|(a, b)| [a, b]).collect();
    nodes.sort();
    nodes.dedup();
    let index_of: HashMap<&PathBuf, usize> =
        nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let mut next: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for (a, b) in edges.keys() {
        next[index_of[a]].push(index_of[b]);
    }
    struct State {
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        counter: usize,
        components: Vec<Vec<usize>>,
    }
    fn visit(v: usize, next: &[Vec<usize>], s: &mut State) {
        s.index[v] = Some(s.counter);
        s.low[v] = s.counter;
        s.counter += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in &next[v] {
            match s.index[w] {
                None => {
                    visit(w, next, s);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            s.components.push(component);
        }
    }
    let n = nodes.len();
    let mut s = State {
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        counter: 0,
        components: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(v, &next, &mut s);
        }
    }
    let mut out: Vec<Vec<PathBuf>> = s
        .components
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut files: Vec<PathBuf> = c.into_iter().map(|i| nodes[i].clone()).collect();
            files.sort();
            files
        })
        .collect();
    out.sort();
    out
}

/// The import circles of the crates rooted at `roots` among `files`, described one per
/// entry: the files and the edges between them.
fn import_circles(files: &Files, roots: &[PathBuf]) -> Vec<String> {
    let mut edges = BTreeMap::new();
    for root in roots {
        edges.extend(Crate::load(files, root).edges());
    }
    cycles(&edges)
        .into_iter()
        .map(|component| {
            let members: BTreeSet<&PathBuf> = component.iter().collect();
            let mut text = format!(
                "{{{}}}:",
                component
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            for ((a, b), via) in &edges {
                if members.contains(a) && members.contains(b) {
                    text.push_str(&format!(
                        "\n    {} -> {} (`{via}`)",
                        a.display(),
                        b.display()
                    ));
                }
            }
            text
        })
        .collect()
}

fn read_rs_files(dir: &Path, base: &Path, out: &mut Files) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            read_rs_files(&path, base, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            out.insert(path.strip_prefix(base).unwrap().to_path_buf(), text);
        }
    }
}

#[test]
fn no_import_circle_in_the_engine_the_sil_runner_or_the_command_line() {
    let package = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Files::new();
    let mut roots = Vec::new();
    for dir in SOURCE_DIRS {
        read_rs_files(&package.join(dir), package, &mut files);
        for root in ["lib.rs", "main.rs"] {
            let p = Path::new(dir).join(root);
            if files.contains_key(&p) {
                roots.push(p);
            }
        }
    }
    assert!(roots.len() >= 3, "found the crate roots: {roots:?}");
    let circles = import_circles(&files, &roots);
    assert!(
        circles.is_empty(),
        "{} import circle(s) (strongly connected components of the file graph):\n{}",
        circles.len(),
        circles.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// The detector on small trees.

fn tree(files: &[(&str, &str)]) -> Files {
    files
        .iter()
        .map(|(p, s)| (PathBuf::from(p), s.to_string()))
        .collect()
}

fn circles_of(files: &[(&str, &str)]) -> Vec<String> {
    import_circles(&tree(files), &[PathBuf::from("src/lib.rs")])
}

#[test]
fn a_planted_circle_through_a_re_export_is_found() {
    let circles = circles_of(&[
        ("src/lib.rs", "pub mod a;\npub mod b;\n"),
        (
            "src/a/mod.rs",
            "mod inner;\npub use inner::{Thing, other as renamed};\n",
        ),
        (
            "src/a/inner.rs",
            "use crate::b::helper;\npub struct Thing;\npub fn other() {}\n",
        ),
        (
            "src/b.rs",
            "use crate::a::Thing;\npub fn helper() -> Thing { Thing }\n",
        ),
    ]);
    assert_eq!(circles.len(), 1, "{circles:?}");
    assert!(
        circles[0].starts_with("{src/a/inner.rs, src/b.rs}"),
        "the re-export in a/mod.rs is not where Thing lives: {circles:?}"
    );
}

#[test]
fn a_tree_without_a_circle_passes() {
    let circles = circles_of(&[
        ("src/lib.rs", "pub mod a;\npub mod b;\npub mod c;\n"),
        (
            "src/a/mod.rs",
            "mod inner;\npub use inner::Thing;\n/// [`crate::b::helper`]\npub fn f() { let _ = \"crate::b::helper\"; }\n",
        ),
        // A unit test may use anything: its imports are not the file's.
        (
            "src/a/inner.rs",
            "pub struct Thing;\n#[cfg(test)]\nmod tests {\n    use crate::b::helper;\n}\n",
        ),
        // b imports from a; a names b only in a comment and a string; c uses b in code.
        (
            "src/b.rs",
            "use crate::a::Thing;\npub fn helper() -> Thing { Thing }\n#[cfg(test)]\nmod tests { use super::*; }\n",
        ),
        ("src/c.rs", "pub fn g() { crate::b::helper(); super::a::f(); }\n"),
    ]);
    assert!(circles.is_empty(), "{circles:?}");
}

#[test]
fn circles_through_code_paths_nested_groups_and_child_modules_are_found() {
    let circles = circles_of(&[
        ("src/lib.rs", "pub mod x;\npub mod y;\npub mod z;\n"),
        ("src/x.rs", "mod sub;\npub fn top() { sub::deep(); }\n"),
        ("src/x/sub.rs", "pub fn deep() { crate::y::f(); }\n"),
        (
            "src/y.rs",
            "use crate::{z::{self, Z as Zed}};\npub fn f() { z::g(); }\n",
        ),
        (
            "src/z.rs",
            "pub struct Z;\npub fn g() { super::x::top(); }\n",
        ),
    ]);
    assert_eq!(circles.len(), 1, "{circles:?}");
    for edge in [
        "src/x.rs -> src/x/sub.rs (`sub::deep`)",
        "src/x/sub.rs -> src/y.rs (`crate::y::f`)",
        "src/y.rs -> src/z.rs (`crate::z`)",
        "src/z.rs -> src/x.rs (`super::x::top`)",
    ] {
        assert!(circles[0].contains(edge), "{edge} in {circles:?}");
    }
}

#[test]
fn mod_declarations_and_other_crates_are_not_imports() {
    let circles = circles_of(&[
        ("src/lib.rs", "pub mod p;\nuse nalgebra::DVector;\n"),
        ("src/p.rs", "use crate::lib_item;\nuse std::fmt;\n"),
    ]);
    assert!(circles.is_empty(), "{circles:?}");
}
