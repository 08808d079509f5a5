//! Plots (issue: the product face): every `--plot` writes its SVG and PNG, the SVG carries the
//! expected titles, axes and legend entries, the PNG is a real image; `eigenfit demo` writes every
//! plot kind; progress bars stay off stderr when it is not a terminal.

mod common;

use common::eigenfit;

use serde_json::Value;
use std::path::Path;
use std::process::Output;

fn json(out: &Output) -> Value {
    let stdout = String::from_utf8(out.stdout.clone()).expect("utf-8");
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

/// Runs `eigenfit ARGS… --plot DIR` with DIR a fresh folder (removed when the first value is
/// dropped); checks the run ended with exit code 0.
fn plotted(args: &[&str]) -> (tempfile::TempDir, Output) {
    let scratch = common::scratch();
    let dir = scratch.path().to_str().expect("a UTF-8 temporary path").to_string();
    let mut all = args.to_vec();
    all.extend(["--plot", dir.as_str()]);
    let out = eigenfit(&all);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    (scratch, out)
}

fn example(name: &str) -> String {
    format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Checks `DIR/STEM.svg` (well-formed enough, with every `expected` text) and `DIR/STEM.png`
/// (PNG signature, an IHDR of a sensible size, more than a blank image's bytes).
fn check_plot(dir: &Path, stem: &str, expected: &[&str]) {
    let svg_path = dir.join(format!("{stem}.svg"));
    let svg = std::fs::read_to_string(&svg_path).unwrap_or_else(|e| panic!("{}: {e}", svg_path.display()));
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{stem}.svg is not an SVG document"
    );
    assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count(), "{stem}.svg: unbalanced <text>");
    assert!(svg.matches('<').count() > 50, "{stem}.svg has almost nothing drawn");
    for text in expected {
        assert!(svg.contains(text), "{stem}.svg lacks `{text}`");
    }
    let png_path = dir.join(format!("{stem}.png"));
    let png = std::fs::read(&png_path).unwrap_or_else(|e| panic!("{}: {e}", png_path.display()));
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png: not a PNG");
    assert_eq!(&png[12..16], b"IHDR");
    let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert!(
        (600..=3000).contains(&width) && (400..=3000).contains(&height),
        "{stem}.png is {width}×{height}"
    );
    assert!(png.len() > 20_000, "{stem}.png is only {} bytes: no text or lines drawn?", png.len());
    // No temporary file is left behind by the atomic writes.
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn simulate_plots_the_critical_speed_map_with_table_1_and_the_mode_shapes() {
    let (scratch, out) =
        plotted(&["simulate", "--preset", "paper-rotor", "--stiffness", "1e5,1e5", "--modes", "3", "--json"]);
    let dir = scratch.path();
    let v = json(&out);
    assert_eq!(v["frequencies_hz"].as_array().unwrap().len(), 3, "the JSON contract is unchanged");
    assert_eq!(v["plots"].as_array().unwrap().len(), 4);
    check_plot(
        dir,
        "critical-speed-map",
        &[
            "paper-rotor: critical speed map",
            "support stiffness k [N/m]",
            "natural frequency f [Hz]",
            "model, mode 1",
            "model, mode 3",
            "paper, Table 1 (modes 1–2)",
        ],
    );
    check_plot(
        dir,
        "mode-shapes",
        &[
            "position along the shaft x [m]",
            "displacement (normalised to the largest) [–]",
            "mode 1: 36.107 Hz",
            "mode 3:",
            "disk 1.35 kg",
            "disk 0.4 kg",
            "K1 = 1e5 N/m",
            "K2 = 1e5 N/m",
        ],
    );
    // What is drawn is what was asked: three modes, not a fixed four.
    for stem in ["critical-speed-map", "mode-shapes"] {
        let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
        assert!(!svg.contains("mode 4"), "{stem}.svg draws a mode that was not asked for");
    }
}

#[test]
fn a_model_file_gets_no_table_1_overlay() {
    let (scratch, out) = plotted(&["simulate", "--model", &example("rotor.toml"), "--sweep", "1e3:1e8:6"]);
    let dir = scratch.path();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("f1 [Hz]") && stdout.contains("wrote "), "{stdout}");
    check_plot(dir, "critical-speed-map", &["support stiffness k [N/m]", "model, mode 1"]);
    let svg = std::fs::read_to_string(dir.join("critical-speed-map.svg")).unwrap();
    assert!(!svg.contains("Table 1"));
}

