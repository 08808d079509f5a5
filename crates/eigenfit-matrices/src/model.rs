//! [`MatricesModel`]: K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ from Matrix Market files, as a
//! [`StructuralModel`].

use crate::error::MatricesError;
use crate::layout::{Dof, DofLayout};
use crate::market::read_symmetric;
use eigenfit_core::matrix::{CscSymmetric, System, SystemDerivative};
use eigenfit_core::model::{Candidate, ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The model file's tables, as written (see docs/matrices.md).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    kind: String,
    #[serde(default)]
    name: Option<String>,
    stiffness: PathBuf,
    mass: PathBuf,
    #[serde(default)]
    dofs: Option<PathBuf>,
    #[serde(default)]
    parameter: Vec<TermTable>,
    #[serde(default)]
    candidate: Vec<TermTable>,
}

/// A `[[parameter]]` or `[[candidate]]` table: both name a matrix term with its range; a
/// parameter needs `nominal` and may have `scale`, a candidate may have `plausible` (checked
/// when read, naming the table). A missing field reads as `None`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TermTable {
    name: String,
    nominal: Option<f64>,
    lower: Option<f64>,
    upper: Option<f64>,
    scale: Option<Scale>,
    plausible: Option<[f64; 2]>,
    unit: Option<String>,
    stiffness: Option<PathBuf>,
    mass: Option<PathBuf>,
}

/// A matrix of the model with the positions of its entries in the common pattern.
#[derive(Debug, Clone)]
struct Term {
    matrix: CscSymmetric,
    /// Index into the common pattern's values of each stored entry.
    slots: Vec<usize>,
}

/// A model given by its matrices: K(p) = K₀ + Σ pᵢKᵢ and M(p) = M₀ + Σ pᵢMᵢ (symmetric, sparse),
/// read from Matrix Market files named in a TOML file.
///
/// Assembly is O(nnz): every matrix's entries were mapped once onto one pattern common to K(p)
/// and M(p) (so the sparse solver's symbolic factorisation is computed once per model), and the
/// derivatives Kᵢ, Mᵢ are exact and cost O(nnz(Kᵢ) + nnz(Mᵢ)).
#[derive(Debug, Clone)]
pub struct MatricesModel {
    name: String,
    params: ParameterSet,
    pattern: CscSymmetric,
    stiffness: Term,
    mass: Term,
    /// (∂K/∂pᵢ, ∂M/∂pᵢ), `None` where the file gives none.
    derivatives: Vec<(Option<Term>, Option<Term>)>,
    candidates: Vec<Candidate>,
    dofs: Option<Vec<Dof>>,
    /// The DOF map's nodes and directions, for measured shapes.
    layout: Option<DofLayout>,
}

