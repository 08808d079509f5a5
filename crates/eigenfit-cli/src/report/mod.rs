//! `--report FILE.html`: one self-contained HTML file to hand over (issue 33) — the verdict and
//! what it means, tables with units, the plots inline as SVG, and the data's provenance (input
//! files with their SHA-256, the command line, the eigenfit version). No script, no stylesheet or
//! font from elsewhere: a browser shows it complete without a network.
//!
//! [`Report`] is the one builder every command fills (`estimate`, `discover`, `campaign`,
//! `campbell`, `bench`, each in its own module here); [`Report::write`] writes it atomically.
//! Every piece of text is HTML-escaped when rendered; only the SVG that [`crate::plot::to_svg`]
//! drew goes in as markup (its text plotters escapes itself).

pub mod bench;
pub mod campaign;
pub mod campbell;
pub mod discover;
pub mod estimate;

use crate::error::CliError;
use crate::plot::Figure;
use sha2::{Digest, Sha256};
use std::cell::RefCell;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The `--report FILE.html` option every reporting command flattens in.
#[derive(Debug, Clone, clap::Args)]
pub struct HtmlArgs {
    /// Write one self-contained HTML report (verdict, tables with units, plots inline, the
    /// inputs' SHA-256, the command line) to this file; checked writable before any work.
    #[arg(long = "report", value_name = "FILE.html")]
    pub html: Option<PathBuf>,
}

impl HtmlArgs {
    /// Refuses, before any work, a report path that cannot be written (exit code 2).
    pub fn check(&self) -> Result<(), CliError> {
        match &self.html {
            Some(path) => crate::output::check_writable(path, "--report"),
            None => Ok(()),
        }
    }
}

thread_local! {
    /// The command line [`crate::run_json`] was given on this thread (the process's own
    /// arguments are the host program's there, e.g. Python's).
    static COMMAND_LINE: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
}

/// Runs `f` with `argv` recorded as this thread's command line (for the report's provenance).
pub(crate) fn with_command_line<T>(argv: &[String], f: impl FnOnce() -> T) -> T {
    let previous = COMMAND_LINE.with(|c| c.replace(Some(argv.to_vec())));
    struct Restore(Option<Vec<String>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            COMMAND_LINE.with(|c| *c.borrow_mut() = previous);
        }
    }
    let _restore = Restore(previous);
    f()
}

/// The command line that asked for this run, quoted as a POSIX shell would need it.
pub fn command_line() -> String {
    let argv = COMMAND_LINE.with(|c| c.borrow().clone()).unwrap_or_else(|| std::env::args().collect());
    argv.iter().map(|a| shell_quote(a)).collect::<Vec<_>>().join(" ")
}

/// `a` as one shell word: as it is when it holds only safe characters, else in single quotes.
fn shell_quote(a: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./:=,+@%".contains(c);
    if !a.is_empty() && a.chars().all(safe) {
        a.to_string()
    } else {
        format!("'{}'", a.replace('\'', r"'\''"))
    }
}

/// `text` with `& < > " '` escaped: safe as HTML text and inside a quoted attribute.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// `v` to `digits` significant digits: plain in [10⁻³, 10⁵), else `1.2346 × 10⁵`; trailing
/// zeros kept (they state the precision); `—` for a value that is not finite.
pub fn number(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return "—".to_string();
    }
    let digits = digits.max(1);
    if v == 0.0 {
        return "0".to_string();
    }
    let exponent = v.abs().log10().floor() as i32;
    if (-3..5).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        let s = format!("{v:.decimals$}");
        // Rounding may carry into a new digit (99999.5 → "100000"): still plain, still right.
        return s;
    }
    let s = format!("{v:.prec$e}", prec = digits - 1);
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    format!("{mantissa} × {}", crate::plot::style::power_of_ten(exp))
}

/// A cell of a table.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// What is shown.
    pub text: String,
    /// The exact value behind a number (in `data-value`, so a reader or a test can take it).
    pub value: Option<f64>,
}

