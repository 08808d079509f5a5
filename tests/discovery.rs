//! Missing-effect discovery on data in which an effect is hidden (issue: discovery).

use eigenfit::core::discovery::{discover, DiscoveryOptions, DiscoveryReport};

use eigenfit::core::eigen::DenseSolver;
use eigenfit::core::measurement::{synthetic::synthesise, synthetic::NoiseRng, Measurement};
use eigenfit::core::model::{Augmented, StructuralModel};
use eigenfit::rotor::{presets, EffectSpec, Rotor};

/// `modes` measured frequencies of `truth` at `stiffness`, with relative noise `rel`.
fn measure(truth: &Rotor, stiffness: &[f64], modes: usize, rel: f64, seed: u64) -> Measurement {
    synthesise(truth, &DenseSolver, stiffness, modes, rel, Some(&mut NoiseRng(seed))).unwrap()
}

fn run(hidden: Option<EffectSpec>, seed: u64) -> DiscoveryReport {
    let base = presets::paper_rotor();
    let truth = match hidden {
        Some(e) => base.with_effect(e).unwrap(),
        None => base.clone(),
    };
    let k = [2e5, 5e4];
    let measured = measure(&truth, &k, 8, 5e-4, seed);
    discover(&base, &DenseSolver, &measured, &base.candidates(), &[1e5, 1e5], &DiscoveryOptions::default())
        .unwrap()
}

fn assert_names(report: &DiscoveryReport, kind: &str, location: Option<usize>, value: f64) {
    let sel = report.selected.as_ref().unwrap_or_else(|| panic!("nothing named; fits: {:#?}", report.fits));
    assert!(report.before.significant);
    assert_eq!((sel.kind.as_str(), sel.location), (kind, location), "fits: {:#?}", report.fits);
    let iv = sel.interval.unwrap();
    assert!(iv[0] <= value && value <= iv[1], "true value {value} outside the interval {iv:?}");
    assert!(
        report.rms_after_hz < 0.5 * report.rms_before_hz,
        "{} → {}",
        report.rms_before_hz,
        report.rms_after_hz
    );
}

#[test]
fn names_a_hidden_disk_inertia() {
    let r = run(Some(EffectSpec::new("disk-rotary-inertia", Some(0), 4e-3)), 1);
    assert_names(&r, "disk-rotary-inertia", Some(0), 4e-3);
}

#[test]
fn names_a_hidden_point_mass() {
    let r = run(Some(EffectSpec::new("point-mass", Some(5), 0.3)), 2);
    assert_names(&r, "point-mass", Some(5), 0.3);
}

#[test]
fn names_a_cracked_element() {
    let r = run(Some(EffectSpec::new("shaft-stiffness-loss", Some(4), 0.3)), 3);
    assert_names(&r, "shaft-stiffness-loss", Some(4), 0.3);
}

#[test]
fn adds_nothing_when_the_model_already_fits() {
    let r = run(None, 4);
    assert!(!r.before.significant, "p = {}", r.before.p_value);
    assert!(r.selected.is_none());
    assert_eq!(r.rms_after_hz, r.rms_before_hz);
}

#[test]
fn a_candidate_at_a_value_is_the_same_model_as_the_effect_in_a_file() {
    let base = presets::paper_rotor();
    // A candidate that adds degrees of freedom (a pedestal) has no `[[effect]]` form; it is held
    // to the independent generator instead (tests/independent_discovery.rs in the rotor crate).
    // So is a taper (graded parts): its file form is a step per element, an approximation by
    // design, not the same model.
    for c in base.candidates().into_iter().filter(|c| c.extra_dofs == 0 && c.graded.is_empty()) {
        let value = c.parameter.as_ref().map_or(1.0, |p| 0.5 * c.plausible.1.min(p.upper));
        let aug = Augmented::new(&base, &c).unwrap();
        let mut p = base.nominal_stiffnesses();
        if c.parameter.is_some() {
            p.push(value);
        }
        let a = aug.assemble(&p).unwrap();
        let mut spec = EffectSpec::new(c.kind.clone(), c.location, value);
        // Placed by coordinate or over a run of elements: the file says so the same way.
        spec.position_m = c.position_m;
        spec.elements = c.elements;
        let b = base.with_effect(spec).unwrap().nominal_system().unwrap();
        let scale = b.stiffness().amax();
        assert!((a.stiffness() - b.stiffness()).amax() <= 1e-12 * scale, "{}", c.label());
        assert!((a.mass() - b.mass()).amax() <= 1e-12, "{}", c.label());
    }
}

/// A mirror-symmetric rotor (uniform shaft, centred disk, equal bearings at both ends) with a
/// bearing mass hidden at one bearing: frequencies cannot tell which end, so discovery must name
/// one and list the mirror bearing as equally good — never pick one silently.
#[test]
fn names_both_mirror_bearings_of_a_symmetric_rotor() {
    use eigenfit::rotor::discovery::discover_rotor;
    use eigenfit::rotor::Disk;
    let rotor =
        presets::steel_shaft_on_end_bearings(0.6, 10, 0.02, 1e5).disk(Disk::new(5, 2.0)).build().unwrap();
    let truth = rotor.with_effect(EffectSpec::new("support-mass", Some(0), 0.4)).unwrap();
    let measured = measure(&truth, &[1e5, 1e5], 8, 5e-4, 11);
    let found = discover_rotor(
        &rotor,
        &eigenfit::core::eigen::BandedSolver::default(),
        &measured,
        &[1e5, 1e5],
        &DiscoveryOptions::default(),
    )
    .unwrap();
    let first = found.effects.first().unwrap_or_else(|| panic!("nothing named: {:#?}", found.report.fits));
    assert_eq!(first.kind, "support-mass", "{first:#?}");
    let named = first.location.unwrap();
    let mirror = 1 - named;
    assert!(
        first.ambiguous_with.iter().any(|a| a.kind == "support-mass" && a.location == Some(mirror)),
        "support-mass@{named} named without its mirror bearing {mirror}: {first:#?}"
    );
    let iv = first.interval.unwrap();
    assert!(iv[0] <= 0.4 && 0.4 <= iv[1], "true 0.4 kg outside {iv:?}");
}
