//! docs/architecture.md names every module of `src/`, and only modules that
//! exist: a module row of its own (`pipelines::fleet`), or its file in its
//! parent's row (`simulation.rs` in `pipelines::fleet`'s).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The module table's rows: module path → the row's text.
fn rows() -> BTreeMap<String, String> {
    let doc = std::fs::read_to_string("docs/architecture.md")
        .unwrap_or_else(|e| panic!("docs/architecture.md: {e}"));
    doc.lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("| `")?;
            let (name, _) = rest.split_once('`')?;
            Some((name.to_owned(), line.to_owned()))
        })
        .collect()
}

/// The file or folder of a module path (`a::b` is `src/a/b.rs` or `src/a/b/`).
fn source_of(module: &str) -> Option<PathBuf> {
    let rel: PathBuf = module.split("::").collect();
    let file = Path::new("src").join(&rel).with_extension("rs");
    let folder = Path::new("src").join(&rel);
    if folder.join("mod.rs").is_file() || folder.is_dir() && file.is_file() {
        Some(folder)
    } else if file.is_file() {
        Some(file)
    } else {
        None
    }
}

/// The child modules declared in a folder: its `.rs` files but `mod.rs`,
/// and its sub-folders.
fn children(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .filter_map(Result::ok)
        .filter_map(|entry| {
            let path = entry.path();
            let name = path.file_name()?.to_str()?.to_owned();
            if path.is_dir() {
                Some(name)
            } else {
                let stem = name.strip_suffix(".rs")?;
                (stem != "mod").then(|| stem.to_owned())
            }
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

/// Every child of `module` (a folder) is a row or named in `module`'s row.
fn check_children(
    module: &str,
    folder: &Path,
    rows: &BTreeMap<String, String>,
    missing: &mut Vec<String>,
) {
    let row = &rows[module];
    for child in children(folder) {
        let path = format!("{module}::{child}");
        if rows.contains_key(&path) {
            if let Some(sub) = source_of(&path).filter(|p| p.is_dir()) {
                check_children(&path, &sub, rows, missing);
            }
        } else if !row.contains(&format!("`{child}.rs`"))
            && !row.contains(&format!("`{child}/`"))
            && !row.contains(&format!("/{child}.rs`"))
        {
            missing.push(path);
        }
    }
}

#[test]
fn every_module_the_architecture_names_exists() {
    let rows = rows();
    assert!(rows.len() > 10, "no module table found");
    let absent: Vec<&String> = rows.keys().filter(|m| source_of(m).is_none()).collect();
    assert!(
        absent.is_empty(),
        "named in docs/architecture.md but not in src/: {absent:?}"
    );
}

#[test]
fn every_module_in_src_is_named_in_the_architecture() {
    let rows = rows();
    let lib = std::fs::read_to_string("src/lib.rs").unwrap_or_else(|e| panic!("src/lib.rs: {e}"));
    let top: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod ")?.strip_suffix(';'))
        .collect();
    assert!(top.len() > 5, "no modules in src/lib.rs");
    let mut missing = Vec::new();
    for module in top {
        if !rows.contains_key(module) {
            // A layer's folder may be named by its modules' rows alone.
            if !rows.keys().any(|r| r.starts_with(&format!("{module}::"))) {
                missing.push(module.to_owned());
                continue;
            }
        }
        if let Some(folder) = source_of(module).filter(|p| p.is_dir()) {
            if rows.contains_key(module) {
                check_children(module, &folder, &rows, &mut missing);
            } else {
                for child in children(&folder) {
                    let path = format!("{module}::{child}");
                    if !rows.contains_key(&path) {
                        missing.push(path);
                    } else if let Some(sub) = source_of(&path).filter(|p| p.is_dir()) {
                        check_children(&path, &sub, &rows, &mut missing);
                    }
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "in src/ but not in docs/architecture.md: {missing:?}"
    );
}