impl Cell {
    /// A text cell.
    pub fn text(text: impl Into<String>) -> Self {
        Self { text: text.into(), value: None }
    }

    /// A number to `digits` significant digits, its exact value kept beside.
    pub fn number(v: f64, digits: usize) -> Self {
        Self { text: number(v, digits), value: Some(v) }
    }

    /// A number with at most `decimals` decimals and no trailing zeros (speeds in rpm: `1000`,
    /// `999.5`), its exact value kept beside.
    pub fn plain(v: f64, decimals: usize) -> Self {
        Self { text: crate::plot::style::trim(v, decimals), value: Some(v) }
    }

    /// A whole number (a mode, a count), shown as it is.
    pub fn integer(n: usize) -> Self {
        Self { text: n.to_string(), value: Some(n as f64) }
    }

    /// A number when there is one, else `—` with the reason given (`why`) in words.
    pub fn maybe(v: Option<f64>, digits: usize, why: &str) -> Self {
        v.map_or_else(|| Self::text(why), |v| Self::number(v, digits))
    }
}

impl From<&str> for Cell {
    fn from(s: &str) -> Self {
        Cell::text(s)
    }
}

impl From<String> for Cell {
    fn from(s: String) -> Self {
        Cell::text(s)
    }
}

/// A table: a caption, the column heads (units in them or in a unit column), the rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Caption above the table.
    pub caption: String,
    /// Column heads.
    pub head: Vec<String>,
    /// Rows of cells.
    pub rows: Vec<Vec<Cell>>,
    /// `class` of the table in the page (`parameters`, `modes`, …), for readers and tests.
    pub class: String,
}

impl Table {
    /// An empty table of `class` with `caption` and the column heads.
    pub fn new(class: &str, caption: impl Into<String>, head: &[&str]) -> Self {
        Self {
            caption: caption.into(),
            head: head.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
            class: class.to_string(),
        }
    }

    /// Adds a row.
    pub fn row(&mut self, cells: Vec<Cell>) {
        self.rows.push(cells);
    }
}

/// One part of a section.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A paragraph of text.
    Text(String),
    /// A list of short statements.
    List(Vec<String>),
    /// A table.
    Table(Table),
    /// A plot: its caption and its SVG.
    Figure {
        /// What the plot shows.
        caption: String,
        /// The SVG document plotters drew.
        svg: String,
    },
}

/// A titled part of the report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Section {
    /// Heading.
    pub heading: String,
    /// Content, in order.
    pub blocks: Vec<Block>,
}

impl Section {
    /// Adds a paragraph.
    pub fn text(&mut self, text: impl Into<String>) -> &mut Self {
        self.blocks.push(Block::Text(text.into()));
        self
    }

    /// Adds a list (nothing when `items` is empty).
    pub fn list(&mut self, items: Vec<String>) -> &mut Self {
        if !items.is_empty() {
            self.blocks.push(Block::List(items));
        }
        self
    }

    /// Adds a table.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.blocks.push(Block::Table(table));
        self
    }

    /// Draws `figure` as SVG into the section; a figure that cannot be drawn is said so in its
    /// place (the report is still written).
    pub fn figure<F: Figure>(&mut self, caption: impl Into<String>, figure: &F) -> &mut Self {
        let caption = caption.into();
        match crate::plot::to_svg(figure) {
            Ok(svg) => self.blocks.push(Block::Figure { caption, svg }),
            Err(e) => self.blocks.push(Block::Text(format!("{caption}: could not be drawn ({e})"))),
        }
        self
    }
}

/// The verdict at the top of the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Whether the result can be used as it is (green) or not (red).
    pub good: bool,
    /// The verdict in a few words (the command's own word, e.g. `converged`, `poor-fit`).
    pub word: String,
    /// What it means for the reader, in a sentence or two.
    pub meaning: String,
}

