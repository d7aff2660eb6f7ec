//! The documentation's own checks, on the files themselves: every relative link in README.md,
//! ARCHITECTURE.md and docs/**/*.md points to a file or folder that exists; every number the
//! README's "How fast, how accurate" table quotes appears on a results page (docs/results/),
//! where it is measured and dated; and the README stays a user's guide (at most 200 lines, no
//! issue or pass numbers).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            markdown_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// The pages the link check reads: README.md, ARCHITECTURE.md and every page under docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![root().join("README.md"), root().join("ARCHITECTURE.md")];
    markdown_files(&root().join("docs"), &mut pages);
    pages.sort();
    pages
}

/// The text of a page outside fenced code blocks and inline code spans, line by line, so that
/// a link-like text in an example is not taken for a link.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut lines = Vec::new();
    let mut fenced = false;
    for (index, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || line.starts_with("    ") && !line.trim_start().starts_with(['-', '|', '*']) {
            continue;
        }
        let mut prose = String::new();
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                prose.push(c);
            }
        }
        lines.push((index + 1, prose));
    }
    lines
}

/// The targets of the inline links `[text](target)` and reference definitions `[x]: target` of
/// one line.
fn link_targets(line: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let bytes = line.as_bytes();
    let mut i = 0;
    while let Some(offset) = line[i..].find("](") {
        let start = i + offset + 2;
        let mut depth = 1;
        let mut end = start;
        while end < bytes.len() {
            match bytes[end] {
                b'(' => depth += 1,
                b')' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            end += 1;
        }
        let target = line[start..end].trim();
        // `[text](<target with spaces>)` or `[text](target "title")`
        let target = match target.strip_prefix('<') {
            Some(rest) => rest.split('>').next().unwrap_or(""),
            None => target.split_whitespace().next().unwrap_or(""),
        };
        targets.push(target.to_string());
        i = end.min(bytes.len());
        if i >= bytes.len() {
            break;
        }
    }
    let trimmed = line.trim_start();
    if trimmed.starts_with('[') {
        if let Some((label, rest)) = trimmed.split_once("]:") {
            if !label.contains(']') {
                if let Some(target) = rest.split_whitespace().next() {
                    targets.push(target.trim_matches(['<', '>']).to_string());
                }
            }
        }
    }
    targets
}

/// A link to another site, an e-mail address or an anchor on the same page: not a file.
fn is_external(target: &str) -> bool {
    target.is_empty()
        || target.starts_with('#')
        || target.contains("://")
        || target.starts_with("mailto:")
}

#[test]
fn every_relative_link_points_to_a_file_that_exists() {
    let mut checked = 0;
    let mut broken = Vec::new();
    for page in pages() {
        let text = read(&page);
        let dir = page.parent().unwrap_or(Path::new("."));
        for (line_number, line) in prose_lines(&text) {
            for target in link_targets(&line) {
                if is_external(&target) {
                    continue;
                }
                let path = target.split('#').next().unwrap_or("");
                let resolved = if let Some(from_root) = path.strip_prefix('/') {
                    root().join(from_root)
                } else {
                    dir.join(path)
                };
                checked += 1;
                if !resolved.exists() {
                    broken.push(format!(
                        "{}:{line_number}: `{target}` ({} does not exist)",
                        page.strip_prefix(root()).unwrap_or(&page).display(),
                        resolved.display()
                    ));
                }
            }
        }
    }
    assert!(
        checked >= 20,
        "only {checked} relative links found: the check no longer reads the pages' links"
    );
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// The numbers of a text: digits with an optional decimal part and exponent (`0.43`, `5e-5`,
/// `1.77e-3`), each whole (a number is not found inside a longer one).
fn numbers(text: &str) -> Vec<String> {
    let chars: Vec<char> = text.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_ascii_alphanumeric() || chars[i - 1] == '.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < chars.len() && chars[j].is_ascii_digit() {
            j += 1;
        }
        if j + 1 < chars.len() && chars[j] == '.' && chars[j + 1].is_ascii_digit() {
            j += 1;
            while j < chars.len() && chars[j].is_ascii_digit() {
                j += 1;
            }
        }
        // An exponent: e, an optional sign, digits.
        if j < chars.len() && chars[j] == 'e' {
            let mut k = j + 1;
            if k < chars.len() && (chars[k] == '-' || chars[k] == '+') {
                k += 1;
            }
            if k < chars.len() && chars[k].is_ascii_digit() {
                while k < chars.len() && chars[k].is_ascii_digit() {
                    k += 1;
                }
                j = k;
            }
        }
        found.push(chars[i..j].iter().collect());
        i = j;
    }
    found
}

