//! Built-in rotors: the paper's rotor and the ROSS cross-check rotor.

use crate::{BearingSpec, Disk, Material, Rotor};

/// Names accepted by [`by_name`].
pub const NAMES: [&str; 2] = ["paper-rotor", "ross-example"];

/// A preset by name.
pub fn by_name(name: &str) -> Option<Rotor> {
    match name {
        "paper-rotor" => Some(paper_rotor()),
        "ross-example" => Some(ross_example()),
        _ => None,
    }
}

/// The ROSS cross-check rotor: 10 equal elements, Ø14 mm × 500 mm steel shaft, point disks of
/// 0.4 kg at node 2 and 1.35 kg at node 8, 1e5 N/m bearings at nodes 0 and 10.
/// ROSS gives 36.954 Hz, 81.302 Hz and 302.94 Hz.
pub fn ross_example() -> Rotor {
    Rotor::builder()
        .material(Material::steel())
        .uniform(0.5, 10)
        .diameter(0.014)
        .disk(Disk::new(2, 0.4))
        .disk(Disk::new(8, 1.35))
        .bearing(BearingSpec::new(0, 1e5))
        .bearing(BearingSpec::new(10, 1e5))
        .build()
        .expect("the ROSS example is valid") // proof: fixed data, checked by the test below
}

/// The paper's rotor (see `docs/paper-rotor.md`).
pub fn paper_rotor() -> Rotor {
    ross_example()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_preset_builds() {
        for name in super::NAMES {
            assert!(super::by_name(name).is_some(), "{name}");
        }
        assert!(super::by_name("nope").is_none());
    }
}