/// An input file (or a built-in model) the result was computed from.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// What it is (`model`, `measured frequencies`, …).
    pub role: String,
    /// The path as given, or the built-in model's name.
    pub name: String,
    /// Its SHA-256 in hex and size in bytes, or why there is none (built in, unreadable).
    pub digest: Result<(String, u64), String>,
}

/// SHA-256 (hex) and size of the file at `path`, read in blocks.
pub fn sha256_file(path: &Path) -> std::io::Result<(String, u64)> {
    use std::io::Read;
    let mut file = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 16];
    let mut size = 0u64;
    loop {
        let n = file.read(&mut buffer)?;
        if n == 0 {
            break;
        }
        size += n as u64;
        hasher.update(&buffer[..n]);
    }
    let digest = hasher.finalize();
    let mut hex = String::with_capacity(64);
    for b in digest {
        let _ = write!(hex, "{b:02x}");
    }
    Ok((hex, size))
}

/// The whole report.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The command (`estimate`, …).
    pub command: String,
    /// Title: the model and what was done.
    pub title: String,
    /// The verdict, when the command gives one.
    pub verdict: Option<Verdict>,
    /// The sections, in order.
    pub sections: Vec<Section>,
    /// The inputs.
    pub inputs: Vec<Input>,
    /// The command line.
    pub command_line: String,
}

impl Report {
    /// An empty report of `command` titled `title`, with this run's command line.
    pub fn new(command: &str, title: impl Into<String>) -> Self {
        Self {
            command: command.to_string(),
            title: title.into(),
            verdict: None,
            sections: Vec::new(),
            inputs: Vec::new(),
            command_line: command_line(),
        }
    }

    /// Sets the verdict.
    pub fn verdict(&mut self, good: bool, word: impl Into<String>, meaning: impl Into<String>) {
        self.verdict = Some(Verdict { good, word: word.into(), meaning: meaning.into() });
    }

    /// A new section headed `heading`, to fill.
    pub fn section(&mut self, heading: impl Into<String>) -> &mut Section {
        self.sections.push(Section { heading: heading.into(), blocks: Vec::new() });
        self.sections.last_mut().expect("just pushed")
    }

    /// Records the input file at `path` with its SHA-256 (or why it could not be read).
    pub fn input(&mut self, role: &str, path: &Path) {
        let digest = sha256_file(path).map_err(|e| format!("could not be read: {e}"));
        self.inputs.push(Input { role: role.to_string(), name: path.display().to_string(), digest });
    }

    /// Records a built-in model (no file: the eigenfit version fixes it).
    pub fn builtin(&mut self, role: &str, name: &str) {
        self.inputs.push(Input {
            role: role.to_string(),
            name: name.to_string(),
            digest: Err(format!("built in (fixed by eigenfit {})", env!("CARGO_PKG_VERSION"))),
        });
    }

    /// Records the model of `--model`/`--preset`.
    pub fn model_source(&mut self, model: &crate::source::ModelArgs) {
        match (&model.model, &model.preset) {
            (Some(path), _) => self.input("model", path),
            (None, Some(name)) => {
                let name = match model.elements {
                    Some(n) => format!("preset {name} ({n} elements)"),
                    None => format!("preset {name}"),
                };
                self.builtin("model", &name);
            }
            (None, None) => {}
        }
    }

