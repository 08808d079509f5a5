//! Fuzz target `model_to_modes`: a rotor description → TOML → parse → build → assemble at the
//! nominal stiffnesses → `DenseSolver` and `BandedSolver` lowest modes.
//!
//! The input is structured (a random rotor whose numbers are mostly physically plausible and
//! sometimes raw bit patterns), so that most cases get past validation and exercise the
//! assembly and the eigen-solver. Properties: every stage returns `Ok` or a typed error, never
//! panics and never hangs (run with `-timeout=`); modes that come back are as many as asked for,
//! finite, and ascending.
//!
//! Models above `MAX_DOFS` degrees of freedom are skipped: they are valid but a dense O(n³)
//! solve of a few thousand DOFs takes seconds, which would swamp the fuzzer.

#![no_main]

use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{BearingSpec, Disk, Material, PointMass, Rotor, RotorSpec, Section, ShaftSpec};
use libfuzzer_sys::arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;

const MAX_DOFS: usize = 120;

/// A number: usually `m · 10^e` with e in a range around `centre`, sometimes raw bits.
fn num(u: &mut Unstructured, centre: i32) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=15)? {
        0 => f64::from_bits(u.arbitrary()?),
        1 => *u.choose(&[0.0, -0.0, -1.0, f64::NAN, f64::INFINITY, f64::MIN_POSITIVE, f64::MAX, 1e-300])?,
        _ => {
            let m = f64::from(u.int_in_range(1u16..=9999)?) / 1000.0;
            let e = centre + i32::from(u.int_in_range(-8i8..=8)?);
            m * 10f64.powi(e)
        }
    })
}

fn small(u: &mut Unstructured, max: usize) -> Result<usize> {
    u.int_in_range(0..=max)
}

fn rotor_spec(u: &mut Unstructured) -> Result<RotorSpec> {
    let materials = (0..small(u, 3)?)
        .map(|i| Ok(Material::new(format!("m{i}"), num(u, 11)?, num(u, 3)?)))
        .collect::<Result<Vec<_>>>()?;
    let elements = small(u, 30)?;
    let mut shaft = ShaftSpec::default();
    if u.arbitrary()? {
        let mut x = 0.0;
        let mut nodes = Vec::new();
        for _ in 0..=elements {
            nodes.push(x);
            x += if u.int_in_range(0u8..=20)? == 0 { num(u, -1)? - 0.5 } else { num(u, -2)? };
        }
        shaft.nodes = Some(nodes);
    } else {
        shaft.length = Some(num(u, 0)?);
        shaft.elements = Some(elements);
    }
    if u.int_in_range(0u8..=10)? > 0 {
        shaft.diameter = Some(num(u, -2)?);
    }
    if u.int_in_range(0u8..=5)? == 0 {
        shaft.inner_diameter = Some(num(u, -3)?);
    }
    if u.int_in_range(0u8..=3)? == 0 {
        shaft.material = Some(format!("m{}", small(u, 3)?));
    }
    for _ in 0..small(u, 3)? {
        let first = small(u, elements + 1)?;
        let mut s = Section::new(first, first + small(u, 5)?);
        if u.arbitrary()? {
            s = s.diameter(num(u, -2)?);
        }
        if u.int_in_range(0u8..=3)? == 0 {
            s = s.inner_diameter(num(u, -3)?);
        }
        if u.int_in_range(0u8..=3)? == 0 {
            s = s.material(format!("m{}", small(u, 3)?));
        }
        shaft.sections.push(s);
    }
    let disks = (0..small(u, 4)?)
        .map(|_| {
            let d = Disk::new(small(u, elements + 1)?, num(u, 0)?);
            Ok(if u.arbitrary()? { d.with_diametral_inertia(num(u, -3)?) } else { d })
        })
        .collect::<Result<Vec<_>>>()?;
    let bearings = (0..small(u, 4)?)
        .map(|_| {
            let b = BearingSpec::new(small(u, elements + 1)?, num(u, 6)?);
            Ok(if u.int_in_range(0u8..=3)? == 0 { b.with_rotational_stiffness(num(u, 3)?) } else { b })
        })
        .collect::<Result<Vec<_>>>()?;
    let point_masses = (0..small(u, 2)?)
        .map(|_| Ok(PointMass::new(small(u, elements + 1)?, num(u, -1)?)))
        .collect::<Result<Vec<_>>>()?;
    Ok(RotorSpec { materials, shaft, disks, bearings, point_masses, ..RotorSpec::default() })
}

fn run(u: &mut Unstructured) -> Result<()> {
    let spec = rotor_spec(u)?;
    let count_seed = small(u, 255)?;
    // Through the text format, as a user's file would come (NaN and inf become `nan`, `inf`).
    let Ok(text) = toml::to_string(&spec) else { return Ok(()) };
    let rotor = match Rotor::from_toml_str(&text) {
        Ok(r) => r,
        Err(e) => {
            let _ = e.to_string();
            return Ok(());
        }
    };
    let n = rotor.dofs();
    if n > MAX_DOFS {
        return Ok(());
    }
    let system = match rotor.nominal_system() {
        Ok(s) => s,
        Err(e) => {
            let _ = e.to_string();
            return Ok(());
        }
    };
    let count = 1 + count_seed % n;
    // The reference solver and the CLI's default.
    let solvers: [&dyn EigenSolver; 2] = [&DenseSolver, &BandedSolver::default()];
    for solver in solvers {
        match solver.lowest(&system, count) {
            Err(e) => {
                let _ = e.to_string();
            }
            Ok(modes) => {
                let l = &modes.eigenvalues;
                assert_eq!(l.len(), count);
                assert!(l.iter().all(|v| v.is_finite()), "non-finite eigenvalue {l:?}\n{text}");
                assert!(
                    l.as_slice().windows(2).all(|w| w[0] <= w[1]),
                    "{}: eigenvalues not ascending {l:?}\n{text}",
                    solver.name()
                );
                assert!(modes.frequencies_hz().iter().all(|f| f.is_finite()));
            }
        }
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
