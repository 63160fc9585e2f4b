//! The commands the README and docs/ show still exist: every `forest SUBCOMMAND …` line in a
//! fenced block (and the indented `[--option …]` lines that continue it) names a subcommand
//! and options that `forest SUBCOMMAND --help` lists.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod cli;

use cli::{forest, ok};

const SUBCOMMANDS: [&str; 7] = [
    "bake", "info", "scene", "render", "bench", "compare", "view",
];

fn pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut v = vec![root.join("README.md"), root.join("ARCHITECTURE.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    v.extend(docs);
    v
}

/// `--option` names in `text` (before any `#` comment).
fn options(text: &str) -> Vec<String> {
    let text = text.split(" #").next().unwrap_or("");
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("--") {
        let after = &rest[i + 2..];
        let name: String = after
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect();
        // `--` alone (cargo's separator) and `---` are no options.
        let before = rest[..i].chars().last();
        if !name.is_empty() && !name.starts_with('-') && before.is_none_or(|c| !c.is_alphanumeric())
        {
            out.push(name.clone());
        }
        rest = &after[name.len()..];
    }
    out
}

/// Every (page, line, subcommand, options) of the fenced `forest …` commands.
fn commands() -> Vec<(String, usize, String, Vec<String>)> {
    let mut out = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let name = page.file_name().unwrap().to_string_lossy().into_owned();
        let lines: Vec<&str> = text.lines().collect();
        let mut fenced = false;
        for (i, line) in lines.iter().enumerate() {
            if line.trim_start().starts_with("```") {
                fenced = !fenced;
                continue;
            }
            if !fenced {
                continue;
            }
            for marker in ["forest ", "forest-cli -- "] {
                let mut from = 0;
                while let Some(k) = line[from..].find(marker) {
                    let at = from + k;
                    from = at + marker.len();
                    // A word of its own (not `my.forest `, not a path ending in `forest`).
                    if at > 0 && !line[..at].ends_with([' ', '(', '`', ':', '$']) {
                        continue;
                    }
                    let tail = &line[from..];
                    let sub = tail.split_whitespace().next().unwrap_or("");
                    if !SUBCOMMANDS.contains(&sub) {
                        continue;
                    }
                    // The rest of this command: up to the next `;`, `&&`, `|` or `forest `.
                    let mut cmd = tail[sub.len()..].to_string();
                    for stop in [" forest ", ";", "&&", " | "] {
                        if let Some(s) = cmd.find(stop) {
                            cmd.truncate(s);
                        }
                    }
                    let mut opts = options(&cmd);
                    // Continuation lines: indented, starting with `[` or `--`.
                    for next in &lines[i + 1..] {
                        let t = next.trim_start();
                        if next.starts_with(' ') && (t.starts_with('[') || t.starts_with("--")) {
                            opts.extend(options(t));
                        } else {
                            break;
                        }
                    }
                    out.push((name.clone(), i + 1, sub.to_string(), opts));
                }
            }
        }
    }
    out
}

#[test]
fn every_documented_command_and_option_exists() {
    let commands = commands();
    assert!(
        commands.len() > 15,
        "only {} commands found",
        commands.len()
    );
    let mut help: BTreeMap<String, String> = BTreeMap::new();
    let mut missing = Vec::new();
    for (page, line, sub, opts) in &commands {
        let h = help
            .entry(sub.clone())
            .or_insert_with(|| ok(&forest(&[sub.as_str(), "--help"])));
        for o in opts {
            let flag = format!("--{o}");
            let listed = h.match_indices(&flag).any(|(i, _)| {
                h[i + flag.len()..]
                    .chars()
                    .next()
                    .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '-'))
            });
            if !listed && o != "help" {
                missing.push(format!("{page}:{line}: forest {sub} {flag}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "documented options that `forest SUBCOMMAND --help` does not list:\n{}",
        missing.join("\n")
    );
}

#[test]
fn the_option_scanner_finds_options_and_skips_the_rest() {
    assert_eq!(
        options("f.forest -o x.png --view inside [--size 800x600] --json # --not-this"),
        vec!["view", "size", "json"]
    );
    assert_eq!(options("-- view f.forest"), Vec::<String>::new());
}