    /// The page.
    pub fn to_html(&self) -> String {
        let mut h = String::with_capacity(64 * 1024);
        let title = escape(&self.title);
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <meta name=\"generator\" content=\"eigenfit {version}\">\n\
             <title>{title}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<main>\n\
             <h1>{title}</h1>\n<p class=\"subtitle\">eigenfit {command} · eigenfit {version}</p>\n",
            version = env!("CARGO_PKG_VERSION"),
            command = escape(&self.command),
        );
        if let Some(v) = &self.verdict {
            let _ = write!(
                h,
                "<section id=\"verdict\" class=\"verdict {}\">\n<h2>Verdict: <span class=\"word\">{}</span></h2>\n\
                 <p class=\"meaning\">{}</p>\n</section>\n",
                if v.good { "good" } else { "bad" },
                escape(&v.word),
                escape(&v.meaning)
            );
        }
        for s in &self.sections {
            let _ = writeln!(h, "<section>\n<h2>{}</h2>", escape(&s.heading));
            for b in &s.blocks {
                render_block(&mut h, b);
            }
            h.push_str("</section>\n");
        }
        self.render_provenance(&mut h);
        h.push_str("</main>\n</body>\n</html>\n");
        h
    }

    fn render_provenance(&self, h: &mut String) {
        h.push_str("<section id=\"provenance\">\n<h2>Provenance</h2>\n");
        h.push_str(
            "<table class=\"inputs\">\n<caption>Inputs: what these results were computed from</caption>\n",
        );
        h.push_str("<thead><tr><th>input</th><th>file</th><th>SHA-256</th><th>size [bytes]</th></tr></thead>\n<tbody>\n");
        for i in &self.inputs {
            let (hash, size) = match &i.digest {
                Ok((hex, size)) => (format!("<code class=\"sha256\">{hex}</code>"), size.to_string()),
                Err(why) => (escape(why), "—".to_string()),
            };
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td><code>{}</code></td><td>{hash}</td><td class=\"num\">{size}</td></tr>",
                escape(&i.role),
                escape(&i.name)
            );
        }
        h.push_str("</tbody>\n</table>\n<dl>\n");
        let _ = write!(
            h,
            "<dt>command line</dt><dd><code class=\"command-line\">{}</code></dd>\n\
             <dt>eigenfit version</dt><dd class=\"version\">{}</dd>\n\
             <dt>written</dt><dd>{} (UTC)</dd>\n</dl>\n</section>\n",
            escape(&self.command_line),
            env!("CARGO_PKG_VERSION"),
            eigenfit_workflow::test_data::utc_date()
        );
    }

    /// Writes the page to `path` atomically (a temporary file renamed into place: never half a
    /// file).
    pub fn write(&self, path: &Path) -> Result<(), CliError> {
        crate::output::write_atomically(path, self.to_html().as_bytes())
    }

    /// Writes the page to `path` after the results were printed: a failure says what was lost
    /// (the results stand, the command keeps its exit code), success says where it went (not
    /// with `--json`, whose standard output is the JSON alone).
    pub fn write_after(&self, path: &Path, json: bool) {
        match self.write(path) {
            Ok(()) if !json => println!("wrote {}", path.display()),
            Ok(()) => {}
            Err(e) => crate::output::report_lost("the HTML report", &e),
        }
    }
}

