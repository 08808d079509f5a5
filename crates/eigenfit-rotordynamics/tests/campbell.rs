//! Campbell diagrams: the shift-invert solver used for large rotors against the dense one,
//! modes followed through speed, and critical speeds on the 1× line.

use eigenfit_rotordynamics::{campbell, ross_file, rpm_to_rad};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

#[test]
fn shift_invert_finds_the_same_lowest_modes_as_the_dense_solver() {
    // 183 shaft nodes, 732 DOF: above the dense limit, so `lowest_modes` runs Arnoldi.
    let rotor = ross_file::read(&data("compressor.toml")).unwrap();
    assert!(rotor.dofs() > eigenfit_rotordynamics::modal::DENSE_DOFS);
    for rpm in [0.0, 5000.0, 11000.0] {
        let w = rpm_to_rad(rpm);
        let fast = rotor.lowest_modes(w, 8).unwrap();
        let dense = rotor.modes(w, false).unwrap();
        for (a, b) in fast.iter().zip(&dense) {
            let rel = (a.eigenvalue - b.eigenvalue).norm() / b.eigenvalue.norm();
            assert!(rel < 1e-9, "{rpm} rpm: {} vs {} ({rel:.2e})", a.eigenvalue, b.eigenvalue);
            assert_eq!(a.whirl, b.whirl, "{rpm} rpm, {} Hz", b.frequency_hz());
        }
    }
}

#[test]
fn critical_speeds_lie_on_the_synchronous_line() {
    let rotor = ross_file::read(&data("rotor_example.toml")).unwrap();
    let speeds: Vec<f64> = (0..=60).map(|i| 200.0 * i as f64).collect();
    let c = campbell(&rotor, &speeds, 4).unwrap();
    assert_eq!(c.frequencies_hz.len(), speeds.len());
    for row in &c.frequencies_hz {
        assert!(row.windows(2).all(|w| w[0] <= w[1]), "not ascending: {row:?}");
    }
    assert!(!c.critical_speeds.is_empty(), "rotor_example's first modes (~15 Hz) cross 1× below 12000 rpm");
    for k in &c.critical_speeds {
        // At the interpolated crossing the rotor has a mode at (nearly) the running frequency.
        let modes = rotor.modes(rpm_to_rad(k.rpm), false).unwrap();
        let sync = k.rpm / 60.0;
        let nearest =
            modes.iter().map(|m| (m.frequency_hz() - sync).abs() / sync).fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-2, "critical speed {} rpm: nearest mode {:.2e} off", k.rpm, nearest);
    }
}

/// ROSS's rotor_example with a heavily damped absorber at node 3 (1 kg on 1 kN/m and
/// 60 N·s/m: ζ = 60/(2·√1000) = 0.95). Its mode (1.59 Hz) crosses 1× near 95 rpm, where nothing
/// resonates: listed as an overdamped crossing, not as a critical speed; the shaft's own
/// crossings (ζ 0.004) stay critical speeds.
#[test]
fn a_mode_damped_beyond_resonance_is_not_a_critical_speed() {
    use eigenfit_rotordynamics::campbell::NO_PEAK_DAMPING_RATIO;
    let mut text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    text.push_str(
        r#"
["BearingElement_Damper"]
cxx = [ 60.0,]
cxy = [ 0,]
cyx = [ 0,]
cyy = [ 60.0,]
kxx = [ 1000.0,]
kxy = [ 0,]
kyx = [ 0,]
kyy = [ 1000.0,]
n = 3
n_link = 7
tag = "Damper"

["PointMass_Absorber"]
n = 7
mx = 1.0
my = 1.0
tag = "Absorber"
"#,
    );
    let rotor = ross_file::parse(&text).unwrap();
    let speeds: Vec<f64> = (0..=30).map(|i| 100.0 * i as f64).collect();
    let c = campbell(&rotor, &speeds, 4).unwrap();
    assert_eq!(c.overdamped_crossings.len(), 2, "{:?}", c.overdamped_crossings);
    for k in &c.overdamped_crossings {
        assert!((k.damping_ratio - 0.949).abs() < 5e-3 && (k.rpm - 95.0).abs() < 2.0, "{k:?}");
    }
    assert_eq!(c.critical_speeds.len(), 2, "{:?}", c.critical_speeds);
    for k in &c.critical_speeds {
        assert!(k.damping_ratio < NO_PEAK_DAMPING_RATIO && (850.0..950.0).contains(&k.rpm), "{k:?}");
    }
}