impl MatricesModel {
    /// Reads the model file `path` (TOML with `kind = "matrices"`) and the matrices it names
    /// (paths relative to it). Every error names the file and the entry or table at fault.
    pub fn from_toml_file(path: &Path) -> Result<Self, MatricesError> {
        let text = std::fs::read_to_string(path).map_err(|e| MatricesError::io(path, e))?;
        let file: ModelFile = toml::from_str(&text)
            .map_err(|e| MatricesError::Toml { path: path.to_path_buf(), detail: e.to_string() })?;
        if file.kind != "matrices" {
            return Err(MatricesError::invalid(
                path,
                format!("kind = \"{}\": expected \"matrices\"", file.kind),
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        let at = |p: &Path| dir.join(p);
        let k0 = read_symmetric(&at(&file.stiffness), None)?;
        let n = k0.dim();
        let m0 = read_symmetric(&at(&file.mass), Some(n))?;
        let read_opt = |p: &Option<PathBuf>| -> Result<Option<CscSymmetric>, MatricesError> {
            p.as_ref().map(|p| read_symmetric(&at(p), Some(n))).transpose()
        };
        let mut list = Vec::with_capacity(file.parameter.len());
        let mut derivative_matrices = Vec::with_capacity(file.parameter.len());
        for (i, t) in file.parameter.iter().enumerate() {
            let table = format!("[[parameter]] {} (`{}`)", i + 1, t.name);
            let refuse = |what: &str| MatricesError::invalid(path, format!("{table}: {what}"));
            let nominal = t.nominal.ok_or_else(|| refuse("missing field `nominal`"))?;
            if t.plausible.is_some() {
                return Err(refuse("`plausible` belongs to a [[candidate]], not to a parameter"));
            }
            let parameter = parameter(&t.name, nominal, t.lower, t.upper, t.scale, t.unit.as_deref())
                .map_err(|e| MatricesError::invalid(path, format!("{table}: {e}")))?;
            if t.stiffness.is_none() && t.mass.is_none() {
                return Err(MatricesError::invalid(
                    path,
                    format!(
                        "{table}: gives neither `stiffness` nor `mass`: the parameter would change nothing"
                    ),
                ));
            }
            list.push(parameter);
            derivative_matrices.push((read_opt(&t.stiffness)?, read_opt(&t.mass)?));
        }
        let params = ParameterSet::new(list).map_err(|e| MatricesError::invalid(path, e.to_string()))?;
        let mut candidates = Vec::with_capacity(file.candidate.len());
        for (i, t) in file.candidate.iter().enumerate() {
            let table = format!("[[candidate]] {} (`{}`)", i + 1, t.name);
            if t.scale.is_some() {
                return Err(MatricesError::invalid(
                    path,
                    format!("{table}: `scale` belongs to a [[parameter]]: a candidate is linear"),
                ));
            }
            let (stiffness, mass) = (read_opt(&t.stiffness)?, read_opt(&t.mass)?);
            if stiffness.is_none() && mass.is_none() {
                return Err(MatricesError::invalid(
                    path,
                    format!("{table}: gives neither `stiffness` nor `mass`"),
                ));
            }
            let nominal = t.nominal.unwrap_or(0.0);
            let lower = t.lower.unwrap_or(0.0);
            let upper = t.upper.unwrap_or(f64::INFINITY);
            let p =
                parameter(&t.name, nominal, Some(lower), Some(upper), Some(Scale::Linear), t.unit.as_deref())
                    .map_err(|e| MatricesError::invalid(path, format!("{table}: {e}")))?;
            let plausible = match t.plausible {
                Some([a, b]) if a <= b => (a, b),
                Some([a, b]) => {
                    return Err(MatricesError::invalid(
                        path,
                        format!("{table}: plausible = [{a}, {b}] is not a range"),
                    ))
                }
                None => (lower, upper),
            };
            let zero = || CscSymmetric::from_triplets(n, []);
            candidates.push(Candidate::linear(
                t.name.clone(),
                None,
                Some(p),
                plausible,
                stiffness.unwrap_or_else(zero).to_sparse_symmetric(),
                mass.unwrap_or_else(zero).to_sparse_symmetric(),
            ));
        }
        let dofs = match &file.dofs {
            Some(p) => {
                let map = read_dof_map(&at(p), n)?;
                DofLayout::new(&map).map_err(|e| MatricesError::invalid(&at(p), e.to_string()))?;
                Some(map)
            }
            None => None,
        };
        let name = file.name.unwrap_or_else(|| path.display().to_string());
        let mut model = Self::assemble_terms(name, params, k0, m0, derivative_matrices);
        // A map that fails here was refused above already.
        model.layout = dofs.as_deref().and_then(|d| DofLayout::new(d).ok());
        model.dofs = dofs;
        model.candidates = candidates;
        Ok(model)
    }

    /// A model from matrices already in memory: K₀, M₀ and, per parameter, (∂K/∂pᵢ, ∂M/∂pᵢ).
    ///
    /// # Panics
    /// When the sizes differ or the derivative list does not match the parameters (a bug in the
    /// caller; files go through [`from_toml_file`](Self::from_toml_file), which reports them).
    pub fn new(
        name: impl Into<String>,
        params: ParameterSet,
        stiffness: CscSymmetric,
        mass: CscSymmetric,
        derivatives: Vec<(Option<CscSymmetric>, Option<CscSymmetric>)>,
    ) -> Self {
        assert_eq!(derivatives.len(), params.len(), "one derivative pair per parameter");
        Self::assemble_terms(name.into(), params, stiffness, mass, derivatives)
    }

    /// The model without candidates or DOF map, its matrices mapped onto their common pattern.
    fn assemble_terms(
        name: String,
        params: ParameterSet,
        k0: CscSymmetric,
        m0: CscSymmetric,
        derivatives: Vec<(Option<CscSymmetric>, Option<CscSymmetric>)>,
    ) -> Self {
        let n = k0.dim();
        // The common pattern: every matrix's entries, zero-valued.
        let mut pattern = CscSymmetric::combination(0.0, &k0, 0.0, &m0);
        for (k, m) in &derivatives {
            for a in [k, m].into_iter().flatten() {
                assert_eq!(a.dim(), n, "derivative matrices of the model's size");
                pattern = CscSymmetric::combination(0.0, &pattern, 0.0, a);
            }
        }
        let term = |matrix: CscSymmetric| Term { slots: slots(&pattern, &matrix), matrix };
        let stiffness = term(k0);
        let mass = term(m0);
        let derivatives = derivatives.into_iter().map(|(k, m)| (k.map(term), m.map(term))).collect();
        Self {
            name,
            params,
            pattern,
            stiffness,
            mass,
            derivatives,
            candidates: Vec::new(),
            dofs: None,
            layout: None,
        }
    }

    /// The model's name (the `name` key, or the file's path).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Stored entries of the common pattern of K(p) and M(p) (upper triangle).
    pub fn nnz(&self) -> usize {
        self.pattern.nnz()
    }

    /// The DOF map, when the model file gives one: entry i describes DOF i.
    pub fn dof_map(&self) -> Option<&[Dof]> {
        self.dofs.as_deref()
    }

    /// The DOF map as nodes and directions (measured shapes are tied to DOFs through it), when
    /// the model file gives one.
    pub fn layout(&self) -> Option<&DofLayout> {
        self.layout.as_ref()
    }

    /// Permutations π of the parameters under which the model may be symmetric: parameter i
    /// exchanged with π\[i\] keeps every trace and Frobenius inner product of the matrices
    /// (see the `symmetry` module), among parameters of the same unit, scale and limits. The
    /// frequencies at p and at p permuted are then expected equal; confirm by one solve.
    /// Empty for an asymmetric structure. O(np² · nnz).
    pub fn parameter_symmetries(&self) -> Vec<Vec<usize>> {
        let terms: Vec<_> = self
            .derivatives
            .iter()
            .map(|(k, m)| (k.as_ref().map(|t| &t.matrix), m.as_ref().map(|t| &t.matrix)))
            .collect();
        let params = self.params.as_slice();
        crate::symmetry::invariant_permutations(&self.stiffness.matrix, &self.mass.matrix, &terms, |i, j| {
            let (a, b) = (&params[i], &params[j]);
            a.unit == b.unit && a.scale == b.scale && a.lower == b.lower && a.upper == b.upper
        })
    }

    /// `base + Σ pᵢ·termᵢ` on the common pattern.
    fn combine<'a>(&self, base: &Term, terms: impl Iterator<Item = (f64, Option<&'a Term>)>) -> CscSymmetric {
        let mut out = self.pattern.clone();
        let values = out.values_mut();
        values.fill(0.0);
        add(values, 1.0, base);
        for (p, t) in terms {
            if let Some(t) = t {
                add(values, p, t);
            }
        }
        out
    }
}

fn add(values: &mut [f64], alpha: f64, term: &Term) {
    for (&slot, &v) in term.slots.iter().zip(term.matrix.values()) {
        values[slot] += alpha * v;
    }
}

/// Position in `pattern`'s values of each stored entry of `a` (a's pattern ⊆ pattern's).
fn slots(pattern: &CscSymmetric, a: &CscSymmetric) -> Vec<usize> {
    let mut out = Vec::with_capacity(a.nnz());
    for c in 0..a.dim() {
        let (rows, _) = pattern.column(c);
        let start = pattern.col_ptr()[c];
        let mut p = 0;
        for &r in a.column(c).0 {
            while rows[p] < r {
                p += 1;
            }
            debug_assert_eq!(rows[p], r, "pattern holds the entry");
            out.push(start + p);
        }
    }
    out
}

/// A checked [`Parameter`] from a table's values.
fn parameter(
    name: &str,
    nominal: f64,
    lower: Option<f64>,
    upper: Option<f64>,
    scale: Option<Scale>,
    unit: Option<&str>,
) -> Result<Parameter, String> {
    let scale = scale.unwrap_or(Scale::Linear);
    // A log-scale parameter lives on (0, ∞): that is its default range.
    let default_lower = match scale {
        Scale::Log => f64::MIN_POSITIVE,
        Scale::Linear => f64::NEG_INFINITY,
    };
    let (lower, upper) = (lower.unwrap_or(default_lower), upper.unwrap_or(f64::INFINITY));
    if name.trim().is_empty() {
        return Err("the name is empty".into());
    }
    if !nominal.is_finite() || lower.is_nan() || upper.is_nan() {
        return Err("nominal, lower and upper must be numbers (nominal finite)".into());
    }
    if scale == Scale::Log && (nominal <= 0.0 || lower < 0.0) {
        return Err(format!(
            "scale = \"log\" needs a positive nominal and lower bound (nominal = {nominal}, lower = {lower})"
        ));
    }
    if lower > upper {
        return Err(format!("lower = {lower} is above upper = {upper}"));
    }
    if nominal < lower || nominal > upper {
        return Err(format!("nominal = {nominal} lies outside [{lower}, {upper}]"));
    }
    let lower = if scale == Scale::Log { lower.max(f64::MIN_POSITIVE) } else { lower };
    Ok(Parameter::new(name, unit.unwrap_or(""), nominal).with_bounds(lower, upper).with_scale(scale))
}

/// Reads the DOF map: CSV with header `dof,node,direction,x,y,z`, DOFs counted from 1, one row
/// per DOF of the model.
fn read_dof_map(path: &Path, n: usize) -> Result<Vec<Dof>, MatricesError> {
    #[derive(Deserialize)]
    struct Row {
        dof: usize,
        #[serde(flatten)]
        info: Dof,
    }
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).map_err(|e| match e.into_kind() {
            csv::ErrorKind::Io(io) => MatricesError::io(path, io),
            other => MatricesError::invalid(path, format!("{other:?}")),
        })?;
    let mut out: Vec<Option<Dof>> = vec![None; n];
    for (line, row) in reader.deserialize::<Row>().enumerate() {
        let line = line + 2;
        let row = row.map_err(|e| MatricesError::invalid(path, format!("line {line}: {e}")))?;
        if row.dof == 0 || row.dof > n {
            return Err(MatricesError::invalid(path, format!("line {line}: dof {} outside 1…{n}", row.dof)));
        }
        if out[row.dof - 1].is_some() {
            return Err(MatricesError::invalid(path, format!("line {line}: dof {} given twice", row.dof)));
        }
        out[row.dof - 1] = Some(row.info);
    }
    if let Some(missing) = out.iter().position(Option::is_none) {
        return Err(MatricesError::invalid(
            path,
            format!("dof {} has no row: the map must describe all {n} DOFs", missing + 1),
        ));
    }
    Ok(out.into_iter().flatten().collect())
}

impl StructuralModel for MatricesModel {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }

    fn dofs(&self) -> usize {
        self.pattern.dim()
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let k =
            self.combine(&self.stiffness, p.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.0.as_ref())));
        let m = self.combine(&self.mass, p.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.1.as_ref())));
        Ok(System::sparse(k, m)?)
    }

    /// Exact: K and M are linear in every parameter.
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let (dk, dm) = self
            .derivatives
            .get(i)
            .ok_or(ModelError::ParameterIndex { index: i, count: self.params.len() })?;
        self.params.check(p)?;
        let n = self.dofs();
        let convert = |t: &Option<Term>| {
            t.as_ref().map_or_else(
                || eigenfit_core::matrix::SparseSymmetric::zeros(n),
                |t| t.matrix.to_sparse_symmetric(),
            )
        };
        Ok(SystemDerivative { stiffness: convert(dk), mass: convert(dm) })
    }

    fn candidates(&self) -> Vec<Candidate> {
        self.candidates.clone()
    }
}
