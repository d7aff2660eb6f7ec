//! The house rules of the source tree, checked on the files themselves (ARCHITECTURE.md,
//! "Floors"): every top-level module is a room on a floor, a room imports only rooms on lower
//! floors (so the import graph has no cycle and no arrow running up), the sub-rooms of a room
//! (its files and folders, at every depth) import each other without a circle, and a source
//! file over 700 lines says at its top why it is that long.
//!
//! An import is any path from `crate::`, `super::`, `self::` or a child module, `use` groups
//! expanded, outside comments and string literals: doc links (`[`crate::report`]`) name a room
//! without depending on it. Paths are resolved to the module they start from, so
//! `super::outcome` in `models/launcher/mod.rs` is `crate::models::outcome`.
//!
//! The long-file rule covers the integration tests too (`tests/`): a test file is read as
//! often as the code it checks.

mod paths;

use paths::{exported_name, resolve, scan, FileScan};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// Rooms from the lowest floor up. Rooms on one floor import nothing from each other.
pub(crate) const FLOORS: &[&[&str]] = &[
    &["units", "field_error", "thesis", "sampling"],
    &["parameters"],
    &["geometry"],
    &["physics"],
    &["wear"],
    &["contact_models"],
    &["analysis"],
    &["excitation"],
    &["models"],
    &["report"],
    &["service_life"],
    &["cases"],
    &["validation"],
    &["gap"],
    &["pipeline"],
    &["store"],
    &["jobs"],
    &["config"],
    &["http"],
    &["cli"],
];

/// Rooms that reach the rooms below them only through named ones, each with the rooms it may
/// import: the job queue reaches the simulation library (models, gap, physics, wear,
/// analysis, ...) only through `pipeline`, its one door, besides the store it keeps its jobs
/// in and the lowest utility rooms.
const DOORS: &[(&str, &[&str])] = &[("jobs", &["units", "field_error", "store", "pipeline"])];

/// Lines a source file may have before it must say why at its top.
const LONG_FILE_LINES: usize = 700;
/// The words a long file's header uses to say why.
const LONG_FILE_REASON: &str = "Over 700 lines";
/// A room's own `mod.rs`, where an arrow inside the room starts or ends.
const ROOM_FILE: &str = "mod.rs";

/// The folders the long-file rule covers, from the repository root.
const LONG_FILE_DIRS: &[&str] = &["src", "tests"];
/// Files over [`LONG_FILE_LINES`] known to lack the header, from the repository root, each
/// waiting for its owner to split it or say why. The check fails on any other such file, and
/// on a listed one that no longer needs the entry, so the list only shrinks.
const KNOWN_LONG_FILES: &[&str] = &[];

/// Circles among sub-rooms known and left for now: (room, the circle's sub-rooms). The check
/// fails on any other circle, and on a listed one that is gone, so the list only shrinks. None
/// is left.
const KNOWN_CIRCLES: &[(&str, &[&str])] = &[];

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

/// A source file of the library crate with its module path and scan.
struct SourceFile {
    /// Path under `src/`.
    rel: String,
    module: Vec<String>,
    /// `mod.rs`: the file of a room with sub-rooms.
    room_file: bool,
    scan: FileScan,
}

/// The library's files (`main.rs`, `bin/` and the floors' own files are left out: the binaries
/// are other crates, and the floors' tests hold paths as text).
fn source_files(src: &Path) -> Vec<SourceFile> {
    let mut paths = Vec::new();
    rust_files(src, &mut paths);
    paths.sort();
    let mut files = Vec::new();
    for path in paths {
        let Ok(rel) = path.strip_prefix(src) else {
            continue;
        };
        let mut module: Vec<String> = rel
            .components()
            .filter_map(|c| c.as_os_str().to_str().map(str::to_string))
            .collect();
        if matches!(
            module.first().map(String::as_str),
            Some("main.rs" | "bin" | "floors.rs" | "floors")
        ) {
            continue;
        }
        let Some(last) = module.pop() else {
            continue;
        };
        let stem = last.strip_suffix(".rs").unwrap_or(&last).to_string();
        let room_file = stem == "mod" || (stem == "lib" && module.is_empty());
        if !room_file {
            module.push(stem);
        }
        let Ok(source) = std::fs::read_to_string(&path) else {
            continue;
        };
        files.push(SourceFile {
            rel: rel.display().to_string(),
            module,
            room_file,
            scan: scan(&source),
        });
    }
    files
}

