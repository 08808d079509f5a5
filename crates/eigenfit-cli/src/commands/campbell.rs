//! `eigenfit campbell`: damped frequencies of a two-plane (ROSS) rotor against speed in rpm,
//! with whirl, log decrement and the critical speeds where followed modes cross the 1× line.

use crate::error::{input, CliError};
use crate::plot;
use crate::plot::campbell::CampbellPlot;
use crate::rotordynamics::load;
use clap::Args;
use eigenfit_rotordynamics::campbell;
use serde_json::json;
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
    /// Write the diagram (campbell.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Accepted like every other command's `--quiet` (campbell shows no progress indicator).
    #[arg(long)]
    pub quiet: bool,
}

/// Parses `FROM:TO:COUNT` (rpm, linear).
pub fn parse_speeds(text: &str) -> Result<Vec<f64>, CliError> {
    let bad = |why: &str| {
        input(format!("--speeds `{text}`: {why} (expected FROM:TO:COUNT in rpm, e.g. 0:12000:50)"))
    };
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let [from, to, count] = parts[..] else { return Err(bad("three fields needed")) };
    let from: f64 = from.parse().map_err(|_| bad("FROM is not a number"))?;
    let to: f64 = to.parse().map_err(|_| bad("TO is not a number"))?;
    let count: usize = count.parse().map_err(|_| bad("COUNT is not a whole number"))?;
    if !from.is_finite() || !to.is_finite() || from < 0.0 || to < from {
        return Err(bad("speeds must be finite with 0 ≤ FROM ≤ TO"));
    }
    if count == 0 || count > 100_000 || (count == 1 && to != from) {
        return Err(bad("COUNT must be 1 … 100000 (1 only when FROM = TO)"));
    }
    Ok((0..count)
        .map(|i| if count == 1 { from } else { from + (to - from) * i as f64 / (count - 1) as f64 })
        .collect())
}

/// Runs `campbell`.
pub fn run(args: &CampbellArgs) -> Result<(), CliError> {
    let speeds = parse_speeds(&args.speeds)?;
    let rotor = load(&args.model)?;
    if args.modes == 0 {
        return Err(input("--modes 0: at least one mode"));
    }
    let c =
        campbell(&rotor, &speeds, args.modes).map_err(|e| input(format!("{}: {e}", args.model.display())))?;
    let plots = match &args.plot {
        Some(dir) => {
            let figure = CampbellPlot { title: args.model.display().to_string(), campbell: &c };
            plot::write(&figure, dir, "campbell")?
        }
        None => Vec::new(),
    };
    if args.json {
        let names = |v: &Vec<eigenfit_rotordynamics::Whirl>| v.iter().map(|w| w.name()).collect::<Vec<_>>();
        let mut out = json!({
            "model": args.model.display().to_string(),
            "speeds_rpm": c.speeds_rpm,
            "frequencies_hz": c.frequencies_hz,
            "whirl": c.whirl.iter().map(names).collect::<Vec<_>>(),
            "log_dec": c.log_dec,
            "critical_speeds_rpm": c.critical_speeds.iter().map(|k| k.rpm).collect::<Vec<_>>(),
            "critical_speeds": c.critical_speeds.iter().map(|k| json!({
                "rpm": k.rpm, "curve": k.curve, "whirl": k.whirl.name(), "log_dec": k.log_dec,
            })).collect::<Vec<_>>(),
            "curves": c.curves,
        });
        if args.plot.is_some() {
            out["plots"] = json!(plot::names(&plots));
        }
        crate::output::emit_json(out);
    } else {
        println!(
            "{}: Campbell diagram, {} modes at {} speeds",
            args.model.display(),
            args.modes,
            speeds.len()
        );
        print!("{:>10}", "rpm");
        (1..=args.modes).for_each(|m| print!("{:>22}", format!("f{m} [Hz] whirl")));
        println!();
        for (k, rpm) in c.speeds_rpm.iter().enumerate() {
            print!("{rpm:>10.1}");
            for (f, w) in c.frequencies_hz[k].iter().zip(&c.whirl[k]) {
                print!("{:>22}", format!("{f:.4} {}", &w.name()[..1]));
            }
            println!();
        }
        if c.critical_speeds.is_empty() {
            println!("no critical speed in range (no followed mode crosses the 1× line)");
        }
        for k in &c.critical_speeds {
            println!("critical speed {:.1} rpm ({} whirl, log dec {:.4})", k.rpm, k.whirl.name(), k.log_dec);
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::parse_speeds;

    #[test]
    fn speeds_are_linear_and_inclusive() {
        assert_eq!(parse_speeds("0:1000:5").unwrap(), vec![0.0, 250.0, 500.0, 750.0, 1000.0]);
        assert_eq!(parse_speeds("300:300:1").unwrap(), vec![300.0]);
        for bad in ["0:10", "a:1:2", "10:0:3", "0:10:0", "-5:10:3", "0:10:1"] {
            assert!(parse_speeds(bad).is_err(), "{bad}");
        }
    }
}
