//! The documentation against what it documents: `docs/guide.md`'s command reference against the
//! binary's `--help`, and every relative link of the README, `docs/` and `bench/results/` against
//! the files and headings it points at.
//!
//! The guide's format (also said in a comment at the top of its "Commands" section):
//! - a command's section starts at a `### `volpt ...`` heading (`### `volpt scene export``);
//! - an option group's section starts at a heading that ends in `options` (`### GPU options`);
//! - an option is a table row whose first cell starts with a backticked option
//!   (`| `--spp N` | ...`); its long names are the `--name`s in that first cell;
//! - a command takes its own rows, the rows of every option group its section links to
//!   (`[GPU](#gpu-options)`), and the rows of `### Global options`.

use std::collections::{BTreeSet, HashMap};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

/// Every subcommand, as typed after `volpt`.
const COMMANDS: &[&str] = &[
    "render",
    "merge",
    "bench",
    "view",
    "info",
    "scene generate",
    "scene export",
    "compare",
    "converge",
    "selftest",
    "plot",
    "print compensate",
    "print delta-e",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The long options `volpt COMMAND --help` lists, without `--help` and `--version`.
fn help_options(command: &str) -> BTreeSet<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_volpt"))
        .args(command.split(' '))
        .arg("--help")
        .output()
        .expect("run volpt");
    assert!(out.status.success(), "volpt {command} --help failed");
    let text = String::from_utf8(out.stdout).expect("UTF-8 help");
    text.lines()
        // Option lines are `  -x, --long <V>`, `      --long <V>` or `  -x <V>`; descriptions
        // are indented further (and may mention other options), so they do not count.
        .filter_map(|line| {
            let trimmed = line.trim_start();
            if line.len() - trimmed.len() > 6 || !trimmed.starts_with('-') {
                return None;
            }
            let mut words = trimmed.split_whitespace();
            let first = words.next()?;
            let long = if first.starts_with("--") {
                first
            } else if first.ends_with(',') {
                words.next()?
            } else {
                return None; // a short option only, such as `-D`
            };
            long_names(long).into_iter().next()
        })
        .filter(|name| name != "--help" && name != "--version")
        .collect()
}

/// The `--name`s in `text`.
fn long_names(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("--") {
        let tail = &rest[i + 2..];
        let len = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .unwrap_or(tail.len());
        if len > 0 && tail.as_bytes()[0].is_ascii_alphabetic() {
            names.push(format!("--{}", &tail[..len]));
        }
        rest = &tail[len..];
    }
    names
}

/// One `###` section of the guide: its heading, its option rows' long names, the anchors it links.
struct Section {
    heading: String,
    options: BTreeSet<String>,
    links: BTreeSet<String>,
}

fn sections(guide: &str) -> Vec<Section> {
    let mut sections: Vec<Section> = Vec::new();
    let mut in_code = false;
    for line in guide.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        if let Some(heading) = line.strip_prefix("### ") {
            sections.push(Section {
                heading: heading.trim().to_owned(),
                options: BTreeSet::new(),
                links: BTreeSet::new(),
            });
            continue;
        }
        if line.starts_with("## ") || line.starts_with("# ") {
            sections.push(Section {
                heading: String::new(),
                options: BTreeSet::new(),
                links: BTreeSet::new(),
            });
            continue;
        }
        let Some(section) = sections.last_mut() else {
            continue;
        };
        if let Some(row) = line.strip_prefix("| `-") {
            let first_cell = row.split(" | ").next().unwrap_or("");
            section
                .options
                .extend(long_names(&format!("-{first_cell}")));
        }
        for target in link_targets(line) {
            if let Some(anchor) = target.strip_prefix('#') {
                section.links.insert(anchor.to_owned());
            }
        }
    }
    sections
}