#[test]
fn estimate_plots_its_convergence_history() {
    let scratch = common::scratch();
    let dir = scratch.path().to_path_buf();
    let csv = dir.join("m.csv");
    std::fs::write(&csv, "mode,frequency_hz\n1,36.107\n2,84.066\n").unwrap();
    let more = ["--plot", dir.to_str().unwrap(), "--json"];
    let out = eigenfit(&common::paper_estimate(csv.to_str().unwrap(), "newton", "1e2,1e2", &more));
    // Table 3 case 1's two frequencies have a second exact solution (docs/strategies.md): the
    // run converges, the data cannot choose, exit 3.
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    assert_eq!(v["converged"], true);
    assert_eq!(v["verdict"], "not-unique");
    assert_eq!(v["plots"].as_array().unwrap().len(), 2);
    check_plot(
        &dir,
        "convergence",
        &[
            "convergence of the newton strategy",
            "iteration",
            "parameter [N/m]",
            "max |f − f_measured| [Hz]",
            "k_K1",
            "k_K2",
            "newton (converged,",
            "newton tolerance, 0.01 Hz",
        ],
    );
}

/// A Campbell diagram's speed axis reads `1000`, not `1000.0`; every tick carries a number.
#[test]
fn campbell_ticks_are_whole_rpm() {
    let model = common::data_file("../eigenfit-rotordynamics/tests/data", "rotor_example.toml");
    let (scratch, _) = plotted(&["campbell", "--model", &model, "--speeds", "0:15000:16", "--modes", "4"]);
    let svg = std::fs::read_to_string(scratch.path().join("campbell.svg")).unwrap();
    let ticks: Vec<&str> = svg
        .split("<text")
        .filter_map(|t| t.split_once('>').map(|(_, rest)| rest.split("</text>").next().unwrap_or("").trim()))
        .filter(|t| t.parse::<f64>().is_ok())
        .collect();
    assert!(ticks.iter().any(|t| t.ends_with("000")), "no thousands on the speed axis: {ticks:?}");
    assert!(!ticks.iter().any(|t| t.ends_with(".0")), "a tick printed with a trailing .0: {ticks:?}");
    // Every tick mark (a 5 px black stroke off an axis) carries a number.
    let marks = svg
        .split("<polyline")
        .skip(1)
        .map(|l| l.split("/>").next().unwrap_or(""))
        .filter(|l| l.contains("stroke=\"#000000\""))
        .filter_map(|l| l.split("points=\"").nth(1).and_then(|p| p.split('"').next()))
        .filter(|p| {
            let xy: Vec<i32> = p.split([' ', ',']).filter_map(|v| v.parse().ok()).collect();
            matches!(xy[..], [x1, y1, x2, y2] if (y1 == y2 && (x2 - x1).abs() == 5) || (x1 == x2 && (y2 - y1).abs() == 5))
        })
        .count();
    assert_eq!(marks, ticks.len(), "tick marks without a number: {ticks:?}");
}

/// The parameter axis carries numbers over its whole range: from 1e6 down to the 5e4 N/m the
/// fit ends at, plotters' own ticks labelled only 10⁵ and 10⁶ (nothing below 1e5), and from 1e4
/// crowded nine labels into one decade.
#[test]
fn the_convergence_plots_parameter_axis_is_labelled_below_1e5() {
    for (initial, expected, crowded) in
        [("1e6,1e6", ["10⁵", "5·10⁴", "2·10⁴"], "3·10⁴"), ("1e4,1e4", ["10⁴", "5·10⁴", "2·10⁵"], "7·10⁴")]
    {
        let measured = example("measured_no_effect.csv");
        let (scratch, _) = plotted(&[
            "estimate",
            "--preset",
            "paper-rotor",
            "--measured",
            &measured,
            "--initial",
            initial,
            "--quiet",
        ]);
        let svg = std::fs::read_to_string(scratch.path().join("convergence.svg")).unwrap();
        for label in expected {
            assert!(svg.contains(label), "from {initial}: no `{label}` on the parameter axis");
        }
        assert!(!svg.contains(crowded), "from {initial}: `{crowded}`: the decade is crowded with labels");
        // The σ line's legend: three digits of the file's largest std_hz (2.0492 Hz), not 2·10⁰.
        assert!(svg.contains("largest measurement σ, 2.05 Hz"), "from {initial}: σ legend");
    }
}

