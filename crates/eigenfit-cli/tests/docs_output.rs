//! The docs quote the CLI's output: every block marked `<!-- regen: COMMAND -->` in README.md and
//! docs/*.md must be what COMMAND prints today, run from the repository root with this build's
//! `eigenfit` first on PATH. A change to a table, a message or a number then fails here until
//! `scripts/regenerate-docs.py` is rerun and the new output reviewed — the docs cannot drift.
//!
//! Blocks marked `regen-md` (Markdown printed by release-built examples and peer scripts) are
//! not run here: they take minutes or a peer's Python environment; the script regenerates them.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One quoted output: where it is, the command that makes it, the text the docs show.
struct Quoted {
    file: PathBuf,
    line: usize,
    command: String,
    shown: String,
}

/// Every `<!-- regen: … -->` block of `text` (the comment, then a fenced block).
fn quoted_blocks(file: &Path, text: &str) -> Vec<Quoted> {
    const OPEN: &str = "<!-- regen: ";
    let mut out = Vec::new();
    let mut rest = text;
    let mut offset = 0;
    while let Some(at) = rest.find(OPEN) {
        let start = offset + at;
        let after = &text[start + OPEN.len()..];
        let end =
            after.find(" -->\n").unwrap_or_else(|| panic!("{}: unclosed regen comment", file.display()));
        let command = after[..end].to_string();
        let body = &after[end + " -->\n".len()..];
        assert!(
            body.starts_with("```"),
            "{}: a regen comment not followed by a fenced block",
            file.display()
        );
        let body = &body[body.find('\n').expect("fence line") + 1..];
        let close = body.find("```").unwrap_or_else(|| panic!("{}: unclosed fence", file.display()));
        out.push(Quoted {
            file: file.to_path_buf(),
            line: text[..start].lines().count() + 1,
            command,
            shown: body[..close].to_string(),
        });
        let consumed = start + OPEN.len() + end;
        offset = consumed;
        rest = &text[consumed..];
    }
    out
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("repository root")
}

#[test]
fn quoted_outputs_are_what_the_commands_print() {
    let root = root();
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_eigenfit")).parent().expect("binary folder").to_path_buf();
    let path = format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap_or_default());
    let mut checked = 0;
    let mut stale = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("readable doc");
        for q in quoted_blocks(file, &text) {
            let out = Command::new("bash")
                .arg("-c")
                .arg(&q.command)
                .current_dir(&root)
                .env("PATH", &path)
                .output()
                .expect("bash runs");
            let code = out.status.code();
            // 0 (an answer) and 3 (a verdict short of one) are outputs the docs quote.
            assert!(
                matches!(code, Some(0) | Some(3)),
                "{}:{}: `{}` exited {code:?}: {}",
                q.file.display(),
                q.line,
                q.command,
                String::from_utf8_lossy(&out.stderr)
            );
            let printed = String::from_utf8(out.stdout).expect("UTF-8 output");
            checked += 1;
            if printed.trim_end() != q.shown.trim_end() {
                let first = printed
                    .lines()
                    .zip(q.shown.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or(printed.lines().count().min(q.shown.lines().count()));
                stale.push(format!(
                    "{}:{}: `{}`\n  first difference at output line {}:\n  docs:    {}\n  printed: {}",
                    q.file.strip_prefix(&root).unwrap_or(&q.file).display(),
                    q.line,
                    q.command,
                    first + 1,
                    q.shown.lines().nth(first).unwrap_or("(end)"),
                    printed.lines().nth(first).unwrap_or("(end)")
                ));
            }
        }
    }
    assert!(checked > 0, "no regen blocks found: the docs quote no command output?");
    assert!(
        stale.is_empty(),
        "{} of {checked} quoted outputs differ from what the commands print; rerun \
         `cargo build --release -p eigenfit-cli && scripts/regenerate-docs.py README.md docs/*.md` \
         and review the change:\n{}",
        stale.len(),
        stale.join("\n")
    );
}