#[test]
fn the_guide_documents_exactly_the_options_of_every_command() {
    let guide = std::fs::read_to_string(root().join("docs/guide.md")).expect("read docs/guide.md");
    let sections = sections(&guide);
    let groups: HashMap<String, &Section> = sections
        .iter()
        .filter(|s| s.heading.ends_with("options"))
        .map(|s| (slug(&s.heading), s))
        .collect();
    let global = groups
        .get("global-options")
        .expect("docs/guide.md has a `### Global options` section");
    let mut problems = Vec::new();
    for command in COMMANDS {
        let heading = format!("`volpt {command}`");
        let Some(section) = sections.iter().find(|s| s.heading == heading) else {
            problems.push(format!("docs/guide.md has no `### {heading}` section"));
            continue;
        };
        let mut documented = section.options.clone();
        documented.extend(global.options.iter().cloned());
        for anchor in &section.links {
            if let Some(group) = groups.get(anchor) {
                documented.extend(group.options.iter().cloned());
            }
        }
        let listed = help_options(command);
        for missing in listed.difference(&documented) {
            problems.push(format!(
                "`volpt {command} --help` lists {missing}, docs/guide.md does not"
            ));
        }
        for extra in documented.difference(&listed) {
            problems.push(format!(
                "docs/guide.md documents {extra} for `volpt {command}`, its --help does not"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// GitHub's heading anchors: lower case, spaces to hyphens, other punctuation dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown file's headings, with GitHub's `-1`, `-2` for repeats.
fn anchors(markdown: &str) -> BTreeSet<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut anchors = BTreeSet::new();
    let mut in_code = false;
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        let level = line.chars().take_while(|&c| c == '#').count();
        if in_code || level == 0 || level > 6 || !line[level..].starts_with(' ') {
            continue;
        }
        let base = slug(&line[level..]);
        let n = seen.entry(base.clone()).or_insert(0);
        anchors.insert(if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        });
        *n += 1;
    }
    anchors
}

/// The targets of the inline links and images on one line, outside code spans.
fn link_targets(line: &str) -> Vec<String> {
    // Drop code spans, so `a[i](j)` in code is not a link.
    let mut text = String::new();
    for (i, part) in line.split('`').enumerate() {
        if i % 2 == 0 {
            text.push_str(part);
        }
    }
    let mut targets = Vec::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find("](") {
        let tail = &rest[i + 2..];
        let mut depth = 0;
        let end = tail.find(|c: char| {
            match c {
                '(' => depth += 1,
                ')' if depth == 0 => return true,
                ')' => depth -= 1,
                _ => {}
            }
            false
        });
        let Some(end) = end else { break };
        // A title after the target (`(file "title")`) is not part of it.
        let target = tail[..end].split_whitespace().next().unwrap_or("");
        targets.push(target.to_owned());
        rest = &tail[end..];
    }
    targets
}

fn markdown_files(dir: &Path, files: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read a docs directory") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            markdown_files(&path, files);
        } else if path.extension().is_some_and(|e| e == "md") {
            files.push(path);
        }
    }
}

/// `a/b/../c` as `a/c`, without touching the file system.
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

#[test]
fn every_relative_link_of_the_readme_and_the_docs_resolves() {
    let root = normalise(&root());
    let mut files = vec![root.join("README.md")];
    markdown_files(&root.join("docs"), &mut files);
    markdown_files(&root.join("bench/results"), &mut files);
    let mut anchor_cache: HashMap<PathBuf, BTreeSet<String>> = HashMap::new();
    let mut problems = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("read a Markdown file");
        let name = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        let mut in_code = false;
        for (number, line) in text.lines().enumerate() {
            if line.trim_start().starts_with("```") {
                in_code = !in_code;
                continue;
            }
            if in_code {
                continue;
            }
            for target in link_targets(line) {
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (path, anchor) = match target.split_once('#') {
                    Some((path, anchor)) => (path, Some(anchor)),
                    None => (target.as_str(), None),
                };
                let resolved = if path.is_empty() {
                    file.clone()
                } else {
                    normalise(&file.parent().expect("a file's folder").join(path))
                };
                let at = format!("{name}:{}: {target}", number + 1);
                if !resolved.exists() {
                    problems.push(format!("{at}: no such file"));
                    continue;
                }
                let Some(anchor) = anchor else { continue };
                if resolved.extension().is_none_or(|e| e != "md") {
                    continue;
                }
                let anchors = anchor_cache.entry(resolved.clone()).or_insert_with(|| {
                    anchors(&std::fs::read_to_string(&resolved).unwrap_or_default())
                });
                if !anchors.contains(anchor) {
                    problems.push(format!("{at}: no heading with this anchor"));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// `docs/extending.md`'s worked example, a new phase function of new physics kept as a patch, touches
/// exactly the three files the page names (and the test oracle), and still applies to this tree:
/// a change that moves what a new part must touch fails here until the page and the patch follow.
#[test]
fn the_worked_extension_touches_three_files_and_applies() {
    let patch = root().join("docs/extending-rayleigh.patch");
    let text = std::fs::read_to_string(&patch).expect("docs/extending-rayleigh.patch");
    let touched: BTreeSet<&str> = text
        .lines()
        .filter_map(|line| line.strip_prefix("diff --git a/"))
        .filter_map(|rest| rest.split(" b/").next())
        .collect();
    let expected: BTreeSet<&str> = [
        "volpt-core/src/phase.rs",
        "volpt-core/src/variant.rs",
        "volpt-scene/src/phase.rs",
        "tests/src/reference.rs",
    ]
    .into_iter()
    .collect();
    assert_eq!(touched, expected);
    let extending = std::fs::read_to_string(root().join("docs/extending.md")).unwrap();
    assert!(extending.contains("extending-rayleigh.patch"));
    // `git apply --check` reads only the working tree (no repository needed); where git is missing
    // the file list above is still checked.
    match std::process::Command::new("git")
        .args(["apply", "--check"])
        .arg(&patch)
        .current_dir(root())
        .output()
    {
        Ok(out) => assert!(
            out.status.success(),
            "docs/extending-rayleigh.patch no longer applies: {}",
            String::from_utf8_lossy(&out.stderr)
        ),
        Err(e) => eprintln!("skipped: git apply --check ({e})"),
    }
}