/// `text` without its bearing tables: a free–free rotor.
fn without_bearings(text: &str) -> String {
    let mut out = String::new();
    let mut keep = true;
    for line in text.lines() {
        if line.starts_with('[') {
            keep = !line.contains("BearingElement");
        }
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

#[test]
fn a_rotor_without_bearings_lists_no_rigid_body_mode_and_no_critical_speed_at_zero() {
    let text = without_bearings(&std::fs::read_to_string(data("rotor_example.toml")).unwrap());
    let free = ross_file::parse(&text).unwrap();
    let held = ross_file::read(&data("rotor_example.toml")).unwrap();
    // Two planes, two rigid motions each (translation, tilt): four, and none with bearings.
    assert_eq!(free.rigid_body_modes(0.0).unwrap(), 4);
    assert_eq!(held.rigid_body_modes(0.0).unwrap(), 0);
    // The modes listed are the free rotor's elastic ones: every one resolved from zero, within a
    // few decades of each other (no round-off value among them), the same as the full solve's
    // modes above its near-zero ones.
    let listed = free.lowest_modes(0.0, 4).unwrap();
    let all = free.modes(0.0, false).unwrap();
    let top = listed.last().unwrap().eigenvalue.norm();
    for mode in &listed {
        assert!(mode.eigenvalue.norm() > 1e-3 * top, "a round-off mode listed: {}", mode.eigenvalue);
    }
    let elastic_full: Vec<_> = all.iter().filter(|m| m.eigenvalue.norm() > 1e-3 * top).take(4).collect();
    for (a, b) in listed.iter().zip(&elastic_full) {
        assert!((a.eigenvalue - b.eigenvalue).norm() <= 1e-9 * b.eigenvalue.norm());
    }
    // No critical speed below a tenth of the first elastic mode's (a rigid-body mode's curve
    // would cross the 1× line at a few thousandths of an rpm).
    let first_rpm = 60.0 * listed[0].frequency_hz();
    let speeds: Vec<f64> = (0..=20).map(|i| 300.0 * i as f64).collect();
    let c = campbell(&free, &speeds, 4).unwrap();
    for k in c.critical_speeds.iter().chain(&c.overdamped_crossings) {
        assert!(k.rpm > 0.1 * first_rpm, "a crossing at {} rpm", k.rpm);
    }
}

#[test]
fn nan_and_inf_in_bearing_tables_are_named_where_they_are() {
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    let cases = [
        ("kxx = [ 1000000.0,]", "kxx = [ 1000000.0, nan,]\nfrequency = [0.0, 10.0]", "`kxx`[1] = nan"),
        ("kyy = [ 800000.0,]", "kyy = -inf", "`kyy` = -inf"),
        ("cxx = [ 0,]", "cxx = [ inf,]", "`cxx`[0] = inf"),
    ];
    for (from, to, said) in cases {
        let e = ross_file::parse(&text.replacen(from, to, 1)).unwrap_err().to_string();
        assert!(e.contains(&format!("`BearingElement_Bearing 0`: {said} is not a finite number")), "{e}");
        assert!(!e.contains("null") && !e.contains("missing"), "{e}");
    }
    // A shaft's value too, and a JSON file with Python's bare NaN / Infinity.
    let e = ross_file::parse(&text.replacen("L = 0.25", "L = nan", 1)).unwrap_err().to_string();
    assert!(e.contains("`L` = nan is not a finite number"), "{e}");
    let json = std::fs::read_to_string(data("rotor_example.json")).unwrap();
    let at = json.find("\"kxx\"").expect("a kxx in the JSON file");
    let open = at + json[at..].find('[').unwrap();
    let bad = format!("{}[Infinity, NaN, {}", &json[..open], &json[open + 1..]);
    let e = ross_file::parse(&bad).unwrap_err().to_string();
    assert!(e.contains("`kxx`[0] = Infinity is not a finite number"), "{e}");
    // The words inside a string are no number: a tag "NaN" reads.
    let tagged = json.replacen("\"tag\": \"", "\"tag\": \"NaN ", 1);
    assert!(ross_file::parse(&tagged).is_ok());
}

/// The work of a Campbell sweep is bounded: on ROSS 3's compressor (732 DOF, 10 modes solved per
/// speed: 36 eigenvalues wanted) each speed takes at most 53 Krylov steps and 1.9 convergence
/// checks on average (measured: 52.1 steps, 1.85 checks). Before the spares were ranked by
/// their margin above the modes returned it took 70.2 steps (bound 80) and 1.20 checks (bound
/// 1.5): the spares at the far end of the wanted set needed 1.9 steps per wanted eigenvalue to
/// reach 1e-8, the modes returned 1.3. A check now costs an eigenvalues-only Hessenberg QR and
/// one inverse iteration per wanted pair, not every Schur vector, so it checks from 47 steps on.
#[test]
fn a_campbell_sweep_of_the_compressor_takes_bounded_krylov_work() {
    use eigenfit_rotordynamics::shift_invert::work;
    let rotor = ross_file::read(&data("ross3/compressor.toml")).unwrap();
    let speeds: Vec<f64> = (0..20).map(|i| 600.0 * i as f64).collect();
    // One rayon thread, this closure on it: the per-thread counter sees every solve.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let (diagram, done) = pool.install(|| {
        let before = work();
        let c = campbell(&rotor, &speeds, 6).unwrap();
        let after = work();
        (c, (after.applications - before.applications, after.checks - before.checks))
    });
    assert_eq!(diagram.frequencies_hz.len(), speeds.len());
    let (steps, checks) = (done.0 as f64 / speeds.len() as f64, done.1 as f64 / speeds.len() as f64);
    eprintln!("per speed: {steps:.1} Krylov steps, {checks:.2} checks");
    assert!(steps > 0.0 && steps <= 53.0, "{steps} Krylov steps per speed");
    assert!(checks <= 1.9, "{checks} convergence checks per speed");
}

