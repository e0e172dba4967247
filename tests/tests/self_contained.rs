//! The repository stands alone: a user clones it and nothing else. No source, test, script or
//! doc may reach outside the checkout (a reference folder beside the checkout, an absolute path of some
//! machine), and every doc a README links to exists.

use std::fs;
use std::path::{Path, PathBuf};

/// The repository's root (this crate lives in `tests/`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every text file of the repository that we write by hand (sources, docs, scripts, config).
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name != ".ci" && name != ".cargo" {
            continue;
        }
        if path.is_dir() {
            if name != "target" && name != "fixtures" {
                text_files(&path, out);
            }
        } else if [
            "rs", "md", "toml", "sh", "js", "html", "css", "json", "dh", "x",
        ]
        .iter()
        .any(|ext| path.extension().is_some_and(|e| e == *ext))
            || path
                .parent()
                .is_some_and(|p| p.file_name().is_some_and(|n| n == "scripts" || n == ".ci"))
        {
            out.push(path);
        }
    }
}

#[test]
fn nothing_reads_or_links_outside_the_repository() {
    let mut files = Vec::new();
    text_files(&root(), &mut files);
    assert!(
        files.len() > 50,
        "found only {} files under {}",
        files.len(),
        root().display()
    );
    // The reference folder beside the repository, spelt in two parts so that this file does
    // not itself name it.
    let outside = ["..", "/shared/"].concat();
    let machine_paths = ["/work/", "/root/", "/home/"];
    let mut offenders = Vec::new();
    // This file names what it looks for.
    for file in files
        .iter()
        .filter(|f| !f.ends_with(file!().rsplit('/').next().unwrap()))
    {
        let Ok(text) = fs::read_to_string(file) else {
            continue;
        };
        for (i, line) in text.lines().enumerate() {
            if line.contains(outside.as_str()) || machine_paths.iter().any(|p| line.contains(p)) {
                offenders.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "references outside the repository:\n{}",
        offenders.join("\n")
    );
}

#[test]
fn the_readmes_local_links_lead_somewhere() {
    let readme = fs::read_to_string(root().join("README.md")).unwrap();
    let mut checked = 0;
    // Markdown links `](target)` and code-quoted paths `docs/....md`.
    for piece in readme.split("](").skip(1) {
        let target = piece.split(')').next().unwrap();
        if target.starts_with("http") || target.starts_with('#') {
            continue;
        }
        assert!(
            root().join(target).exists(),
            "README links to missing `{target}`"
        );
        checked += 1;
    }
    for word in readme.split(|c: char| c == '`' || c.is_whitespace() || c == '(' || c == ')') {
        let word = word.trim_end_matches([',', '.', ';', ':']);
        if word.starts_with("docs/") && word.ends_with(".md") {
            assert!(root().join(word).exists(), "README names missing `{word}`");
            checked += 1;
        }
    }
    assert!(
        checked >= 5,
        "only {checked} local references found in README.md"
    );
}

#[test]
fn the_independent_fixture_ships_with_the_repository() {
    let fixture = root().join("fixtures/sample-mouse");
    assert!(fixture.join("sequence.json").is_file());
    assert!(fixture.join("truth.csv").is_file());
    assert!(fixture.join("cam0/000000.pgm").is_file());
    assert!(root().join("fixtures/README.md").is_file());
}
