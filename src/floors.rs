//! The house rules of the source tree, checked on the files themselves (ARCHITECTURE.md,
//! "Floors"): every top-level module is a room on a floor, a room imports only rooms on lower
//! floors (so the import graph has no cycle and no arrow running up), and a source file over
//! 700 lines says at its top why it is that long.
//!
//! An import is any `crate::<room>` path or a `use crate::{<room>, ...}` group outside a
//! comment: doc links (`[`crate::report`]`) name a room without depending on it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Rooms from the lowest floor up. Rooms on one floor import nothing from each other.
pub(crate) const FLOORS: &[&[&str]] = &[
    &["units", "field_error", "thesis", "sampling"],
    &["geometry"],
    &["physics"],
    &["wear"],
    &["contact_models"],
    &["analysis"],
    &["excitation"],
    &["models"],
    &["report"],
    &["service_life"],
    &["pipeline"],
    &["validation"],
    &["gap"],
    &["store"],
    &["jobs"],
    &["config"],
    &["http"],
    &["cli"],
];

/// Lines a source file may have before it must say why at its top.
const LONG_FILE_LINES: usize = 700;
/// The words a long file's header uses to say why.
const LONG_FILE_REASON: &str = "Over 700 lines";

fn floor_of(room: &str) -> Option<usize> {
    FLOORS.iter().position(|floor| floor.contains(&room))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source without comments (line comments and doc comments; block comments are not used).
fn code_only(source: &str) -> String {
    source
        .lines()
        .map(|line| match line.find("//") {
            // A `//` inside a string literal (a URL) is rare in paths that matter here; the
            // rest of such a line holds no import.
            Some(at) => &line[..at],
            None => line,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifier `s` starts with, if any.
fn leading_name(s: &str) -> Option<String> {
    let name: String = s
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then_some(name)
}

/// Rooms a piece of code imports: `crate::room` and `use crate::{room, ...}`.
fn imported_rooms(code: &str) -> Vec<String> {
    let mut rooms = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // The group ends at its matching brace (groups nest: `physics::{a, b}`).
            let mut depth = 0;
            let end = group
                .char_indices()
                .find(|&(_, c)| {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => return true,
                        '}' => depth -= 1,
                        _ => {}
                    }
                    false
                })
                .map_or(group.len(), |(i, _)| i);
            // Top-level entries of the group: names before `::` at depth zero.
            let mut start = 0;
            let inner = &group[..end];
            for (i, c) in inner
                .char_indices()
                .chain(std::iter::once((inner.len(), ',')))
            {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        rooms.extend(leading_name(inner[start..i].trim()));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            rooms.extend(leading_name(rest));
        }
    }
    rooms
}

/// The room a file under `src/` belongs to (`None` for the crate root, `main.rs` and `bin/`,
/// which sit above every floor).
fn room_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    let room = first.strip_suffix(".rs").unwrap_or(first);
    match room {
        "lib" | "main" | "bin" | "floors" => None,
        other => Some(other.to_string()),
    }
}

/// Every arrow of the import graph: (from room, to room) -> files that import.
fn import_graph(src: &Path) -> BTreeMap<(String, String), Vec<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut arrows: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
    for file in files {
        let Some(from) = room_of(src, &file) else {
            continue;
        };
        let Ok(source) = std::fs::read_to_string(&file) else {
            continue;
        };
        for to in imported_rooms(&code_only(&source)) {
            if to != from && to != "self" {
                let rel = file
                    .strip_prefix(src)
                    .unwrap_or(&file)
                    .display()
                    .to_string();
                let files = arrows.entry((from.clone(), to)).or_default();
                if !files.contains(&rel) {
                    files.push(rel);
                }
            }
        }
    }
    arrows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn src() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
    }

    #[test]
    fn every_room_has_a_floor_and_imports_only_lower_floors() {
        let arrows = import_graph(&src());
        assert!(
            arrows.len() > 30,
            "the scan found only {} arrows: it no longer reads the tree",
            arrows.len()
        );
        let mut wrong = Vec::new();
        for ((from, to), files) in &arrows {
            match (floor_of(from), floor_of(to)) {
                (Some(a), Some(b)) if b < a => {}
                (Some(_), Some(_)) => {
                    wrong.push(format!("{from} -> {to} (up or sideways) in {files:?}"))
                }
                _ => wrong.push(format!(
                    "{from} -> {to}: a room without a floor in FLOORS ({files:?})"
                )),
            }
        }
        assert!(
            wrong.is_empty(),
            "arrows against the floors:\n{}",
            wrong.join("\n")
        );
    }

    #[test]
    fn the_scan_sees_grouped_and_nested_imports() {
        let code = code_only(
            "use crate::{geometry::x, physics::{a, b}, units};\n\
             /// [`crate::http`] is a doc link\n\
             let v = crate::wear::law(1); // crate::jobs in a comment",
        );
        let mut rooms = imported_rooms(&code);
        rooms.sort();
        assert_eq!(rooms, ["geometry", "physics", "units", "wear"]);
    }

    #[test]
    fn long_files_say_why() {
        let mut files = Vec::new();
        rust_files(&src(), &mut files);
        let mut unexplained = Vec::new();
        for file in files {
            let Ok(source) = std::fs::read_to_string(&file) else {
                continue;
            };
            let lines = source.lines().count();
            let header: String = source.lines().take(40).collect::<Vec<_>>().join("\n");
            if lines > LONG_FILE_LINES && !header.contains(LONG_FILE_REASON) {
                unexplained.push(format!("{} ({lines} lines)", file.display()));
            }
        }
        assert!(
            unexplained.is_empty(),
            "files over {LONG_FILE_LINES} lines without \"{LONG_FILE_REASON}\" and a reason \
             in their first 40 lines:\n{}",
            unexplained.join("\n")
        );
    }
}