/// The divergence check by Sturm counts on band matrices agrees with the dense symmetric
/// eigen-solve of M⁻¹ᐟ²K_sM⁻ᵀᐟ² it replaced: rotor_example with one bearing at −8e8 N/m in x is
/// statically unstable, with the same lowest eigenvalue; the file as saved is not.
#[test]
fn divergence_by_sturm_counts_matches_the_dense_eigenvalue() {
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    let held = ross_file::parse(&text).unwrap();
    assert_eq!(held.divergent(0.0), None);
    let negative = ross_file::parse(&text.replacen("kxx = [ 1000000.0,]", "kxx = [ -8e8,]", 1)).unwrap();
    let lowest = negative.divergent(0.0).expect("a −8e8 N/m bearing outweighs the shaft");
    let mats = negative.matrices(0.0);
    let n = negative.dofs();
    let sym = |a: &faer::Mat<f64>| nalgebra::DMatrix::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let l = nalgebra::Cholesky::new(sym(&mats.m)).unwrap().l();
    let x = l.solve_lower_triangular(&sym(&mats.k)).unwrap();
    let a = l.solve_lower_triangular(&x.transpose()).unwrap();
    let a = (&a + a.transpose()) * 0.5;
    let dense = a.symmetric_eigenvalues().iter().copied().fold(f64::INFINITY, f64::min);
    assert!(dense < 0.0);
    assert!((lowest - dense).abs() <= 1e-9 * dense.abs(), "Sturm {lowest:e}, dense {dense:e}");
}

/// Refined on the rotor, a critical speed and its damping ratio (the amplification factor's ζ)
/// do not depend on the sweep that found it: 3 speeds over 0–12000 rpm and 241 speeds give the
/// same crossing, to the refinement's 1e-10, where the interpolated values differ.
#[test]
fn refined_critical_speeds_do_not_depend_on_the_sweep() {
    use eigenfit_rotordynamics::campbell::refine_critical_speed;
    let rotor = ross_file::read(&data("ross3/pchip_speed.toml")).unwrap();
    let sweep =
        |count: usize| -> Vec<f64> { (0..count).map(|i| 12000.0 * i as f64 / (count - 1) as f64).collect() };
    let (coarse, fine) = (campbell(&rotor, &sweep(3), 4).unwrap(), campbell(&rotor, &sweep(241), 4).unwrap());
    let refined = |c: &eigenfit_rotordynamics::Campbell| -> Vec<_> {
        c.critical_speeds.iter().map(|k| refine_critical_speed(&rotor, c, k, 4).unwrap()).collect()
    };
    let (rc, rf) = (refined(&coarse), refined(&fine));
    assert!(!rc.is_empty(), "the coarse sweep finds a crossing");
    let mut moved = 0.0_f64;
    for (k, r) in coarse.critical_speeds.iter().zip(&rc) {
        // On the 1× line: the refined mode's frequency is the running frequency.
        let twin = rf
            .iter()
            .min_by(|a, b| (a.rpm - r.rpm).abs().total_cmp(&(b.rpm - r.rpm).abs()))
            .expect("the fine sweep finds it too");
        assert!((twin.rpm - r.rpm).abs() <= 1e-8 * r.rpm, "{} vs {} rpm", r.rpm, twin.rpm);
        let dz = (twin.damping_ratio - r.damping_ratio).abs();
        assert!(dz <= 1e-6 * r.damping_ratio.abs(), "ζ {} vs {}", r.damping_ratio, twin.damping_ratio);
        moved = moved.max((k.damping_ratio - r.damping_ratio).abs() / r.damping_ratio.abs());
    }
    eprintln!("largest change of ζ by the refinement on the 3-speed sweep: {moved:.3}");
}
