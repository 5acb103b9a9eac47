//! Every command the README and `docs/` show with its output (a ```console block: `$ bonescope …`, then what it
//! prints, `...` for lines left out, `[..]` for part of a line, `? N` for an exit code other than 0) is run on the
//! shared assets and must print what the page shows. `TRYCMD=overwrite cargo test --test readme` rewrites the pages'
//! outputs after a deliberate change (then put the `...` back where lines were left out).

#[test]
fn the_readme_and_the_docs_print_what_they_show() {
    trycmd::TestCases::new()
        .register_bin("bonescope", trycmd::cargo::cargo_bin!("bonescope"))
        .case("README.md")
        .case("docs/*.md");
}

/// Every option `--help` lists is in its command's synopsis in `docs/` (`bonescope COMMAND …` and the lines continuing
/// it), or, for the runtime techniques' layer options, in the synopsis's `[layer options]` and the table of
/// `docs/cli.md`; `--max-memory`, which every command takes, is said once there.
#[test]
fn every_option_is_in_its_commands_synopsis() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let pages: String = ["cli.md", "bake-and-diff.md", "app.md"]
        .iter()
        .map(|page| std::fs::read_to_string(root.join("docs").join(page)).unwrap())
        .collect();
    let layer_table: Vec<&str> = pages.lines().filter(|line| line.starts_with("| `--")).collect();
    let commands = ["inspect", "scan", "storage", "report", "export", "explain", "bake", "diff", "fit", "render"];
    let mut missing = Vec::new();
    for command in commands {
        let synopsis = synopsis(&pages, command);
        assert!(!synopsis.is_empty(), "no synopsis of `{command}` in docs/");
        for option in options(command) {
            let in_synopsis = synopsis.contains(&format!("[{option}")) || synopsis.contains(&format!(" {option} "));
            let layer = synopsis.contains("[layer options") && layer_table.iter().any(|row| row.contains(&option));
            let global = option == "--max-memory" && pages.contains("takes `--max-memory SIZE`");
            if !(in_synopsis || layer || global) {
                missing.push(format!("{command} {option}"));
            }
        }
    }
    assert!(missing.is_empty(), "options --help lists that no synopsis in docs/ shows: {missing:?}");
}

/// The synopses of `command`: each line `bonescope COMMAND …` of a page and the indented lines continuing it.
fn synopsis(pages: &str, command: &str) -> String {
    let mut lines = pages.lines().peekable();
    let mut found = String::new();
    while let Some(line) = lines.next() {
        if !line.starts_with(&format!("bonescope {command} ")) || !line.contains('[') {
            continue;
        }
        found.push_str(line);
        while let Some(next) = lines.next_if(|next| next.starts_with("    [") || next.starts_with("    --")) {
            found.push(' ');
            found.push_str(next);
        }
        found.push(' ');
    }
    found
}

/// The long options `bonescope COMMAND --help` lists, but `--help`.
fn options(command: &str) -> Vec<String> {
    let help = std::process::Command::new(env!("CARGO_BIN_EXE_bonescope")).args([command, "--help"]).output().unwrap();
    assert!(help.status.success(), "{command} --help");
    let text = String::from_utf8(help.stdout).unwrap();
    let mut options: Vec<String> = text
        .lines()
        .filter_map(|line| {
            let line = line.trim_start();
            let line = line.strip_prefix("-").and_then(|l| l.split_once(", ")).map_or(line, |(_, long)| long);
            let name = line.strip_prefix("--")?.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).next()?;
            Some(format!("--{name}"))
        })
        .filter(|option| option != "--help")
        .collect();
    options.dedup();
    options
}

/// Every crate the package and the Python module depend on (normal and dev) has a row in the table of
/// `docs/dependencies.md`, which says why it is there.
#[test]
fn every_dependency_says_why_in_the_docs() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/dependencies.md")).unwrap();
    let rows: Vec<&str> = page.lines().filter(|line| line.starts_with("| ")).collect();
    let mut missing = Vec::new();
    for manifest in ["Cargo.toml", "python/Cargo.toml"] {
        let text = std::fs::read_to_string(root.join(manifest)).unwrap();
        let names = dependencies(&text);
        assert!(names.iter().any(|n| n == "serde_json"), "{manifest}'s dependencies are read: {names:?}");
        for name in names {
            let named = format!("`{name}`");
            if !rows.iter().any(|row| row.split('|').nth(1).is_some_and(|cell| cell.contains(&named))) {
                missing.push(format!("{manifest}: {name}"));
            }
        }
    }
    assert!(missing.is_empty(), "dependencies without a row in docs/dependencies.md: {missing:?}");
}

/// The names in a manifest's `[dependencies]` and `[dev-dependencies]` tables (renamed ones by their package name).
fn dependencies(manifest: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut listing = false;
    for line in manifest.lines() {
        if line.starts_with('[') {
            listing = matches!(line.trim(), "[dependencies]" | "[dev-dependencies]");
            continue;
        }
        let Some((name, spec)) = line.split_once('=').filter(|_| listing && !line.starts_with('#')) else { continue };
        let package = spec.split("package = \"").nth(1).and_then(|rest| rest.split('"').next());
        names.push(package.unwrap_or(name.trim()).to_owned());
    }
    names.retain(|name| !name.is_empty() && name != "bonescope");
    names
}
