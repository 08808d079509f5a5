//! Mirror symmetry of a rotor: when the shaft, disks, point masses and bearings read the same
//! from either end, an effect and its mirror image give exactly the same frequencies (with the
//! bearing stiffnesses swapped), so no frequency data can tell them apart. Discovery then names
//! both (`ambiguous_with`) instead of picking one silently.

use crate::model::Rotor;
use eigenfit_core::discovery::{Alternative, NamedEffect, Place};

/// Index maps of a mirror-symmetric rotor onto itself.
pub struct Mirror {
    nodes: usize,
    elements: usize,
    /// Bearing i ↔ bearing `bearings[i]`.
    bearings: Vec<usize>,
    /// Disk i ↔ disk `disks[i]`.
    disks: Vec<usize>,
    /// x ↔ `ends` − x.
    ends: f64,
}

impl Mirror {
    /// The mirror maps of `rotor`, or `None` when it is not mirror-symmetric (to 1e-9
    /// relative). Effects already in the model (`[[effect]]`) are not mirrored: such a rotor is
    /// treated as asymmetric.
    pub fn of(rotor: &Rotor) -> Option<Self> {
        let x = rotor.nodes();
        let n = x.len();
        let ends = x[0] + x[n - 1];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-12);
        let length = x[n - 1] - x[0];
        if !rotor.spec().effects.is_empty()
            || (0..n).any(|i| (x[i] + x[n - 1 - i] - ends).abs() > 1e-9 * length)
        {
            return None;
        }
        let el = rotor.elements();
        let m = el.len();
        let same_element = |a: usize, b: usize| {
            close(el[a].outer_diameter, el[b].outer_diameter)
                && close(el[a].inner_diameter, el[b].inner_diameter)
                && el[a].material == el[b].material
        };
        if (0..m).any(|e| !same_element(e, m - 1 - e)) {
            return None;
        }
        let disks = rotor.disks();
        let disk_map: Option<Vec<usize>> = disks
            .iter()
            .map(|d| {
                disks.iter().position(|o| {
                    o.node == n - 1 - d.node
                        && close(o.mass, d.mass)
                        && close(o.diametral_inertia, d.diametral_inertia)
                })
            })
            .collect();
        let masses = rotor.point_masses();
        let masses_mirror =
            masses.iter().all(|p| masses.iter().any(|o| o.node == n - 1 - p.node && close(o.mass, p.mass)));
        let bearings = rotor.bearings();
        let bearing_map: Option<Vec<usize>> = bearings
            .iter()
            .map(|b| {
                bearings.iter().position(|o| {
                    o.node == n - 1 - b.node && close(o.rotational_stiffness, b.rotational_stiffness)
                })
            })
            .collect();
        match (disk_map, bearing_map, masses_mirror) {
            (Some(disks), Some(bearings), true) => {
                Some(Self { nodes: n, elements: m, bearings, disks, ends })
            }
            _ => None,
        }
    }

    /// The mirror image of `effect` as an alternative that fits exactly as well, or `None` for an
    /// effect without a place (or one on the symmetry plane, its own image).
    pub fn image(&self, effect: &NamedEffect) -> Option<Alternative> {
        let mut place = (effect.location, effect.position_m, effect.elements);
        match effect.kind.as_str() {
            "disk-rotary-inertia" => place.0 = effect.location.map(|d| self.disks[d]),
            "bearing-rotational-stiffness" | "support-mass" | crate::pedestal::KIND => {
                place.0 = effect.location.map(|b| self.bearings[b])
            }
            "point-mass" => {
                place.1 = effect.position_m.map(|x| self.ends - x);
                place.0 = effect.location.map(|i| self.nodes - 1 - i);
            }
            "shaft-stiffness-loss" | "section-change" => {
                let [a, b] = effect.elements.or(effect.location.map(|l| [l, l]))?;
                let (a, b) = (self.elements - 1 - b, self.elements - 1 - a);
                place.0 = Some(a);
                place.2 = effect.elements.map(|_| [a, b]);
            }
            _ => return None,
        }
        if place == (effect.location, effect.position_m, effect.elements) {
            return None;
        }
        Some(Alternative {
            place: Place::new(&effect.kind, place.0, place.1, place.2)
                .tapered_to(effect.taper_to.map(|t| self.elements - 1 - t)),
            value: effect.value,
            unit: effect.unit.clone(),
            delta_aicc: 0.0,
        })
    }
}

/// Lists the mirror image of every named effect of a mirror-symmetric `rotor` in its
/// `ambiguous_with` (once).
pub fn add_images(rotor: &Rotor, effects: &mut [NamedEffect]) {
    let Some(mirror) = Mirror::of(rotor) else { return };
    for e in effects.iter_mut() {
        if let Some(image) = mirror.image(e) {
            let listed = e.ambiguous_with.iter().any(|a| {
                a.kind == image.kind
                    && a.location == image.location
                    && a.position_m.zip(image.position_m).is_none_or(|(p, q)| (p - q).abs() < 1e-9)
                    && a.elements == image.elements
            });
            if !listed {
                e.ambiguous_with.insert(0, image);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Mirror;
    use crate::{presets, Disk, EffectSpec, Rotor};
    use eigenfit_core::discovery::{NamedEffect, Place};
    use eigenfit_core::eigen::{DenseSolver, EigenSolver};

    fn symmetric() -> Rotor {
        presets::steel_shaft_on_end_bearings(0.6, 10, 0.02, 1e5)
            .disk(Disk::new(2, 1.0))
            .disk(Disk::new(8, 1.0))
            .build()
            .unwrap()
    }

    fn effect(kind: &str, location: Option<usize>) -> NamedEffect {
        NamedEffect {
            place: Place::new(kind, location, None, None),
            value: Some(0.3),
            interval: None,
            unit: String::new(),
            delta_aicc: 10.0,
            ambiguous_with: Vec::new(),
            companions: Vec::new(),
        }
    }

    #[test]
    fn an_effect_and_its_image_give_the_same_frequencies() {
        let rotor = symmetric();
        let mirror = Mirror::of(&rotor).expect("symmetric");
        let f = |e: EffectSpec, k: [f64; 2]| {
            let r = rotor.with_effect(e).unwrap();
            DenseSolver.lowest(&r.system_at(&k).unwrap(), 6).unwrap().frequencies_hz()
        };
        for (kind, location) in
            [("support-mass", 0), ("point-mass", 3), ("shaft-stiffness-loss", 1), ("disk-rotary-inertia", 0)]
        {
            let image = mirror.image(&effect(kind, Some(location))).expect("an image");
            let value = if kind == "disk-rotary-inertia" { 1e-3 } else { 0.3 };
            // The bearings' stiffnesses swap with the image.
            let a = f(EffectSpec::new(kind, Some(location), value), [1e5, 3e5]);
            let b = f(EffectSpec::new(kind, image.location, value), [3e5, 1e5]);
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x - y).abs() <= 1e-9 * x,
                    "{kind}@{location} vs its image {}: {x} vs {y}",
                    image.label
                );
            }
        }
        // On the symmetry plane an effect is its own image.
        assert!(mirror.image(&effect("point-mass", Some(5))).is_none());
    }

    #[test]
    fn the_paper_rotor_is_not_symmetric() {
        assert!(Mirror::of(&presets::paper_rotor()).is_none());
    }
}