/// Every module of the files plus their inline modules.
fn all_modules(files: &[SourceFile]) -> BTreeSet<Vec<String>> {
    let mut modules = BTreeSet::new();
    for file in files {
        modules.insert(file.module.clone());
        for inline in &file.scan.inline_modules {
            modules.insert([file.module.as_slice(), inline].concat());
        }
    }
    modules
}

/// The modules a file imports, resolved.
fn imports_of(file: &SourceFile, modules: &BTreeSet<Vec<String>>) -> Vec<Vec<String>> {
    file.scan
        .paths
        .iter()
        .filter_map(|(inline, path)| {
            let current = [file.module.as_slice(), inline].concat();
            resolve(&current, &path.segments, modules)
        })
        .collect()
}

/// Arrows of an import graph: (from, to) -> files that import.
type Arrows = BTreeMap<(String, String), Vec<String>>;

fn add_arrow(arrows: &mut Arrows, from: &str, to: &str, file: &str) {
    let files = arrows
        .entry((from.to_string(), to.to_string()))
        .or_default();
    if !files.iter().any(|f| f == file) {
        files.push(file.to_string());
    }
}

/// Every arrow between top-level rooms (the crate root sits above every floor).
fn import_graph(src: &Path) -> Arrows {
    let files = source_files(src);
    let modules = all_modules(&files);
    let mut arrows = Arrows::new();
    for file in &files {
        let Some(from) = file.module.first() else {
            continue;
        };
        for target in imports_of(file, &modules) {
            if let Some(to) = target.first().filter(|to| *to != from) {
                add_arrow(&mut arrows, from, to, &file.rel);
            }
        }
    }
    arrows
}

/// The arrows among the sub-rooms of every room with a folder, by room (`models`,
/// `models::launcher`, ...). A room's sub-rooms are its files and folders; its own `mod.rs`
/// ([`ROOM_FILE`]) is the room itself (the items its sub-rooms share, and the door that
/// declares and re-exports them), so arrows to and from it are left out. A name the `mod.rs`
/// re-exports counts as the sub-room it comes from.
fn sub_room_graphs(src: &Path) -> BTreeMap<Vec<String>, Arrows> {
    let files = source_files(src);
    let modules = all_modules(&files);
    let file_modules: BTreeSet<&Vec<String>> = files.iter().map(|f| &f.module).collect();
    let mut graphs = BTreeMap::new();
    for room_file in files.iter().filter(|f| f.room_file && !f.module.is_empty()) {
        let room = &room_file.module;
        let is_sub_room = |name: &str| {
            let mut child = room.clone();
            child.push(name.to_string());
            file_modules.contains(&child)
        };
        // Where a name the room re-exports comes from (a glob is looked up in the sub-room's
        // public items).
        let source_of = |name: &str| -> Option<String> {
            for path in &room_file.scan.reexports {
                let Some(target) = resolve(room, &path.segments, &modules) else {
                    continue;
                };
                let Some(sub) = target
                    .strip_prefix(room.as_slice())
                    .and_then(|rest| rest.first())
                    .filter(|sub| is_sub_room(sub))
                else {
                    continue;
                };
                let glob = path.segments.last().is_some_and(|s| s == "*");
                let named = !glob && exported_name(path) == Some(name);
                let in_glob = glob
                    && target.len() == room.len() + 1
                    && files.iter().any(|f| {
                        f.module == target
                            && (f.scan.public_items.contains(name)
                                || f.scan
                                    .reexports
                                    .iter()
                                    .any(|r| exported_name(r) == Some(name)))
                    });
                if named || in_glob {
                    return Some(sub.clone());
                }
            }
            None
        };
        let mut arrows = Arrows::new();
        for file in files.iter().filter(|f| f.module.starts_with(room)) {
            let from = file
                .module
                .get(room.len())
                .cloned()
                .unwrap_or_else(|| ROOM_FILE.to_string());
            for target in imports_of(file, &modules) {
                let Some(rest) = target.strip_prefix(room.as_slice()) else {
                    continue;
                };
                let to = match rest.first() {
                    None => ROOM_FILE.to_string(),
                    Some(sub) if is_sub_room(sub) => sub.clone(),
                    Some(name) => source_of(name).unwrap_or_else(|| ROOM_FILE.to_string()),
                };
                if to != from && from != ROOM_FILE && to != ROOM_FILE {
                    add_arrow(&mut arrows, &from, &to, &file.rel);
                }
            }
        }
        graphs.insert(room.clone(), arrows);
    }
    graphs
}