#[test]
fn compare_plots_convergence_and_iteration_maps() {
    let (scratch, out) = plotted(&common::paper_compare("1e5:1e5", "4", &["--strategies", "newton,damped"]));
    let dir = scratch.path();
    // Not a terminal: no progress bar on stderr.
    assert!(out.stderr.is_empty(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("target [N/m]") && stdout.contains("it. med"), "{stdout}");
    for stem in ["compare-convergence", "compare-iterations"] {
        check_plot(
            dir,
            stem,
            &[
                "initial k_K1 [N/m]",
                "initial k_K2 [N/m]",
                "newton · target 1e5, 1e5 N/m",
                "damped · target 1e5, 1e5 N/m",
            ],
        );
    }
    let svg = std::fs::read_to_string(dir.join("compare-convergence.svg")).unwrap();
    for legend in
        ["converged to the target (within 10 %)", "converged elsewhere", "no convergence", "the target"]
    {
        assert!(svg.contains(legend), "{legend}");
    }
    let svg = std::fs::read_to_string(dir.join("compare-iterations.svg")).unwrap();
    assert!(svg.contains("iterations from each initial guess") && svg.contains(">\niterations\n<"));
}

#[test]
fn discover_plots_the_residual_before_and_after_with_the_noise_band() {
    let (scratch, out) = plotted(&[
        "discover",
        "--preset",
        "paper-rotor",
        "--measured",
        &example("measured_hidden_effect.csv"),
        "--json",
    ]);
    let dir = scratch.path();
    let v = json(&out);
    let written: Vec<&str> = v["written"].as_array().unwrap().iter().map(|w| w.as_str().unwrap()).collect();
    assert!(
        written.iter().any(|w| w.ends_with("discovery.svg"))
            && written.iter().any(|w| w.ends_with("discovery.png"))
    );
    check_plot(
        dir,
        "discovery",
        &[
            "residual per mode before and after discovery",
            "(model − measured) / σ",
            "mode",
            "±2σ noise band",
            "before: stiffnesses calibrated, nominal model",
            "after: with disk-rotary-inertia@0",
            "+2σ",
            "−2σ",
        ],
    );
}

#[test]
fn demo_writes_every_plot_kind_and_reports() {
    let scratch = common::scratch();
    let dir = scratch.path().to_path_buf();
    let out_dir = dir.join("report");
    let out = eigenfit(&["demo", "--out", out_dir.to_str().unwrap(), "--grid", "4"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    for part in
        ["1. Table 1", "paper [Hz]", "model [Hz]", "diff [%]", "2. Table 3 case 1", "damped", "4. Discovery"]
    {
        assert!(stdout.contains(part), "report lacks `{part}`:\n{stdout}");
    }
    assert!(stdout.contains("missing effect: disk-rotary-inertia@0"), "{stdout}");
    assert!(stdout.contains(&format!("written to {}", std::fs::canonicalize(&out_dir).unwrap().display())));
    let kinds = [
        "critical-speed-map",
        "mode-shapes",
        "convergence",
        "compare-convergence",
        "compare-iterations",
        "discovery",
    ];
    for stem in kinds {
        check_plot(&out_dir, stem, &["paper-rotor"]);
    }
    let svg = std::fs::read_to_string(out_dir.join("convergence.svg")).unwrap();
    for strategy in ["newton · k_K1", "p-step · k_K1", "damped · k_K1", "target"] {
        assert!(svg.contains(strategy), "convergence.svg lacks {strategy}");
    }
}

#[test]
fn demo_json_lists_the_results_and_the_plots() {
    let scratch = common::scratch();
    let dir = scratch.path().to_path_buf();
    let out = eigenfit(&["demo", "--out", dir.to_str().unwrap(), "--grid", "3", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v = json(&out);
    assert_eq!(v["table_1"].as_array().unwrap().len(), 18);
    let estimates = v["table_3_case_1"]["estimates"].as_array().unwrap();
    assert_eq!(estimates.len(), 3);
    for e in estimates {
        assert_eq!(e["converged"], true, "{e}");
        let k1 = e["parameters"][0].as_f64().unwrap();
        assert!((k1 / 1e5 - 1.0).abs() < 1e-3, "{e}");
    }
    assert_eq!(v["discovery"]["kind"], "disk-rotary-inertia");
    assert_eq!(v["plots"].as_array().unwrap().len(), 12);
}

/// Asked for more modes than a plot can tell apart, both plots draw the lowest six and say so.
#[test]
fn plots_of_fewer_modes_than_asked_say_so() {
    let (scratch, _) = plotted(&["simulate", "--preset", "paper-rotor", "--modes", "8", "--quiet"]);
    let map = std::fs::read_to_string(scratch.path().join("critical-speed-map.svg")).unwrap();
    assert!(map.contains("(the lowest 6 of the 8 modes asked)"), "the map does not say it drew 6 of 8");
    assert!(map.contains("model, mode 6") && !map.contains("model, mode 7"));
    let shapes = std::fs::read_to_string(scratch.path().join("mode-shapes.svg")).unwrap();
    assert!(shapes.contains("(the lowest 6 of the 8 modes asked: more would not be told apart)"));
    assert!(shapes.contains("mode 6:") && !shapes.contains("mode 7:"));
}

/// A benchmark's evaluations axis carries numbers even over less than a decade (3 starts of
/// one problem: an ECDF between 15 and 60 evaluations had no label), and every tick has one.
/// (One strategy that reaches the truth every time: the helper expects exit code 0.)
#[test]
fn bench_plots_label_every_tick_of_the_evaluations_axis() {
    let (scratch, _) = plotted(&[
        "bench",
        "--problems",
        "paper-table2",
        "--strategies",
        "damped",
        "--starts",
        "3",
        "--quiet",
    ]);
    for stem in ["bench_ecdf", "bench_profile"] {
        let svg = std::fs::read_to_string(scratch.path().join(format!("{stem}.svg"))).unwrap();
        let texts: Vec<&str> = svg
            .split("<text")
            .filter_map(|t| {
                t.split_once('>').map(|(_, rest)| rest.split("</text>").next().unwrap_or("").trim())
            })
            .collect();
        // Numbers on the log axis read `10¹`, `2·10¹`; on the fraction axis `0.5`.
        let numeric =
            |t: &str| !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || ".·⁰¹²³⁴⁵⁶⁷⁸⁹⁻".contains(c));
        let log_labels = texts.iter().filter(|t| numeric(t) && t.contains("10")).count();
        assert!(log_labels >= 1, "{stem}: no number on the evaluations axis: {texts:?}");
        let marks = svg
            .split("<polyline")
            .skip(1)
            .map(|l| l.split("/>").next().unwrap_or(""))
            .filter(|l| l.contains("stroke=\"#000000\""))
            .filter_map(|l| l.split("points=\"").nth(1).and_then(|p| p.split('"').next()))
            .filter(|p| {
                let xy: Vec<i32> = p.split([' ', ',']).filter_map(|v| v.parse().ok()).collect();
                matches!(xy[..], [x1, y1, x2, y2] if (y1 == y2 && (x2 - x1).abs() == 5) || (x1 == x2 && (y2 - y1).abs() == 5))
            })
            .count();
        assert_eq!(
            marks,
            texts.iter().filter(|t| numeric(t)).count(),
            "{stem}: tick marks without a number: {texts:?}"
        );
    }
}
