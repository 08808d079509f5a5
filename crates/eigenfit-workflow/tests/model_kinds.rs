//! A model kind of a library consumer's own (issue 27 item 6): registered by name, a file with
//! `kind = "<name>"` goes through the same `simulate`, `estimate` and `discover` workflows as the
//! built-in kinds, without an enum edited.

use eigenfit_core::matrix::System;
use eigenfit_core::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use eigenfit_core::nalgebra::DMatrix;
use eigenfit_workflow::estimate::{self, EstimateOutcome, EstimateRequest};
use eigenfit_workflow::model::{register_model_kind, AnyModel, ModelKind};
use eigenfit_workflow::progress::NoProgress;
use eigenfit_workflow::simulate::{at_point, SweepCheck};
use eigenfit_workflow::test_data::TestDataOptions;
use eigenfit_workflow::ModelSource;
use std::path::Path;

/// Two storeys of `mass` kg on springs k1 (to ground) and k2 (between them).
struct TwoStorey {
    mass: f64,
    parameters: ParameterSet,
}

impl StructuralModel for TwoStorey {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }
    fn dofs(&self) -> usize {
        2
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.parameters.check(p)?;
        let k = DMatrix::from_row_slice(2, 2, &[p[0] + p[1], -p[1], -p[1], p[1]]);
        Ok(System::new(k, DMatrix::from_diagonal_element(2, 2, self.mass))?)
    }
}

/// Reads `mass = …` from a `kind = "two-storey"` file.
struct TwoStoreyKind;

impl ModelKind for TwoStoreyKind {
    fn load(&self, _: &Path, text: &str) -> Result<Box<dyn StructuralModel + Send + Sync>, String> {
        let table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
        let mass = table.get("mass").and_then(|v| v.as_float()).ok_or("`mass = …` (kg) is missing")?;
        let k = |name: &str| Parameter::new(name, "N/m", 2e4).with_bounds(1e2, 1e7).with_scale(Scale::Log);
        let parameters = ParameterSet::new(vec![k("k1"), k("k2")]).map_err(|e| e.to_string())?;
        Ok(Box::new(TwoStorey { mass, parameters }))
    }
}

#[test]
fn a_registered_model_kind_is_simulated_and_estimated_like_a_built_in_one() {
    register_model_kind("two-storey", TwoStoreyKind).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("frame.toml");
    std::fs::write(&file, "kind = \"two-storey\"\nmass = 2.0\n").unwrap();
    let source = ModelSource::file(&file);
    let (model, label) = source.load_any().unwrap();
    assert!(matches!(model, AnyModel::Registered(_)));
    // The measurement: the model's own two frequencies at the truth, with 0.1 % std.
    let truth = [3e4, 1e4];
    let solver = source.solver().unwrap();
    let f = at_point(&label, &model, solver.as_ref(), &truth, 2, SweepCheck::None).unwrap().frequencies_hz;
    // Closed form of the 2-DOF chain: ω² = (k1 + 2k2 ∓ √(k1² + 4k2²)) / 2m.
    let (k1, k2, m) = (truth[0], truth[1], 2.0);
    let root = (k1 * k1 + 4.0 * k2 * k2).sqrt();
    for (fk, sign) in f.iter().zip([-1.0, 1.0]) {
        let exact = ((k1 + 2.0 * k2 + sign * root) / (2.0 * m)).sqrt() / (2.0 * std::f64::consts::PI);
        assert!((fk / exact - 1.0).abs() < 1e-12, "{fk} against {exact}");
    }
    let csv = dir.path().join("measured.csv");
    std::fs::write(
        &csv,
        format!("mode,frequency_hz,std_hz\n1,{},{}\n2,{},{}\n", f[0], 1e-3 * f[0], f[1], 1e-3 * f[1]),
    )
    .unwrap();
    let request = EstimateRequest {
        source,
        measured: csv,
        test_data: TestDataOptions::default(),
        strategy: "damped".into(),
        samples: None,
        seed: 0,
        initial: None,
        residual: "relative".into(),
        max_iterations: 1000,
        budget: 20_000,
        write_model: false,
        alternative_starts: None,
        bearing_parameters: None,
        refit: None,
    };
    let EstimateOutcome::Done(done) = estimate::run(&request, &mut Vec::new(), &mut NoProgress).unwrap()
    else {
        panic!("an estimate")
    };
    let json = serde_json::to_value(&done.report).unwrap();
    // Two frequencies, two stiffnesses: the truth is an exact solution, and the data fit another
    // as well (the search lists it); the truth is among the two.
    let mut found = vec![done.estimate.parameters.clone()];
    for a in json["alternative_solutions"].as_array().unwrap() {
        found.push(vec![a["parameters"]["k1"].as_f64().unwrap(), a["parameters"]["k2"].as_f64().unwrap()]);
    }
    assert!(
        found.iter().any(|p| p.iter().zip(&truth).all(|(a, b)| (a / b - 1.0).abs() < 1e-8)),
        "{found:?}: {json}"
    );
    // A misspelt kind names the registered ones.
    std::fs::write(&file, "kind = \"two-story\"\nmass = 2.0\n").unwrap();
    let err = ModelSource::file(&file).load_any().err().expect("refused").to_string();
    assert!(err.contains("two-storey"), "{err}");
}
