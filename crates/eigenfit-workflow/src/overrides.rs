//! Parameter values given as text: lists `K1,K2,…`, overrides `NAME=VALUE` (`--set`) and held
//! parameters (`--fix`). Every error names the option and the item.

use crate::error::{input, WorkflowError};
use eigenfit_core::model::{Fixed, StructuralModel};

/// Parses `K1,K2,…` into finite numbers, naming the bad item (errors start with `flag`).
pub fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>, WorkflowError> {
    text.split(',')
        .enumerate()
        .map(|(i, item)| {
            let v: f64 = item
                .trim()
                .parse()
                .map_err(|_| input(format!("{flag}: item {} `{}` is not a number", i + 1, item.trim())))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(input(format!("{flag}: item {} `{}` is not finite", i + 1, item.trim())))
            }
        })
        .collect()
}

/// Parameter vector from the nominal values, a full list (`stiffness`: `K1,K2,…`, errors named
/// `flag`) and overrides `NAME=VALUE` (`--set`); checked against the parameters' limits.
pub fn parameter_vector(
    model: &dyn StructuralModel,
    flag: &str,
    stiffness: Option<&str>,
    sets: &[String],
) -> Result<Vec<f64>, WorkflowError> {
    let params = model.parameters();
    let mut p = params.nominal_values();
    if let Some(text) = stiffness {
        let values = parse_list(flag, text)?;
        if values.len() != p.len() {
            return Err(input(format!(
                "{flag}: {} values given but the model has {} parameters ({})",
                values.len(),
                p.len(),
                eigenfit_core::names::listed(&params.iter().map(|q| q.name.as_str()).collect::<Vec<_>>())
            )));
        }
        p = values;
    }
    refuse_repeated("--set", sets)?;
    for s in sets {
        let (name, value) =
            s.split_once('=').ok_or_else(|| input(format!("--set `{s}`: expected NAME=VALUE")))?;
        let i = params.index_of(name.trim()).map_err(|e| input(format!("--set: {e}")))?;
        p[i] = parse_list("--set", value)?[0];
    }
    params.check(&p).map_err(|e| input(format!("{flag}: {e}")))?;
    Ok(p)
}

/// Refuses `NAME=VALUE` items (`flag`'s) that name one parameter twice: which value was meant
/// cannot be known, and the last one silently winning is a slip hidden.
pub fn refuse_repeated<S: AsRef<str>>(flag: &str, items: &[S]) -> Result<(), WorkflowError> {
    let names: Vec<&str> =
        items.iter().map(|s| s.as_ref().split_once('=').map_or(s.as_ref(), |(n, _)| n).trim()).collect();
    match (1..names.len()).find(|&j| names[..j].contains(&names[j])) {
        Some(j) => Err(input(format!("{flag}: `{}` is given twice; give each name once", names[j]))),
        None => Ok(()),
    }
}

/// `model` with the `--fix NAME=VALUE` parameters held.
pub fn fixed<M: StructuralModel>(model: M, fixes: &[String]) -> Result<Fixed<M>, WorkflowError> {
    let mut pairs = Vec::new();
    for f in fixes {
        let (name, value) =
            f.split_once('=').ok_or_else(|| input(format!("--fix `{f}`: expected NAME=VALUE")))?;
        let v: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| input(format!("--fix `{f}`: `{}` is not a finite number", value.trim())))?;
        if pairs.iter().any(|(n, _): &(String, f64)| n == name.trim()) {
            return Err(input(format!("--fix: `{}` is given twice", name.trim())));
        }
        pairs.push((name.trim().to_string(), v));
    }
    let held = Fixed::new(model, &pairs).map_err(|e| input(format!("--fix: {e}")))?;
    // Every parameter held leaves an empty fit, which would otherwise fail later as "no
    // stiffness can produce mode 1 … a typing slip?".
    if !pairs.is_empty() && held.parameters().is_empty() {
        let names: Vec<&str> = pairs.iter().map(|(n, _)| n.as_str()).collect();
        return Err(input(format!(
            "--fix holds every parameter ({}): nothing is left to fit; leave at least one free (to see the \
             model at given values, use `simulate --set NAME=VALUE`)",
            names.join(", ")
        )));
    }
    Ok(held)
}

/// Points `K1:K2` separated by commas, each of `np` positive values (`--targets`, `--initials`).
pub fn points(flag: &str, text: &str, np: usize) -> Result<Vec<Vec<f64>>, WorkflowError> {
    text.split(',')
        .map(|item| {
            let p = parse_list(flag, &item.replace(':', ","))?;
            if p.len() != np || p.iter().any(|&v| v <= 0.0) {
                return Err(input(format!(
                    "{flag}: `{item}` must be {np} positive stiffnesses joined by `:`"
                )));
            }
            Ok(p)
        })
        .collect()
}
