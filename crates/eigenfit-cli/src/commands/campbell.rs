//! `eigenfit campbell`: damped frequencies of a two-plane (ROSS) rotor against speed in rpm,
//! with whirl, log decrement and the critical speeds where followed modes cross the 1× line.

use crate::error::CliError;
use crate::plot;
use crate::plot::campbell::CampbellPlot;
use clap::Args;
use eigenfit_workflow::rotordynamics::campbell_diagram_with;
use std::path::PathBuf;

/// Arguments of `campbell`.
#[derive(Debug, Args)]
pub struct CampbellArgs {
    /// Rotor file written by ROSS `Rotor.save` (TOML or JSON).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// Speeds in rpm, linearly spaced FROM:TO:COUNT.
    #[arg(long, value_name = "FROM:TO:COUNT")]
    pub speeds: String,
    /// Number of modes (lowest damped frequencies) per speed.
    #[arg(long, default_value_t = 6)]
    pub modes: usize,
    /// Operating speed range FROM:TO in rpm: each critical speed's separation margin from it, API
    /// 684 style (the margin required from the amplification factor 1/(2ζ)).
    #[arg(long, value_name = "FROM:TO")]
    pub operating: Option<String>,
    /// Write the diagram (campbell.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--quiet` (accepted like every other command's; campbell shows no progress indicator),
    /// `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// `--report FILE.html`.
    #[command(flatten)]
    pub html: crate::report::HtmlArgs,
}

/// Runs `campbell`.
pub fn run(args: &CampbellArgs) -> Result<(), CliError> {
    // Every output is checked writable before the diagram is computed.
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    args.html.check()?;
    let html = args.html.html.as_ref().map(|_| {
        let mut html = crate::report::Report::new("campbell", "campbell");
        html.input("rotor (ROSS)", &args.model);
        html
    });
    let mut report = campbell_diagram_with(&args.model, &args.speeds, args.modes, args.operating.as_deref())?;
    crate::commands::simulate::print_notes(&report.notes);
    let plots = match &args.plot {
        Some(dir) => {
            let figure = CampbellPlot { title: report.model.clone(), campbell: &report.campbell };
            // A write failing after the diagram says what was lost; the diagram below stands.
            plot::write(&figure, dir, "campbell").unwrap_or_else(|e| {
                crate::output::report_lost("the Campbell plot", &e);
                Vec::new()
            })
        }
        None => Vec::new(),
    };
    report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
    crate::output::report(args.report.json, &report, |report| {
        println!(
            "{}: Campbell diagram, {} modes at {} speeds",
            report.model,
            args.modes,
            report.campbell.speeds_rpm.len()
        );
        print!("{:>10}", "rpm");
        (1..=args.modes).for_each(|m| print!("{:>22}", format!("f{m} [Hz] whirl")));
        println!();
        for (k, rpm) in report.campbell.speeds_rpm.iter().enumerate() {
            print!("{rpm:>10.1}");
            for (f, w) in report.campbell.frequencies_hz[k].iter().zip(&report.campbell.whirl[k]) {
                print!("{:>22}", format!("{f:.4} {}", &w.name()[..1]));
            }
            println!();
        }
        if report.campbell.critical_speeds.is_empty() {
            if report.campbell.overdamped_crossings.is_empty() {
                println!("no critical speed in range (no followed mode crosses the 1× line)");
            } else {
                println!("no critical speed in range (only modes damped beyond resonance cross the 1× line)");
            }
        }
        for k in &report.campbell.critical_speeds {
            println!(
                "critical speed {:.1} rpm ({} whirl, log dec {:.4}, damping ratio {:.3})",
                k.rpm,
                k.whirl.name(),
                k.log_dec,
                k.damping_ratio
            );
        }
        for k in &report.campbell.overdamped_crossings {
            println!(
                "not a critical speed: {:.1} rpm, where a mode with damping ratio {:.3} (|ζ| ≥ 1/√2: no resonance peak) crosses 1×",
                k.rpm, k.damping_ratio
            );
        }
        if let (Some([lo, hi]), Some(margins)) = (report.operating_range_rpm, &report.separation_margins) {
            println!("separation margins from the operating range {lo:.0}–{hi:.0} rpm (API 684 style):");
            if margins.is_empty() {
                println!("  no critical speed in the sweep");
            }
            for m in margins {
                let af = m.amplification_factor.map_or("∞".to_string(), |a| format!("{a:.2}"));
                println!(
                    "  {:.1} rpm {}: AF {af}, margin {:.1} %, required {:.1} % — {}",
                    m.rpm,
                    m.position,
                    m.margin_percent,
                    m.required_margin_percent,
                    if m.passes { "passes" } else { "FAILS" }
                );
            }
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    });
    if let (Some(path), Some(mut html)) = (&args.html.html, html) {
        crate::report::campbell::fill(&mut html, &report, args.modes);
        html.write_after(path, args.report.json);
    }
    Ok(())
}