/// The circles of a graph, one per set of nodes, each as its nodes in order (the first node
/// repeated at the end).
fn circles(arrows: &Arrows) -> Vec<Vec<String>> {
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in arrows.keys() {
        next.entry(from.as_str()).or_default().push(to.as_str());
    }
    let mut seen: BTreeSet<BTreeSet<String>> = BTreeSet::new();
    let mut found = Vec::new();
    for (from, to) in arrows.keys() {
        // The shortest way back from `to` to `from`, if any.
        let mut came_from: BTreeMap<&str, &str> = BTreeMap::new();
        let mut queue = VecDeque::from([to.as_str()]);
        while let Some(node) = queue.pop_front() {
            if node == from {
                break;
            }
            for &n in next.get(node).into_iter().flatten() {
                if n != to && !came_from.contains_key(n) {
                    came_from.insert(n, node);
                    queue.push_back(n);
                }
            }
        }
        if !came_from.contains_key(from.as_str()) {
            continue;
        }
        // Back from `from` to `to` (the only node without a predecessor), then turned round.
        let mut back = vec![from.as_str()];
        while let Some(&previous) = back.last().and_then(|n| came_from.get(n)) {
            back.push(previous);
        }
        let circle: Vec<String> = std::iter::once(from.as_str())
            .chain(back.into_iter().rev())
            .map(str::to_string)
            .collect();
        if seen.insert(circle.iter().cloned().collect()) {
            found.push(circle);
        }
    }
    found
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
    fn a_room_with_doors_imports_only_through_them() {
        let arrows = import_graph(&src());
        for (room, doors) in DOORS {
            assert!(
                doors
                    .iter()
                    .any(|door| arrows.contains_key(&(room.to_string(), door.to_string()))),
                "the scan found no arrow from {room} through its doors: it no longer reads the \
                 tree"
            );
            let wrong: Vec<String> = arrows
                .iter()
                .filter(|((from, to), _)| from == room && !doors.contains(&to.as_str()))
                .map(|((from, to), files)| format!("{from} -> {to} in {files:?}"))
                .collect();
            assert!(
                wrong.is_empty(),
                "{room} imports past its doors {doors:?}:\n{}",
                wrong.join("\n")
            );
        }
    }

    #[test]
    fn sub_rooms_import_each_other_without_a_circle() {
        let graphs = sub_room_graphs(&src());
        let models = graphs
            .get(&vec!["models".to_string()])
            .map_or(0, |arrows| arrows.len());
        assert!(
            graphs.len() > 10 && models > 10,
            "the scan found {} rooms with sub-rooms and {models} arrows inside models: it no \
             longer reads the tree",
            graphs.len()
        );
        let nodes_of = |circle: &[&str]| circle.iter().map(|n| n.to_string()).collect();
        let known: BTreeSet<(String, BTreeSet<String>)> = KNOWN_CIRCLES
            .iter()
            .map(|(room, circle)| (room.to_string(), nodes_of(circle)))
            .collect();
        let mut found = Vec::new();
        let mut still_known = BTreeSet::new();
        for (room, arrows) in &graphs {
            let room = room.join("::");
            for circle in circles(arrows) {
                let key = (room.clone(), circle.iter().cloned().collect());
                if known.contains(&key) {
                    still_known.insert(key);
                    continue;
                }
                let steps: Vec<String> = circle
                    .windows(2)
                    .map(|w| {
                        let files = &arrows[&(w[0].clone(), w[1].clone())];
                        format!("    {} -> {} in {files:?}", w[0], w[1])
                    })
                    .collect();
                found.push(format!(
                    "{room}: {}\n{}",
                    circle.join(" -> "),
                    steps.join("\n")
                ));
            }
        }
        assert!(
            found.is_empty(),
            "import circles among sub-rooms:\n{}",
            found.join("\n")
        );
        let gone: Vec<_> = known.difference(&still_known).collect();
        assert!(
            gone.is_empty(),
            "known circles that are gone, to take off KNOWN_CIRCLES: {gone:?}"
        );
    }

    fn resolved(module: &[&str], source: &str) -> Vec<String> {
        let module: Vec<String> = module.iter().map(|s| s.to_string()).collect();
        let file = SourceFile {
            rel: String::new(),
            module: module.clone(),
            room_file: false,
            scan: scan(source),
        };
        let mut modules = all_modules(std::slice::from_ref(&file));
        modules.insert(vec!["models".into(), "case".into(), "child".into()]);
        let mut paths: Vec<String> = imports_of(&file, &modules)
            .iter()
            .map(|p| p.join("::"))
            .collect();
        paths.sort();
        paths.dedup();
        paths
    }

    #[test]
    fn the_scan_sees_grouped_nested_and_relative_imports() {
        let paths = resolved(
            &["models", "case"],
            "use crate::{geometry::x, physics::{a, b}, units};\n\
             /// [`crate::http`] is a doc link\n\
             let v = crate::wear::law(1); // crate::jobs in a comment\n\
             let s = \"crate::store in a string\"; let c = '{';\n\
             use super::{launcher, outcome::RunError};\n\
             use self::child::f as g;\n\
             fn f() -> Box<super::checkpoint::Checkpoint> { child::h() }\n\
             mod tests { use super::*; use super::super::spec; }\n\
             use nalgebra::Vector3;",
        );
        assert_eq!(
            paths,
            [
                "geometry::x",
                "models::case",
                "models::case::child::f",
                "models::case::child::h",
                "models::checkpoint::Checkpoint",
                "models::launcher",
                "models::outcome::RunError",
                "models::spec",
                "physics::a",
                "physics::b",
                "units",
                "wear::law",
            ]
        );
    }

    #[test]
    fn a_circle_is_found_with_its_steps() {
        let mut arrows = Arrows::new();
        for (from, to) in [
            ("case", "launcher"),
            ("launcher", "outcome"),
            ("outcome", "checkpoint"),
            ("checkpoint", "case"),
            ("checkpoint", "run"),
            ("case", "run"),
        ] {
            add_arrow(&mut arrows, from, to, "x.rs");
        }
        assert_eq!(
            circles(&arrows),
            [["case", "launcher", "outcome", "checkpoint", "case"]]
        );
        arrows.remove(&("outcome".to_string(), "checkpoint".to_string()));
        assert!(circles(&arrows).is_empty());
    }

    /// Files over [`LONG_FILE_LINES`] lines whose first 40 lines do not say why, as paths from
    /// the repository root.
    fn unexplained_long_files(root: &Path) -> Vec<String> {
        let mut files = Vec::new();
        for dir in LONG_FILE_DIRS {
            rust_files(&root.join(dir), &mut files);
        }
        files.sort();
        let mut unexplained = Vec::new();
        for file in files {
            let Ok(source) = std::fs::read_to_string(&file) else {
                continue;
            };
            let lines = source.lines().count();
            let header: String = source.lines().take(40).collect::<Vec<_>>().join("\n");
            if lines > LONG_FILE_LINES && !header.contains(LONG_FILE_REASON) {
                let rel = file.strip_prefix(root).unwrap_or(&file);
                unexplained.push(format!("{} ({lines} lines)", rel.display()));
            }
        }
        unexplained
    }

    #[test]
    fn long_files_say_why() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let unexplained = unexplained_long_files(root);
        let path_of = |entry: &String| entry.split(" (").next().unwrap_or("").to_string();
        let new: Vec<&String> = unexplained
            .iter()
            .filter(|entry| !KNOWN_LONG_FILES.contains(&path_of(entry).as_str()))
            .collect();
        assert!(
            new.is_empty(),
            "files over {LONG_FILE_LINES} lines without \"{LONG_FILE_REASON}\" and a reason \
             in their first 40 lines:\n{}",
            new.iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join("\n")
        );
        let fixed: Vec<&&str> = KNOWN_LONG_FILES
            .iter()
            .filter(|known| !unexplained.iter().any(|entry| path_of(entry) == **known))
            .collect();
        assert!(
            fixed.is_empty(),
            "known long files that now say why or are short enough, to take off \
             KNOWN_LONG_FILES: {fixed:?}"
        );
    }

    #[test]
    fn the_long_file_rule_reads_src_and_tests() {
        let dir = std::env::temp_dir().join(format!("floors-long-{}", std::process::id()));
        let long_body = "fn f() {}\n".repeat(LONG_FILE_LINES + 1);
        for (path, text) in [
            ("src/a.rs", long_body.clone()),
            (
                "src/b.rs",
                format!("//! {LONG_FILE_REASON}: a table.\n{long_body}"),
            ),
            ("tests/c/d.rs", long_body.clone()),
            ("tests/e.rs", "fn g() {}\n".to_string()),
            ("bench/f.rs", long_body.clone()),
        ] {
            let file = dir.join(path);
            std::fs::create_dir_all(file.parent().unwrap_or(&dir)).expect("temp dir");
            std::fs::write(&file, text).expect("temp file");
        }
        let found = unexplained_long_files(&dir);
        let _ = std::fs::remove_dir_all(&dir);
        let lines = LONG_FILE_LINES + 1;
        assert_eq!(
            found,
            [
                format!("src/a.rs ({lines} lines)"),
                format!("tests/c/d.rs ({lines} lines)")
            ]
        );
    }
}