/// The data rows of the table under the README's "How fast, how accurate" heading.
fn speed_table_rows(readme: &str) -> Vec<String> {
    let mut rows = Vec::new();
    let mut in_section = false;
    for line in readme.lines() {
        if line.starts_with("## ") {
            in_section = line
                .trim_start_matches("## ")
                .starts_with("How fast, how accurate");
            continue;
        }
        if in_section && line.starts_with('|') {
            rows.push(line.to_string());
        }
    }
    // The header row and its separator.
    rows.into_iter().skip(2).collect()
}

#[test]
fn every_number_in_the_readmes_speed_table_is_on_a_results_page() {
    let readme = read(&root().join("README.md"));
    let rows = speed_table_rows(&readme);
    let quoted: Vec<String> = rows.iter().flat_map(|row| numbers(row)).collect();
    assert!(
        rows.len() >= 5 && quoted.len() >= 10,
        "the README's \"How fast, how accurate\" table has {} rows and {} numbers: the check \
         no longer finds it",
        rows.len(),
        quoted.len()
    );
    let mut results = Vec::new();
    markdown_files(&root().join("docs/results"), &mut results);
    let measured: BTreeSet<String> = results
        .iter()
        .flat_map(|page| numbers(&read(page)))
        .collect();
    let missing: Vec<&String> = quoted.iter().filter(|n| !measured.contains(*n)).collect();
    assert!(
        missing.is_empty(),
        "numbers the README quotes that no page under docs/results/ carries: {missing:?}"
    );
}

/// Ordinal words: `first` to `twentieth`, `thirtieth`, `twenty-fifth`, `25th`.
fn is_ordinal(word: &str) -> bool {
    const ORDINALS: &[&str] = &[
        "first",
        "second",
        "third",
        "fourth",
        "fifth",
        "sixth",
        "seventh",
        "eighth",
        "ninth",
        "tenth",
        "eleventh",
        "twelfth",
        "thirteenth",
        "fourteenth",
        "fifteenth",
        "sixteenth",
        "seventeenth",
        "eighteenth",
        "nineteenth",
        "twentieth",
        "thirtieth",
    ];
    let last = word.rsplit('-').next().unwrap_or(word);
    ORDINALS.contains(&last)
        || (word.len() > 2
            && word[..word.len() - 2].chars().all(|c| c.is_ascii_digit())
            && ["st", "nd", "rd", "th"].contains(&&word[word.len() - 2..]))
}

/// Where a text names an issue, a session or a pass: `issue 27`, `session 4`, `twenty-fifth
/// pass`.
fn lab_notebook_framing(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let words: Vec<&str> = lower
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '#'))
        .filter(|w| !w.is_empty())
        .collect();
    let mut found = Vec::new();
    for pair in words.windows(2) {
        let numbered = pair[1]
            .trim_start_matches('#')
            .starts_with(|c: char| c.is_ascii_digit());
        if (pair[0] == "issue" || pair[0] == "session") && numbered
            || (pair[1] == "pass" || pair[1] == "passes") && is_ordinal(pair[0])
        {
            found.push(format!("{} {}", pair[0], pair[1]));
        }
    }
    found
}

#[test]
fn the_readme_is_a_guide_not_a_notebook() {
    let readme = read(&root().join("README.md"));
    let lines = readme.lines().count();
    assert!(lines <= 200, "README.md has {lines} lines; at most 200");
    let mut pages = vec![root().join("README.md")];
    markdown_files(&root().join("docs/guide"), &mut pages);
    let found: Vec<String> = pages
        .iter()
        .flat_map(|page| {
            let name = page
                .strip_prefix(root())
                .unwrap_or(page)
                .display()
                .to_string();
            lab_notebook_framing(&read(page))
                .into_iter()
                .map(move |f| format!("{name}: {f}"))
        })
        .collect();
    assert!(
        found.is_empty(),
        "the README and the guides name issues, sessions or passes (they belong in \
         docs/journal/): {found:?}"
    );
}

#[test]
fn the_scanners_read_what_they_should() {
    assert_eq!(
        numbers("0.43x, 250 µs, 5e-5 s, 0.54-0.71 %, 1.77e-3, A-D, x2 v1.5"),
        ["0.43", "250", "5e-5", "0.54", "0.71", "1.77e-3"]
    );
    assert_eq!(
        link_targets("see [a](docs/a.md#x) and [b](<b c.md>), [c](https://x.org \"t\")"),
        ["docs/a.md#x", "b c.md", "https://x.org"]
    );
    assert_eq!(link_targets("[ref]: ../x.md"), ["../x.md"]);
    let prose = prose_lines("a [x](y.md)\n```\n[z](w.md)\n```\n`[q](r.md)` b");
    let targets: Vec<String> = prose.iter().flat_map(|(_, l)| link_targets(l)).collect();
    assert_eq!(targets, ["y.md"]);
    assert_eq!(
        lab_notebook_framing("Issue 27's target; the twenty-fifth pass; it passes; with pass"),
        ["issue 27", "twenty-fifth pass"]
    );
}
