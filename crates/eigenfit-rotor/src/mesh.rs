//! Mesh refinement: the same rotor with every shaft element split into equal parts, to tell a
//! discretisation error from missing physics.

use crate::error::RotorError;
use crate::model::Rotor;
use crate::spec::Section;
use crate::RotorBuilder;

/// `rotor` with every shaft element split into `factor` equal elements. Disks, bearings and
/// point masses stay on the same physical nodes (node i becomes node `factor`·i); effects keep
/// their meaning (a section change covers the split elements of its run). A
/// `shaft-stiffness-loss` cannot be split faithfully (it is a loss in one element): refusing is
/// better than a silently different model.
pub fn refined(rotor: &Rotor, factor: usize) -> Result<Rotor, RotorError> {
    if factor == 0 {
        return Err(RotorError::ShaftLayout("mesh refinement needs a factor of at least 1"));
    }
    let mut spec = rotor.spec().clone();
    let nodes = rotor.nodes();
    let mut fine = Vec::with_capacity((nodes.len() - 1) * factor + 1);
    for w in nodes.windows(2) {
        fine.extend((0..factor).map(|i| w[0] + (w[1] - w[0]) * i as f64 / factor as f64));
    }
    fine.push(nodes[nodes.len() - 1]);
    spec.shaft.nodes = Some(fine);
    spec.shaft.length = None;
    spec.shaft.elements = None;
    // One section per original element, carrying its resolved diameter and material.
    spec.shaft.sections = rotor
        .elements()
        .iter()
        .enumerate()
        .map(|(e, el)| {
            Section::new(e * factor, e * factor + factor - 1)
                .diameter(el.outer_diameter)
                .inner_diameter(el.inner_diameter)
                .material(rotor.materials()[el.material].name.clone())
        })
        .collect();
    for d in &mut spec.disks {
        d.node *= factor;
    }
    for b in &mut spec.bearings {
        b.node *= factor;
    }
    for p in &mut spec.point_masses {
        p.node *= factor;
    }
    for (i, e) in spec.effects.iter_mut().enumerate() {
        match e.kind.as_str() {
            "point-mass" if e.position_m.is_none() => e.location = e.location.map(|n| n * factor),
            "section-change" => {
                let [a, b] = e.elements.or(e.location.map(|l| [l, l])).unwrap_or([0, 0]);
                e.location = Some(a * factor);
                e.elements = Some([a * factor, b * factor + factor - 1]);
            }
            "shaft-stiffness-loss" => {
                return Err(RotorError::Effect {
                    entry: i,
                    kind: e.kind.clone(),
                    why: "a loss in one element cannot be carried to a refined mesh".into(),
                })
            }
            _ => {}
        }
    }
    RotorBuilder::from_spec(spec).build()
}

#[cfg(test)]
mod tests {
    use crate::presets;
    use eigenfit_core::eigen::{DenseSolver, EigenSolver};

    #[test]
    fn refining_converges_from_above_and_keeps_the_parts() {
        let coarse = presets::paper_rotor();
        let k = [2e5, 5e4];
        let f = |r: &crate::Rotor| DenseSolver.lowest(&r.system_at(&k).unwrap(), 8).unwrap().frequencies_hz();
        let (f1, f2, f4) =
            (f(&coarse), f(&super::refined(&coarse, 2).unwrap()), f(&super::refined(&coarse, 4).unwrap()));
        assert_eq!(super::refined(&coarse, 1).unwrap().nodes(), coarse.nodes());
        for m in 0..8 {
            // Consistent-mass Hermite elements bound the frequencies from above.
            assert!(f1[m] >= f2[m] * (1.0 - 1e-12) && f2[m] >= f4[m] * (1.0 - 1e-12), "mode {m}");
        }
        let r = super::refined(&coarse, 3).unwrap();
        assert_eq!(r.nodes().len(), 31);
        assert!((r.total_mass() - coarse.total_mass()).abs() < 1e-12 * coarse.total_mass());
        assert_eq!(r.bearings()[0].node, 30);
    }
}