fn render_block(h: &mut String, b: &Block) {
    match b {
        Block::Text(t) => {
            let _ = writeln!(h, "<p>{}</p>", escape(t));
        }
        Block::List(items) => {
            h.push_str("<ul>\n");
            for i in items {
                let _ = writeln!(h, "<li>{}</li>", escape(i));
            }
            h.push_str("</ul>\n");
        }
        Block::Table(t) => {
            let _ = write!(
                h,
                "<table class=\"{}\">\n<caption>{}</caption>\n<thead><tr>",
                escape(&t.class),
                escape(&t.caption)
            );
            for c in &t.head {
                let _ = write!(h, "<th>{}</th>", escape(c));
            }
            h.push_str("</tr></thead>\n<tbody>\n");
            for row in &t.rows {
                h.push_str("<tr>");
                for c in row {
                    match c.value {
                        Some(v) => {
                            let _ =
                                write!(h, "<td class=\"num\" data-value=\"{v:e}\">{}</td>", escape(&c.text));
                        }
                        None => {
                            let _ = write!(h, "<td>{}</td>", escape(&c.text));
                        }
                    }
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</tbody>\n</table>\n");
        }
        Block::Figure { caption, svg } => {
            // The SVG's own XML declaration, if any, does not belong inside HTML.
            let svg = svg.trim_start();
            let svg = match svg.strip_prefix("<?xml") {
                Some(rest) => rest.split_once("?>").map_or(svg, |(_, s)| s.trim_start()),
                None => svg,
            };
            let _ = write!(h, "<figure>\n{svg}\n<figcaption>{}</figcaption>\n</figure>\n", escape(caption));
        }
    }
}

/// The page's whole style: system fonts only, nothing loaded.
const CSS: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,'DejaVu Sans',sans-serif;color:#1e1e1e;background:#fff;margin:0}\
main{max-width:1100px;margin:0 auto;padding:1.5em}\
h1{font-size:1.6em;margin-bottom:.2em}h2{font-size:1.25em;margin-top:1.6em;border-bottom:1px solid #ddd}\
.subtitle{color:#666;margin-top:0}\
.verdict{border-left:.5em solid;padding:.4em 1em;border-radius:4px}\
.verdict h2{border:none;margin:.3em 0}\
.verdict.good{border-color:#009e73;background:#eaf7f2}.verdict.bad{border-color:#d55e00;background:#fcefe6}\
table{border-collapse:collapse;margin:1em 0;font-size:.95em}\
caption{text-align:left;font-weight:600;padding-bottom:.3em}\
th,td{border-bottom:1px solid #e2e2e2;padding:.3em .8em;text-align:left;vertical-align:top}\
th{background:#f4f4f4}td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\
figure{margin:1em 0}figure svg{max-width:100%;height:auto;border:1px solid #eee}\
figcaption{color:#444;font-size:.95em}\
code{font-family:ui-monospace,'DejaVu Sans Mono',monospace;font-size:.9em;word-break:break-all}\
dt{font-weight:600;margin-top:.5em}dd{margin-left:1.5em}\
@media print{main{max-width:none}figure{break-inside:avoid}}";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_markup_and_quotes() {
        assert_eq!(escape(r#"<b a="x">&'"#), "&lt;b a=&quot;x&quot;&gt;&amp;&#39;");
    }

    #[test]
    fn numbers_keep_their_significant_digits_and_their_power_of_ten() {
        assert_eq!(number(123456.0, 4), "1.235 × 10⁵");
        assert_eq!(number(0.000_012_5, 3), "1.25 × 10⁻⁵");
        assert_eq!(number(12.5, 4), "12.50");
        assert_eq!(number(-0.5, 2), "-0.50");
        assert_eq!(number(f64::NAN, 4), "—");
    }

    #[test]
    fn shell_words_are_quoted_only_when_needed() {
        assert_eq!(shell_quote("--measured=a.csv"), "--measured=a.csv");
        assert_eq!(shell_quote("my file's.csv"), r"'my file'\''s.csv'");
        assert_eq!(shell_quote(""), "''");
    }

    /// The known SHA-256 of "abc" (FIPS 180-2, appendix B.1).
    #[test]
    fn file_digests_are_sha256() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("abc");
        std::fs::write(&path, b"abc").unwrap();
        let (hex, size) = sha256_file(&path).unwrap();
        assert_eq!(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
        assert_eq!(size, 3);
    }

    #[test]
    fn user_text_is_escaped_everywhere_it_appears() {
        let mut r = Report::new("estimate", "<script>alert(1)</script>");
        r.verdict(false, "poor-fit <x>", "a & b");
        let mut t = Table::new("parameters", "caption <i>", &["name <u>"]);
        t.row(vec![Cell::text("<img src=x>"), Cell::number(1.0, 3)]);
        r.section("<h9>").table(t).text("\"quoted\"").list(vec!["<li>".into()]);
        r.inputs.push(Input { role: "model".into(), name: "a<b>.toml".into(), digest: Err("<why>".into()) });
        r.command_line = "eigenfit '<x>'".into();
        let html = r.to_html();
        for raw in ["<script>", "<x>", "<i>", "<u>", "<img", "<h9>", "<li><li>", "a<b>", "<why>", "'<x>'"] {
            assert!(!html.contains(raw), "unescaped `{raw}` in the page");
        }
        assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    }
}
