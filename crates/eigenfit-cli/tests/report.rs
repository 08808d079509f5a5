//! `--report FILE.html` (issue 33): one self-contained page, checked in a real headless browser
//! (Debian's `chromium`): the DOM it builds from the file shows the verdict, every parameter with
//! its value and unit, the plots as SVG and the inputs' SHA-256, and the browser's network log
//! holds no request. Without chromium these tests fail, saying how to install it; set
//! EIGENFIT_SKIP_BROWSER=1 to skip the browser part on a machine that cannot have one.

mod common;

use common::eigenfit;

use serde_json::Value;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn json(out: &Output) -> Value {
    let stdout = String::from_utf8(out.stdout.clone()).expect("utf-8");
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn example(name: &str) -> String {
    format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn sha256(path: &Path) -> String {
    let digest = Sha256::digest(std::fs::read(path).expect("an input file"));
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// The browser, or `None` (with the reason printed) when EIGENFIT_SKIP_BROWSER=1. Missing
/// without that variable is a failure: CI installs it (scripts/test.sh).
fn chromium() -> Option<PathBuf> {
    if std::env::var("EIGENFIT_SKIP_BROWSER").is_ok_and(|v| v == "1") {
        eprintln!("EIGENFIT_SKIP_BROWSER=1: the report is not rendered in a browser in this run");
        return None;
    }
    let found = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .map(|d| d.join("chromium"))
        .find(|p| p.is_file());
    match found {
        Some(p) => Some(p),
        None => panic!(
            "chromium is not installed: the HTML report is checked in a real browser \
             (apt-get install chromium, as scripts/test.sh does), or set EIGENFIT_SKIP_BROWSER=1 to skip"
        ),
    }
}

/// What the browser made of `page`: its DOM after loading (`--dump-dom`) and every URL the page
/// asked for in the browser's network log (`--log-net-log`), file: URLs left out.
struct Rendered {
    dom: String,
    requests: Vec<String>,
}

fn render(browser: &Path, page: &Path) -> Rendered {
    let scratch = common::scratch();
    let netlog = scratch.path().join("netlog.json");
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            // The browser's own traffic (updates, safe browsing) is not the page's.
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--no-default-browser-check",
            "--metrics-recording-only",
        ])
        .arg(format!("--user-data-dir={}", scratch.path().join("profile").display()))
        .arg(format!("--log-net-log={}", netlog.display()))
        .arg("--dump-dom")
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success() && dom.contains("</html>"),
        "chromium did not render {}: {}",
        page.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let log = std::fs::read_to_string(&netlog).expect("chromium wrote its network log");
    // One event a line. The page's own requests are those made for the file:// page (its
    // network isolation key); the browser's own traffic (update checks, time) is keyed apart.
    let mut requests: Vec<String> = log
        .lines()
        .filter(|l| l.contains("\"network_isolation_key\":\"file://"))
        .filter_map(|l| l.split("\"url\":\"").nth(1))
        .filter_map(|s| s.split('"').next())
        .filter(|u| !u.starts_with("file:"))
        .map(str::to_string)
        .collect();
    requests.sort();
    requests.dedup();
    Rendered { dom, requests }
}

/// The page as the browser paints it, 1200 px wide, tall enough for the whole report.
fn screenshot(browser: &Path, page: &Path) -> image::RgbImage {
    let scratch = common::scratch();
    let png = scratch.path().join("page.png");
    let out = Command::new(browser)
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--hide-scrollbars"])
        .arg(format!("--user-data-dir={}", scratch.path().join("profile").display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg("--window-size=1200,4000")
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(png.is_file(), "no screenshot: {}", String::from_utf8_lossy(&out.stderr));
    image::open(&png).expect("a PNG").to_rgb8()
}

/// Checks the page's text for what makes it self-contained: nothing loaded from elsewhere.
fn self_contained(html: &str) {
    for banned in ["<script", "<link", "<iframe", "<img", "@import", "url("] {
        assert!(!html.contains(banned), "the report holds `{banned}`");
    }
    // The only address in the page is SVG's namespace, which is a name, not a request.
    let addresses = html.matches("http://").count() + html.matches("https://").count();
    let namespaces = html.matches("xmlns=\"http://www.w3.org/2000/svg\"").count();
    assert_eq!(addresses, namespaces, "the report names an address other than the SVG namespace");
}

/// The rows of the table of class `class` in `dom`: each row's cells as (text, data-value).
fn rows(dom: &str, class: &str) -> Vec<Vec<(String, Option<f64>)>> {
    let start = dom.find(&format!("<table class=\"{class}\"")).unwrap_or_else(|| panic!("no {class} table"));
    let table = &dom[start..start + dom[start..].find("</table>").expect("table closed")];
    let body = &table[table.find("<tbody>").expect("a body")..];
    body.split("<tr>")
        .skip(1)
        .map(|row| {
            row.split("<td")
                .skip(1)
                .map(|cell| {
                    let (attrs, rest) = cell.split_once('>').expect("a cell");
                    let text = rest.split("</td>").next().unwrap_or("").to_string();
                    let value = attrs
                        .split("data-value=\"")
                        .nth(1)
                        .and_then(|v| v.split('"').next())
                        .map(|v| v.parse::<f64>().expect("a number in data-value"));
                    (unescape(&text), value)
                })
                .collect()
        })
        .collect()
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// A number as the report shows it (`1.234 × 10⁵`, `-0.50`) back as a value.
fn shown(text: &str) -> f64 {
    let sup = |c: char| "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().position(|d| d == c);
    match text.split_once(" × 10") {
        Some((m, e)) => {
            let negative = e.starts_with('⁻');
            let digits: String = e.chars().filter_map(sup).map(|d| char::from(b'0' + d as u8)).collect();
            let e: i32 = digits.parse().expect("an exponent");
            m.parse::<f64>().expect("a mantissa") * 10f64.powi(if negative { -e } else { e })
        }
        None => text.parse().unwrap_or_else(|_| panic!("`{text}` is not a number")),
    }
}

/// The same number: the page's `data-value` is the shortest text that reads back as the value;
/// serde_json's default parser (no `float_roundtrip`) may read the JSON's text one ulp away.
fn same(shown: Option<f64>, json: Option<f64>) -> bool {
    match (shown, json) {
        (Some(a), Some(b)) => (a - b).abs() <= f64::EPSILON * a.abs().max(b.abs()),
        _ => false,
    }
}

/// The provenance lists `path` with its SHA-256.
fn lists_input(dom: &str, path: &Path) {
    let hash = sha256(path);
    assert!(dom.contains(&hash), "the provenance lacks {} ({hash})", path.display());
}

#[test]
fn an_estimate_report_shows_the_verdict_every_parameter_with_its_unit_the_plots_and_the_inputs() {
    let scratch = common::scratch();
    let page = scratch.path().join("estimate report.html");
    let measured = example("measured_no_effect.csv");
    let out = eigenfit(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        &measured,
        "--initial",
        "1e6,1e6",
        "--quiet",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).expect("the report was written");
    self_contained(&html);
    // No temporary file left beside it.
    let left: Vec<_> = std::fs::read_dir(scratch.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 1, "{left:?}");

    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "the page made requests: {:?}", r.requests);
    let dom = &r.dom;
    // The verdict, in the JSON's word, with its meaning.
    let verdict = v["verdict"].as_str().unwrap();
    assert!(dom.contains(&format!("<span class=\"word\">{verdict}</span>")), "verdict {verdict}");
    let good = v["acceptable"] == true && v["unique"] == true;
    assert!(dom.contains(if good { "class=\"verdict good\"" } else { "class=\"verdict bad\"" }));
    assert!(dom.contains("class=\"meaning\""));
    // Each parameter: its name, its unit, the estimate exactly (data-value) and as shown.
    let params = v["parameters"].as_object().unwrap();
    let table = rows(dom, "parameters");
    assert_eq!(table.len(), params.len());
    // JSON objects come sorted by name; the page keeps the model's order.
    for row in &table {
        let name = &row[0].0;
        let value = &params[name];
        assert_eq!(row[1].0, "N/m", "{name}'s unit");
        let value = value.as_f64().unwrap();
        assert!(same(row[3].1, Some(value)), "{name}: the exact estimate in data-value");
        let text = shown(&row[3].0);
        assert!((text / value - 1.0).abs() < 5e-6, "{name}: shows {} for {value}", row[3].0);
        let iv = &v["intervals"][name];
        assert!(same(row[4].1, iv[0].as_f64()), "{name}: interval from");
        assert!(same(row[5].1, iv[1].as_f64()), "{name}: interval to");
    }
    // Each measured mode with both frequencies.
    let modes = rows(dom, "modes");
    let measured_hz = v["measured_hz"].as_array().unwrap();
    assert_eq!(modes.len(), measured_hz.len());
    for (row, (m, f)) in modes.iter().zip(measured_hz.iter().zip(v["frequencies_hz"].as_array().unwrap())) {
        assert!(same(row[1].1, m.as_f64()) && same(row[2].1, f.as_f64()), "{row:?}");
    }
    // The convergence plot, drawn inline: an SVG with its curves and its own legend text.
    assert!(dom.matches("<svg").count() >= 1, "no SVG in the page");
    assert!(dom.contains("<polyline") || dom.contains("<path"), "the SVG has no lines");
    assert!(dom.contains("convergence of the damped strategy"));
    // What the page shows on screen: the verdict's box in its colour and the plot's curves.
    let shot = screenshot(&browser, &page);
    let count = |rgb: [u8; 3]| shot.pixels().filter(|p| p.0 == rgb).count();
    let (box_colour, bad_colour) = ([0xea, 0xf7, 0xf2], [0xfc, 0xef, 0xe6]);
    assert!(count(if good { box_colour } else { bad_colour }) > 10_000, "no verdict box on screen");
    assert!(count([0, 114, 178]) > 200, "no curve of the convergence plot on screen");
    // Provenance: the measured file's SHA-256, the built-in model, the command line, the version.
    lists_input(dom, Path::new(&measured));
    assert!(dom.contains("preset paper-rotor"));
    assert!(dom.contains("class=\"command-line\"") && dom.contains("--report"));
    assert!(dom.contains(&format!("<dd class=\"version\">{}</dd>", env!("CARGO_PKG_VERSION"))));
}

/// The network check finds a request when there is one: the same browser on a page that loads
/// an image from an address logs it.
#[test]
fn the_network_check_sees_a_request_when_a_page_makes_one() {
    let Some(browser) = chromium() else { return };
    let scratch = common::scratch();
    let page = common::write_in(
        &scratch,
        "fetching.html",
        "<!DOCTYPE html><html><body><img src=\"http://eigenfit.invalid/x.png\"></body></html>",
    );
    let r = render(&browser, &page);
    assert!(r.requests.iter().any(|u| u.contains("eigenfit.invalid")), "{:?}", r.requests);
}

/// Units come from each parameter's declaration: a matrices model declaring two different units
/// shows each in its row.
#[test]
fn each_parameter_row_carries_its_own_declared_unit() {
    let scratch = common::scratch();
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    // The corpus's chain, its matrix files named by absolute path, with a unit declared on each
    // of its two [[parameter]] tables.
    let text = std::fs::read_to_string(corpus.join("chain_two_springs.toml"))
        .unwrap()
        .replace("\"K", &format!("\"{}/K", corpus.display()))
        .replace("\"M0", &format!("\"{}/M0", corpus.display()))
        .replacen("name = \"ground\"\n", "name = \"ground\"\nunit = \"N/m\"\n", 1)
        .replacen("name = \"coupling\"\n", "name = \"coupling\"\nunit = \"kN/m\"\n", 1);
    let model = common::write_in(&scratch, "chain.toml", &text);
    let page = scratch.path().join("r.html");
    let measured = corpus.join("chain_measured.csv");
    let out = eigenfit(&[
        "estimate",
        "--model",
        model.to_str().unwrap(),
        "--measured",
        measured.to_str().unwrap(),
        "--quiet",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&out.stderr));
    let html = std::fs::read_to_string(&page).expect("the report was written");
    let table = rows(&html, "parameters");
    let units: Vec<(&str, &str)> = table.iter().map(|r| (r[0].0.as_str(), r[1].0.as_str())).collect();
    assert_eq!(units, [("ground", "N/m"), ("coupling", "kN/m")]);
    lists_input(&html, &model);
    lists_input(&html, &measured);
}

#[test]
fn a_report_that_cannot_be_written_is_refused_before_the_fit() {
    let scratch = common::scratch();
    let missing = scratch.path().join("no such folder").join("r.html");
    for target in [missing.to_str().unwrap(), scratch.path().to_str().unwrap()] {
        let out = eigenfit(&[
            "estimate",
            "--preset",
            "paper-rotor",
            "--measured",
            &example("measured_no_effect.csv"),
            "--report",
            target,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("--report"), "{err}");
        // Refused before the fit: nothing printed on standard output.
        assert!(out.stdout.is_empty(), "{}", String::from_utf8_lossy(&out.stdout));
    }
}

#[test]
fn discover_writes_a_report_naming_the_missing_effect() {
    let scratch = common::scratch();
    let page = scratch.path().join("d.html");
    let measured = example("measured_hidden_effect.csv");
    let out = eigenfit(&[
        "discover",
        "--preset",
        "paper-rotor",
        "--measured",
        &measured,
        "--quiet",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).unwrap();
    self_contained(&html);
    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "{:?}", r.requests);
    assert!(r.dom.contains("<span class=\"word\">explained</span>"));
    let kind = v["missing_effect"]["kind"].as_str().unwrap();
    let effects = rows(&r.dom, "effects");
    assert!(effects[0][0].0.starts_with(kind), "{:?} is not the {kind}", effects[0][0]);
    assert!(same(effects[0][2].1, v["missing_effect"]["value"].as_f64()));
    let params = rows(&r.dom, "parameters");
    let calibrated = v["calibrated_parameters"].as_object().unwrap();
    assert_eq!(params.len(), calibrated.len());
    // JSON objects come sorted by name; the page keeps the model's order.
    for row in &params {
        let name = &row[0].0;
        let value = &calibrated[name];
        assert_eq!(row[1].0, "N/m", "{name}'s unit");
        assert!(same(row[2].1, value.as_f64()), "{name}");
    }
    // Each mode as the JSON numbers it (from 1), with both frequencies.
    let modes = rows(&r.dom, "modes");
    let json_modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), json_modes.len());
    for (row, m) in modes.iter().zip(json_modes) {
        assert_eq!(row[0].1, m["mode"].as_f64(), "{row:?}");
        assert!(
            same(row[1].1, m["measured_hz"].as_f64()) && same(row[5].1, m["after_hz"].as_f64()),
            "{row:?}"
        );
    }
    assert!(r.dom.contains("<svg"), "the residual plot");
    lists_input(&r.dom, Path::new(&measured));
}

#[test]
fn campbell_writes_a_report_with_the_diagram_and_the_margins() {
    let model = common::data_file("../eigenfit-rotordynamics/tests/data", "rotor_example.toml");
    let scratch = common::scratch();
    let page = scratch.path().join("c.html");
    let out = eigenfit(&[
        "campbell",
        "--model",
        &model,
        "--speeds",
        "0:15000:31",
        "--modes",
        "4",
        "--operating",
        "4000:8000",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).unwrap();
    self_contained(&html);
    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "{:?}", r.requests);
    let margins = v["separation_margins"].as_array().unwrap();
    let passes = margins.iter().all(|m| m["passes"] == true);
    assert!(r.dom.contains(if passes { ">margins pass<" } else { ">margins fail<" }));
    let speeds = v["critical_speeds_rpm"].as_array().unwrap();
    if !speeds.is_empty() {
        let table = rows(&r.dom, "critical-speeds");
        assert_eq!(table.len(), speeds.len());
        for (row, rpm) in table.iter().zip(speeds) {
            assert!(same(row[0].1, rpm.as_f64()), "{:?} vs {rpm}", row[0]);
        }
    }
    assert!(r.dom.contains("Campbell diagram</text>") || r.dom.contains("Campbell diagram"));
    assert!(r.dom.contains("<svg"));
    lists_input(&r.dom, Path::new(&model));
}

#[test]
fn bench_writes_a_report_with_the_summary_and_both_plots() {
    let scratch = common::scratch();
    let page = scratch.path().join("b.html");
    let out = eigenfit(&[
        "bench",
        "--problems",
        "paper-table2",
        "--strategies",
        "newton,damped",
        "--starts",
        "2",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).unwrap();
    self_contained(&html);
    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "{:?}", r.requests);
    let table = rows(&r.dom, "summary");
    let summary = v["summary"].as_array().unwrap();
    assert_eq!(table.len(), summary.len());
    for (row, s) in table.iter().zip(summary) {
        assert_eq!(row[1].0, s["strategy"].as_str().unwrap());
        assert!(same(row[3].1, s["success_rate"].as_f64().map(|x| 100.0 * x)), "{row:?}");
    }
    assert_eq!(r.dom.matches("<svg").count(), 2, "the profile and the ECDF");
}

/// A campaign's page lists the campaign file and every file it names with their SHA-256, and
/// shows the joint parameters with the units the model declares; a configuration's name is
/// escaped like every user text.
#[test]
fn campaign_writes_a_report_listing_every_file_the_campaign_names() {
    let scratch = common::scratch();
    let dir = scratch.path();
    std::fs::copy(example("rotor.toml"), dir.join("rotor.toml")).unwrap();
    std::fs::copy(example("measured_no_effect.csv"), dir.join("run.csv")).unwrap();
    let campaign = common::write_in(
        &scratch,
        "campaign.toml",
        "[[configuration]]\nname = \"as <built>\"\nmodel = \"rotor.toml\"\nmeasured = \"run.csv\"\n",
    );
    let page = dir.join("c.html");
    let out = eigenfit(&[
        "campaign",
        campaign.to_str().unwrap(),
        "--quiet",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).unwrap();
    self_contained(&html);
    assert!(!html.contains("<built>") && html.contains("as &lt;built&gt;"), "the name is not escaped");
    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "{:?}", r.requests);
    for file in ["campaign.toml", "rotor.toml", "run.csv"] {
        lists_input(&r.dom, &dir.join(file));
    }
    let table = rows(&r.dom, "parameters");
    let params = v["parameters"].as_object().unwrap();
    assert_eq!(table.len(), params.len());
    // JSON objects come sorted by name; the page keeps the model's order.
    for row in &table {
        let name = &row[0].0;
        let value = &params[name];
        assert_eq!(row[1].0, "N/m", "{name}'s unit");
        assert!(same(row[3].1, value.as_f64()), "{name}");
    }
    assert!(r.dom.contains("<span class=\"word\">"), "no verdict");
}

/// A ROSS run-up fit's page: each bearing coefficient in its unit (stiffnesses N/m, damping
/// N·s/m), each run-up point, the verdict, and the figures `--plot` draws: the run-up fit, the
/// estimated rotor's Campbell diagram, its mode shapes and orbits, the convergence.
#[test]
fn a_runup_estimate_report_gives_each_coefficient_its_unit() {
    let data = |name: &str| common::data_file("../eigenfit-rotordynamics/tests/data", name);
    let (model, measured) = (data("runup_nominal.toml"), data("runup_truth.csv"));
    let scratch = common::scratch();
    let page = scratch.path().join("runup.html");
    let out = eigenfit(&[
        "estimate",
        "--model",
        &model,
        "--measured",
        &measured,
        "--parameters",
        "kxx,cyy",
        "--quiet",
        "--json",
        "--report",
        page.to_str().unwrap(),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    let html = std::fs::read_to_string(&page).unwrap();
    self_contained(&html);
    let captions: Vec<&str> =
        html.split("<figcaption>").skip(1).map(|c| c.split("</figcaption>").next().unwrap()).collect();
    assert_eq!(captions.len(), 4, "{captions:?}");
    for (caption, starts) in
        captions.iter().zip(["Run-up fit", "Campbell diagram", "Mode shapes", "Convergence"])
    {
        assert!(caption.starts_with(starts), "{caption}");
    }
    assert!(!html.contains("could not be computed"));
    let Some(browser) = chromium() else { return };
    let r = render(&browser, &page);
    assert!(r.requests.is_empty(), "{:?}", r.requests);
    assert!(r.dom.contains(&format!("<span class=\"word\">{}</span>", v["verdict"].as_str().unwrap())));
    let table = rows(&r.dom, "parameters");
    let params = v["parameters"].as_object().unwrap();
    assert_eq!(table.len(), params.len());
    // JSON objects come sorted by name; the page keeps the model's order.
    for row in &table {
        let name = &row[0].0;
        let value = &params[name];
        let unit = if name.starts_with("kxx") { "N/m" } else { "N·s/m" };
        assert_eq!(row[1].0, unit, "{name}'s unit");
        assert!(same(row[3].1, value.as_f64()), "{name}");
    }
    let points = rows(&r.dom, "modes");
    assert_eq!(points.len(), v["points"].as_array().unwrap().len());
    for (row, p) in points.iter().zip(v["points"].as_array().unwrap()) {
        assert!(
            same(row[0].1, p["speed_rpm"].as_f64()) && same(row[2].1, p["measured_hz"].as_f64()),
            "{row:?}"
        );
    }
    lists_input(&r.dom, Path::new(&model));
    lists_input(&r.dom, Path::new(&measured));
}
