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

/// The module table in order: (module, floor, the imports column). A bold
/// row (`| **base** |`) starts a floor.
fn table() -> Vec<(String, usize, String)> {
    let doc = std::fs::read_to_string("docs/architecture.md")
        .unwrap_or_else(|e| panic!("docs/architecture.md: {e}"));
    let mut floor = 0;
    let mut table = Vec::new();
    for line in doc.lines() {
        if line.starts_with("| **") {
            floor += 1;
        } else if let Some(rest) = line.strip_prefix("| `") {
            let Some((name, _)) = rest.split_once('`') else {
                continue;
            };
            let body = line.trim_end().trim_end_matches('|');
            let imports = body.rsplit_once('|').map_or("", |(_, last)| last).trim();
            table.push((name.to_owned(), floor, imports.to_owned()));
        }
    }
    table
}

/// The backticked module paths of an imports column (`mission` (the
/// diagnostics), `base::ode`, …).
fn listed(column: &str) -> Vec<String> {
    column
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_owned)
        .collect()
}

/// The module path of a source file (`src/a/b/mod.rs` and `src/a/b.rs` are
/// `a::b`).
fn module_of(file: &Path) -> Vec<String> {
    let rel = file.strip_prefix("src").unwrap_or(file).with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// The `.rs` files of a module row: its file, its folder, without the
/// sub-modules that have rows of their own and without test files.
fn files_of(module: &str, rows: &BTreeMap<String, String>) -> Vec<PathBuf> {
    let rel: PathBuf = module.split("::").collect();
    let mut files = Vec::new();
    let file = Path::new("src").join(&rel).with_extension("rs");
    if file.is_file() {
        files.push(file);
    }
    let folder = Path::new("src").join(&rel);
    let mut stack = vec![folder];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.filter_map(Result::ok) {
            let path = entry.path();
            let owner = module_of(&path).join("::");
            if owner != module && rows.contains_key(&owner) {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs")
                && path.file_name().is_some_and(|n| n != "tests.rs")
            {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The modules of ours a file's code names (`crate::a::b::…`, `super::…`
/// resolved against the file's own path), comments and its `#[cfg(test)]`
/// tail left out: what it imports, not what its tests or its prose do.
fn referenced(file: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let here = module_of(file);
    // `x.rs` is the module `x`; `super` from it is its parent (for
    // `x/mod.rs` too: the module path already names the folder).
    let mut found = Vec::new();
    for line in text.lines() {
        if line.starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find(|c: char| c.is_ascii_alphabetic()) {
            rest = &rest[at..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let word = &rest[..end];
            rest = &rest[end..];
            let parts: Vec<&str> = word.split("::").filter(|p| !p.is_empty()).collect();
            let path = match parts.first() {
                Some(&"crate") => parts[1..].iter().map(|p| p.to_string()).collect(),
                Some(&"super") => {
                    let ups = parts.iter().take_while(|p| **p == "super").count();
                    let mut base = here.clone();
                    for _ in 0..ups {
                        base.pop();
                    }
                    base.extend(parts[ups..].iter().map(|p| p.to_string()));
                    base
                }
                _ => continue,
            };
            if !path.is_empty() {
                found.push(path);
            }
        }
    }
    found
}

/// The row a module path belongs to: the longest row that prefixes it.
fn row_of<'a>(
    path: &[String],
    rows: &'a [(String, usize, String)],
) -> Option<&'a (String, usize, String)> {
    rows.iter()
        .filter(|(name, _, _)| {
            let name: Vec<&str> = name.split("::").collect();
            name.len() <= path.len() && name.iter().zip(path).all(|(a, b)| a == b)
        })
        .max_by_key(|(name, _, _)| name.split("::").count())
}

fn within(inner: &str, outer: &str) -> bool {
    inner == outer || inner.starts_with(&format!("{outer}::"))
}

/// Each row's imports column is what its code imports: every module of ours
/// its files name is listed (or is the row's own, or below it), every module
/// listed is named by its files, and nothing is imported from a higher floor.
#[test]
fn each_rows_imports_are_what_its_code_imports() {
    let table = table();
    let rows: BTreeMap<String, String> = table
        .iter()
        .map(|(m, _, i)| (m.clone(), i.clone()))
        .collect();
    let mut wrong = Vec::new();
    for (module, floor, column) in &table {
        let files = files_of(module, &rows);
        assert!(!files.is_empty(), "no source files for `{module}`");
        let anything = column.contains("everything above");
        let allowed = listed(column);
        let mut used = std::collections::BTreeSet::new();
        for file in &files {
            for path in referenced(file) {
                let Some((target, target_floor, _)) = row_of(&path, &table) else {
                    continue;
                };
                if within(target, module) {
                    continue;
                }
                if target_floor > floor {
                    wrong.push(format!(
                        "{}: `{module}` (floor {floor}) imports `{}` from the higher floor {target_floor}",
                        file.display(),
                        path.join("::")
                    ));
                }
                let full = path.join("::");
                match allowed.iter().find(|e| within(target, e) || within(e, target) && within(&full, e)) {
                    Some(entry) => {
                        used.insert(entry.clone());
                    }
                    None if anything => {}
                    None => wrong.push(format!(
                        "{}: `{module}` imports `{full}`, which its imports column ({column:?}) does not list",
                        file.display()
                    )),
                }
            }
        }
        for entry in allowed.iter().filter(|e| !used.contains(*e)) {
            wrong.push(format!(
                "`{module}`'s imports column lists `{entry}`, which none of its files imports"
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "docs/architecture.md's imports columns disagree with the code:\n  {}",
        wrong.join("\n  ")
    );
}

/// The floors stand in the table's order: `base` first, the front ends last.
#[test]
fn the_floors_stand_in_order() {
    let floors: Vec<(String, usize)> = table().into_iter().map(|(m, f, _)| (m, f)).collect();
    let first = |layer: &str| {
        floors
            .iter()
            .find(|(m, _)| within(m, layer))
            .map(|(_, f)| *f)
            .unwrap_or_else(|| panic!("no row for `{layer}`"))
    };
    let order = [
        "base",
        "mission",
        "pipelines",
        "outcome",
        "run",
        "tui",
        "cli",
    ];
    for pair in order.windows(2) {
        assert!(
            first(pair[0]) <= first(pair[1]),
            "`{}` stands above `{}` in docs/architecture.md",
            pair[0],
            pair[1]
        );
    }
    assert!(first("base") < first("mission") && first("mission") < first("pipelines"));
    assert!(first("pipelines") < first("outcome") && first("outcome") < first("run"));
}

/// The places outside `src/pipelines/` that still know a pipeline by name
/// (a `Kind` or `Outcome` variant, an outcome type, `.theta_pso()` /
/// `.flatlo()` / `.fleet()`), each with why. Issue 38: a pipeline is read
/// through its face; this list only shrinks.
const KNOWS_PIPELINES_BY_NAME: &[(&str, &str)] = &[(
    "src/distributed/coordinator.rs",
    "the fleet's transport (fleet code that does process and network I/O, so on a floor of its own above the pipelines) builds the fleet's outcome; it matches over no kind",
)];

/// Issue 53, item 1: the places outside `src/pipelines/` that still name a
/// pipeline's module (`theta_pso::…`) or its mission section
/// (`mission.fleet`), each with why. A section is to become a unit of its
/// pipeline, registered once; until then this list only shrinks.
const NAMES_A_PIPELINE_OR_ITS_SECTION: &[(&str, &str)] = &[
    (
        "src/cli.rs",
        "`run theta-pso|flatlo|fleet`: each subcommand's own request (a warm start, processes) and `agent`'s ids",
    ),
    (
        "src/cli/eval_cmd.rs",
        "`eval` is θ-PSO's cost of given paths: its cost model and encoding",
    ),
    (
        "src/cli/sweep_cmd.rs",
        "the SPSO reference's figures (`spso::g17`) and its encodings",
    ),
    (
        "src/distributed/agent.rs",
        "the fleet's transport: one agent process",
    ),
    (
        "src/distributed/coordinator.rs",
        "the fleet's transport: builds the fleet's outcome",
    ),
    (
        "src/distributed/inbox.rs",
        "the fleet's transport: the fleet's messages",
    ),
    (
        "src/distributed/realtime.rs",
        "the fleet's transport: the fleet's links",
    ),
    (
        "src/distributed/wire.rs",
        "the fleet's transport: the fleet's wire format",
    ),
    (
        "src/mission/model.rs",
        "the sections themselves, and θ-PSO's clearance margin in the passing altitudes",
    ),
    ("src/tui/app.rs", "the formation editor lists θ-PSO's IWPs"),
    ("src/tui/editor.rs", "θ-PSO's IWPs"),
    ("src/tui/fields.rs", "θ-PSO's IWPs in the formation's items"),
    ("src/tui/find.rs", "θ-PSO's IWPs in the item finder"),
];

/// Lines of `file` outside comments and its `#[cfg(test)]` module that name
/// a pipeline's module or its mission section.
fn names_a_pipeline_or_its_section(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let modules = ["theta_pso::", "flatlo::", "fleet::"];
    let section = |code: &str| {
        [".theta_pso", ".flatlo", ".fleet"].iter().any(|s| {
            code.match_indices(s).any(|(i, _)| {
                let next = code[i + s.len()..].chars().next();
                !next.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '(')
            })
        })
    };
    text.lines()
        .take_while(|line| !line.starts_with("#[cfg(test)]"))
        .map(|line| line.split("//").next().unwrap_or(""))
        .filter(|code| modules.iter().any(|m| code.contains(m)) || section(code))
        .map(str::to_owned)
        .collect()
}

/// Issue 53's grep, wider than issue 38's: outside `src/pipelines/`, only
/// the listed files name a pipeline's module or its section, and every
/// listed file still does. A new one fails here: reach the pipeline through
/// its face, or the shared floor (`pipelines::verify`,
/// `pipelines::quadrotor`), instead.
#[test]
fn outside_the_pipelines_only_the_listed_files_name_a_pipeline_or_its_section() {
    only_the_listed_files(
        "src/pipelines",
        NAMES_A_PIPELINE_OR_ITS_SECTION,
        &names_a_pipeline_or_its_section,
        "these files name a pipeline's module or section; reach it through its face instead",
        "these files no longer name a pipeline or its section: take them off the list",
    );
}

/// Lines of `file` outside comments and its `#[cfg(test)]` module that name
/// a pipeline.
fn names_a_pipeline(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let names = [
        "Kind::ThetaPso",
        "Kind::Flatlo",
        "Kind::Fleet",
        "Outcome::ThetaPso",
        "Outcome::Flatlo",
        "Outcome::Fleet",
        "ThetaPsoOutcome",
        "FlatloOutcome",
        "FleetOutcome",
        ".theta_pso()",
        ".flatlo()",
        ".fleet()",
    ];
    text.lines()
        .take_while(|line| !line.starts_with("#[cfg(test)]"))
        .map(|line| line.split("//").next().unwrap_or(""))
        .filter(|code| names.iter().any(|n| code.contains(n)))
        .map(str::to_owned)
        .collect()
}

/// Issue 38's grep: outside `src/pipelines/` (where each pipeline and its
/// one registration live), only the listed places name a pipeline, and
/// every listed place still does (a place that no longer needs it leaves
/// the list). A new place fails here: read the pipeline through its face
/// (`pipelines::face`) instead.
#[test]
fn outside_the_pipelines_only_the_listed_places_name_a_pipeline() {
    only_the_listed_files(
        "src/pipelines",
        KNOWS_PIPELINES_BY_NAME,
        &names_a_pipeline,
        "these files name a pipeline; read it through its face instead",
        "these files no longer name a pipeline: take them off the list",
    );
}

/// The files under `src/` outside `skip` (and not a `tests.rs`) where
/// `finds` finds something are exactly those `listed`: a new one fails
/// with `new_why` and what was found in it, a listed one where nothing is
/// found any more with `gone_why`.
fn only_the_listed_files(
    skip: &str,
    listed: &[(&str, &str)],
    finds: &dyn Fn(&Path) -> Vec<String>,
    new_why: &str,
    gone_why: &str,
) {
    let found: Vec<String> = rust_files(Path::new("src"))
        .into_iter()
        .filter(|p| !p.starts_with(skip))
        .filter(|p| p.file_name().is_none_or(|n| n != "tests.rs"))
        .filter(|p| !finds(p).is_empty())
        .map(|p| p.to_string_lossy().replace('\\', "/"))
        .collect();
    let listed: Vec<&str> = listed.iter().map(|(f, _)| *f).collect();
    let new: Vec<_> = found
        .iter()
        .filter(|f| !listed.contains(&f.as_str()))
        .collect();
    let gone: Vec<_> = listed
        .iter()
        .filter(|f| !found.iter().any(|r| r == *f))
        .collect();
    assert!(
        new.is_empty(),
        "{new_why}: {:?}",
        new.iter()
            .map(|f| (f, finds(Path::new(f.as_str()))))
            .collect::<Vec<_>>()
    );
    assert!(gone.is_empty(), "{gone_why}: {gone:?}");
}

/// The files "Adding a pipeline" lists: the numbered items' first path.
fn files_a_pipeline_touches() -> Vec<String> {
    let doc = std::fs::read_to_string("docs/architecture.md")
        .unwrap_or_else(|e| panic!("docs/architecture.md: {e}"));
    let section = doc
        .split("## Adding a pipeline")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .unwrap_or_else(|| panic!("no \"Adding a pipeline\" section"));
    section
        .lines()
        .filter_map(|line| {
            let (number, rest) = line.split_once(". `")?;
            number.parse::<usize>().ok()?;
            Some(rest.split_once('`')?.0.to_owned())
        })
        .collect()
}

/// Issue 38: "Adding a pipeline" lists the files a new pipeline touches
/// outside its folder, at most four; each exists, and each source file
/// among them is where every pipeline is registered (it names each
/// pipeline's module or section), so the list names no file a pipeline
/// does not need.
#[test]
fn adding_a_pipeline_lists_the_files_every_pipeline_registers_in() {
    let files = files_a_pipeline_touches();
    assert!(
        (1..=4).contains(&files.len()),
        "\"Adding a pipeline\" lists {} files: {files:?}",
        files.len()
    );
    assert!(
        files.contains(&"src/pipelines/mod.rs".to_owned()),
        "{files:?}"
    );
    assert!(
        files.contains(&"docs/architecture.md".to_owned()),
        "{files:?}"
    );
    // A pipeline is a folder with a face (a shared piece, such as the
    // verification, is a folder without one).
    let pipelines = children(Path::new("src/pipelines"))
        .into_iter()
        .filter(|c| Path::new("src/pipelines").join(c).join("face.rs").is_file())
        .collect::<Vec<_>>();
    assert!(pipelines.len() >= 3, "{pipelines:?}");
    for file in files.iter().filter(|f| f.ends_with(".rs")) {
        let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{file} (listed): {e}"));
        for p in &pipelines {
            assert!(
                text.contains(&format!("{p}:")) || text.contains(&format!("mod {p};")),
                "{file} is listed as a place every pipeline registers in, but does not register `{p}`"
            );
        }
    }
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The `N` of the first "Long (~N lines)" in `text`.
fn stated_length(text: &str) -> Option<usize> {
    let (_, rest) = text.split_once("Long (~")?;
    rest.split_once(" lines)")?.0.parse().ok()
}

/// Whether a stated length is current: within 10 % (files) or 15 %
/// (functions) of the real one, or a few lines.
fn current(stated: usize, real: usize, share: f64, slack: usize) -> bool {
    stated.abs_diff(real) as f64 <= (share * real as f64).max(slack as f64)
}

/// Issue 38: a file over 700 lines or a function over 120 says why in one
/// line that starts "Long (~N lines) because", and N is current (the
/// module's `//!` doc for a file, the function's `///` doc).
#[test]
fn long_files_and_functions_say_why_and_how_long() {
    let mut wrong = Vec::new();
    for file in rust_files(Path::new("src")) {
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let lines: Vec<&str> = text.lines().collect();
        if lines.len() > 700 {
            let module_doc: String = lines
                .iter()
                .take_while(|l| l.starts_with("//!") || l.trim().is_empty())
                .copied()
                .collect::<Vec<_>>()
                .join(" ");
            match stated_length(&module_doc) {
                None => wrong.push(format!(
                    "{}: {} lines, no reason",
                    file.display(),
                    lines.len()
                )),
                Some(n) if !current(n, lines.len(), 0.10, 25) => wrong.push(format!(
                    "{}: {} lines, says ~{n}",
                    file.display(),
                    lines.len()
                )),
                Some(_) => {}
            }
        }
        for (start, line) in lines.iter().enumerate() {
            let code = line.trim_start();
            let indent = &line[..line.len() - code.len()];
            let signature = code
                .trim_start_matches("pub(crate) ")
                .trim_start_matches("pub(super) ")
                .trim_start_matches("pub ")
                .trim_start_matches("const ")
                .trim_start_matches("unsafe ");
            if !signature.starts_with("fn ") || line.trim_end().ends_with(';') {
                continue;
            }
            let close = format!("{indent}}}");
            let Some(end) = lines[start..].iter().position(|l| *l == close) else {
                continue;
            };
            let length = end + 1;
            if length <= 120 {
                continue;
            }
            let doc: Vec<&str> = lines[..start]
                .iter()
                .rev()
                .take_while(|l| {
                    l.trim_start().starts_with("///") || l.trim_start().starts_with("#[")
                })
                .copied()
                .collect();
            let name = signature[3..].split(['(', '<']).next().unwrap_or("?");
            let at = format!("{}:{} fn {name}", file.display(), start + 1);
            match stated_length(&doc.join(" ")) {
                None => wrong.push(format!("{at}: {length} lines, no reason")),
                Some(n) if !current(n, length, 0.15, 15) => {
                    wrong.push(format!("{at}: {length} lines, says ~{n}"))
                }
                Some(_) => {}
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "say why in one line, \"Long (~N lines) because …\", or split where a concept ends:\n  {}",
        wrong.join("\n  ")
    );
}

/// The places that read an obstacle's polygon as the file writes it (its
/// `footprint` vertices), each with why: the polygon's file form (read,
/// validated, imported, its vertices edited on the map). Everything else
/// asks the shape (`Obstacle::outline`, `base::shape::Outline`).
const READS_THE_FOOTPRINT_FIELD: &[(&str, &str)] = &[
    (
        "src/mission/obstacle.rs",
        "the file form, and the registration that makes it a shape (`outline`)",
    ),
    (
        "src/mission/validate/site.rs",
        "the footprint's rules as written: vertices, a simple polygon",
    ),
    (
        "src/import/merge.rs",
        "a re-import compares the surveyed vertices with the file's",
    ),
    (
        "src/import/mod.rs",
        "the survey's polygons written as footprints",
    ),
    (
        "src/import/pieces.rs",
        "the survey's polygons written as footprints",
    ),
    (
        "src/tui/editor.rs",
        "a footprint's vertices stepped through, added, moved and deleted",
    ),
    ("src/tui/fields.rs", "a vertex as an item of the inspector"),
    (
        "src/tui/fields/table.rs",
        "a vertex's coordinates as inspector fields",
    ),
    ("src/tui/input.rs", "a vertex picked with the mouse"),
    (
        "src/tui/view/map/mod.rs",
        "a selected footprint's vertices drawn as handles",
    ),
];

/// Issue 53's "a shape is a type": outside `src/base/shape/` no file
/// branches on how an obstacle's shape is stored (its `footprint` field, a
/// prism's polygon), but the listed file-form places; a new place fails
/// here: ask the shape (`Obstacle::outline`, `Outline`) instead. The third
/// shape that shows it is `tests/all/shapes.rs`.
#[test]
fn outside_the_shape_module_only_the_file_form_reads_a_footprint() {
    let reads = |file: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(file).unwrap_or_default();
        text.lines()
            .take_while(|line| !line.starts_with("#[cfg(test)]"))
            .map(|line| line.split("//").next().unwrap_or(""))
            .filter(|code| {
                [".footprint", ".polygon"].iter().any(|n| {
                    code.match_indices(n).any(|(i, _)| {
                        !code[i + n.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
                    })
                })
            })
            .map(str::to_owned)
            .collect()
    };
    only_the_listed_files(
        "src/base/shape",
        READS_THE_FOOTPRINT_FIELD,
        &reads,
        "these files read an obstacle's footprint field; ask its shape instead",
        "these files no longer read it: take them off the list",
    );
}
