//! Paths in Rust source as far as the floors need them: a small tokenizer that drops comments,
//! string and character literals, `use` trees with their groups expanded, and the module a
//! path names from where it is written (`crate::`, `super::`, `self::` or a child module).
//! Written here rather than taken from a parser crate: the floors read only paths, and a test
//! of the house rules should build with nothing but std.

use std::collections::BTreeSet;

/// What paths are made of; everything else is `Other`.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Ident(String),
    PathSep,
    Open,
    Close,
    Comma,
    Star,
    Other(char),
}

/// The tokens of a source, without comments, string and character literals.
fn tokens(source: &str) -> Vec<Token> {
    let s: Vec<char> = source.chars().collect();
    let at = |i: usize| s.get(i).copied().unwrap_or('\0');
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        if c.is_whitespace() {
            i += 1;
        } else if c == '/' && at(i + 1) == '/' {
            while i < s.len() && s[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < s.len() {
                if s[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if s[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == '"' {
            i = skip_string(&s, i + 1);
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{7f}') or a lifetime or label ('a).
            if at(i + 1) == '\\' {
                i += 2;
                while i < s.len() && s[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(i + 2) == '\'' {
                i += 3;
            } else {
                i += 1;
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < s.len() && (s[i].is_alphanumeric() || s[i] == '_') {
                i += 1;
            }
            let word: String = s[start..i].iter().collect();
            let raw = matches!(word.as_str(), "r" | "br" | "cr");
            if matches!(word.as_str(), "b" | "c") && at(i) == '"' {
                i = skip_string(&s, i + 1);
            } else if raw && (at(i) == '"' || at(i) == '#') {
                let mut hashes = 0;
                while at(i + hashes) == '#' {
                    hashes += 1;
                }
                if at(i + hashes) == '"' {
                    i = skip_raw_string(&s, i + hashes + 1, hashes);
                } else {
                    // A raw identifier (`r#type`): the next word is read on its own.
                    i += hashes;
                }
            } else {
                out.push(Token::Ident(word));
            }
        } else if c.is_ascii_digit() {
            while i < s.len() && (s[i].is_alphanumeric() || s[i] == '_') {
                i += 1;
            }
            out.push(Token::Other('0'));
        } else {
            out.push(match c {
                ':' if at(i + 1) == ':' => {
                    i += 1;
                    Token::PathSep
                }
                '{' => Token::Open,
                '}' => Token::Close,
                ',' => Token::Comma,
                '*' => Token::Star,
                other => Token::Other(other),
            });
            i += 1;
        }
    }
    out
}

/// The index after the string whose body starts at `i`.
fn skip_string(s: &[char], mut i: usize) -> usize {
    while i < s.len() {
        match s[i] {
            '\\' => i += 2,
            '"' => return i + 1,
            _ => i += 1,
        }
    }
    i
}

/// The index after the raw string with `hashes` hashes whose body starts at `i`.
fn skip_raw_string(s: &[char], mut i: usize, hashes: usize) -> usize {
    while i < s.len() {
        if s[i] == '"' && (1..=hashes).all(|k| s.get(i + k) == Some(&'#')) {
            return i + 1 + hashes;
        }
        i += 1;
    }
    i
}

/// A path as written (`a::b::{c, d as e}` gives `a::b::c` and `a::b::d` named `e`).
#[derive(Debug, Clone)]
pub(super) struct WrittenPath {
    pub(super) segments: Vec<String>,
    pub(super) alias: Option<String>,
}

/// The paths of the use tree (or plain path) starting at `toks[*i]`; `*i` moves past it.
fn use_tree(toks: &[Token], i: &mut usize) -> Vec<WrittenPath> {
    let mut prefix = Vec::new();
    loop {
        match toks.get(*i) {
            Some(Token::Ident(name)) => {
                prefix.push(name.clone());
                *i += 1;
            }
            Some(Token::Star) => {
                prefix.push("*".to_string());
                *i += 1;
                break;
            }
            Some(Token::Open) => {
                *i += 1;
                let mut paths = Vec::new();
                while let Some(t) = toks.get(*i) {
                    match t {
                        Token::Close => {
                            *i += 1;
                            break;
                        }
                        Token::Comma => *i += 1,
                        _ => {
                            let before = *i;
                            for mut sub in use_tree(toks, i) {
                                let mut segments = prefix.clone();
                                segments.append(&mut sub.segments);
                                paths.push(WrittenPath {
                                    segments,
                                    alias: sub.alias,
                                });
                            }
                            if *i == before {
                                *i += 1;
                            }
                        }
                    }
                }
                return paths;
            }
            _ => break,
        }
        if toks.get(*i) == Some(&Token::PathSep) {
            *i += 1;
        } else {
            break;
        }
    }
    let mut alias = None;
    if let (Some(Token::Ident(kw)), Some(Token::Ident(name))) = (toks.get(*i), toks.get(*i + 1)) {
        if kw == "as" {
            alias = Some(name.clone());
            *i += 2;
        }
    }
    vec![WrittenPath {
        segments: prefix,
        alias,
    }]
}

/// What a file says about paths: each path with the module it is written in (relative to the
/// file's module: inline `mod x { }` blocks), its inline modules, and what its top level
/// makes public (items and `pub use` re-exports, globs included).
#[derive(Debug, Default)]
pub(super) struct FileScan {
    pub(super) paths: Vec<(Vec<String>, WrittenPath)>,
    pub(super) inline_modules: Vec<Vec<String>>,
    pub(super) public_items: BTreeSet<String>,
    pub(super) reexports: Vec<WrittenPath>,
}

/// The keywords a public item's name follows (`pub fn name`, `pub struct Name`, ...).
const ITEM_KEYWORDS: &[&str] = &[
    "fn", "struct", "enum", "static", "type", "trait", "mod", "union", "const",
];

/// Reads a file's paths, inline modules and public names ([`FileScan`]).
pub(super) fn scan(source: &str) -> FileScan {
    let toks = tokens(source);
    let mut found = FileScan::default();
    let mut depth = 0usize;
    // Inline modules open at the current point, with the depth their body is at.
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let here: Vec<String> = inline.iter().map(|(name, _)| name.clone()).collect();
        match &toks[i] {
            Token::Open => {
                depth += 1;
                i += 1;
            }
            Token::Close => {
                if inline.last().is_some_and(|&(_, d)| d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
            }
            Token::Ident(word) if word == "mod" => {
                if let (Some(Token::Ident(name)), Some(Token::Open)) =
                    (toks.get(i + 1), toks.get(i + 2))
                {
                    let mut module = here.clone();
                    module.push(name.clone());
                    found.inline_modules.push(module);
                    inline.push((name.clone(), depth + 1));
                }
                i += 1;
            }
            Token::Ident(word) if word == "pub" && depth == 0 => {
                let mut j = i + 1;
                if toks.get(j) == Some(&Token::Other('(')) {
                    while j < toks.len() && toks[j] != Token::Other(')') {
                        j += 1;
                    }
                    j += 1;
                }
                while matches!(toks.get(j), Some(Token::Ident(w)) if w == "async" || w == "unsafe")
                {
                    j += 1;
                }
                match (toks.get(j), toks.get(j + 1), toks.get(j + 2)) {
                    (Some(Token::Ident(kw)), _, _) if kw == "use" => {
                        j += 1;
                        for path in use_tree(&toks, &mut j) {
                            found.reexports.push(path.clone());
                            found.paths.push((here.clone(), path));
                        }
                        i = j;
                        continue;
                    }
                    (Some(Token::Ident(kw)), Some(Token::Ident(f)), Some(Token::Ident(name)))
                        if kw == "const" && f == "fn" =>
                    {
                        found.public_items.insert(name.clone());
                    }
                    (Some(Token::Ident(kw)), Some(Token::Ident(name)), _)
                        if ITEM_KEYWORDS.contains(&kw.as_str()) =>
                    {
                        found.public_items.insert(name.clone());
                    }
                    _ => {}
                }
                i += 1;
            }
            Token::Ident(_) if toks.get(i + 1) == Some(&Token::PathSep) => {
                for path in use_tree(&toks, &mut i) {
                    found.paths.push((here.clone(), path));
                }
            }
            _ => i += 1,
        }
    }
    found
}

/// The module `path` names when written in module `current`: `crate::`, `super::`, `self::`
/// or a child of `current` (one of `modules`); `None` for other crates and items in scope.
/// A trailing `self` or `*` names the module before it.
pub(super) fn resolve(
    current: &[String],
    path: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<Vec<String>> {
    let first = path.first()?;
    let mut absolute: Vec<String> = match first.as_str() {
        "crate" => path[1..].to_vec(),
        "self" => [current, &path[1..]].concat(),
        "super" => {
            let up = path.iter().take_while(|s| *s == "super").count();
            let base = current.get(..current.len().checked_sub(up)?)?;
            [base, &path[up..]].concat()
        }
        _ => {
            let mut child = current.to_vec();
            child.push(first.clone());
            if !modules.contains(&child) {
                return None;
            }
            [current, path].concat()
        }
    };
    while absolute.last().is_some_and(|s| s == "self" || s == "*") {
        absolute.pop();
    }
    Some(absolute)
}

/// The name a `use` path binds (`self` binds the module before it).
pub(super) fn exported_name(path: &WrittenPath) -> Option<&str> {
    path.alias.as_deref().or_else(|| {
        path.segments
            .iter()
            .rev()
            .find(|s| *s != "self")
            .map(String::as_str)
    })
}
