//! [`MatricesModel`]: K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ from Matrix Market files, as a
//! [`StructuralModel`].

use crate::condensation::{Partition, MAX_CONDENSED_DOFS};
use crate::error::MatricesError;
use crate::layout::{Dof, DofLayout};
use crate::market::read_symmetric;
use eigenfit_core::matrix::{Condensed, CscSymmetric, Expansion, SparseSymmetric, System, SystemDerivative};
use eigenfit_core::measurement::measured_csv::shown_number;
use eigenfit_core::model::{Candidate, ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The model file's tables, as written (see docs/matrices.md).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    kind: String,
    #[serde(default)]
    name: Option<String>,
    /// `mtx` (Matrix Market, the default), `dmig` (Nastran) or `abaqus` (`*MATRIX OUTPUT`).
    #[serde(default)]
    format: Option<String>,
    stiffness: Files,
    mass: Files,
    #[serde(default)]
    dofs: Option<PathBuf>,
    /// Node coordinates (`node,x,y,z`) for the labelled formats' DOF map.
    #[serde(default)]
    nodes: Option<PathBuf>,
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
    stiffness: Option<Files>,
    mass: Option<Files>,
}

/// One matrix file, or several whose matrices are summed (`stiffness = ["K1.mtx", "K2.mtx"]`).
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Files {
    One(PathBuf),
    Several(Vec<PathBuf>),
}

impl Files {
    fn paths(&self) -> &[PathBuf] {
        match self {
            Files::One(p) => std::slice::from_ref(p),
            Files::Several(v) => v,
        }
    }
}

/// A parameter vector p and T(p) = [I; −X(p)], X = K_ss(p)⁻¹K_sm(p), there.
type LastCondensation = (Vec<f64>, Arc<Expansion>);

/// The static condensation of a model's massless DOFs and the last T = [I; −K_ss⁻¹K_sm] computed.
#[derive(Debug)]
struct Condensation {
    partition: Partition,
    /// (p, T(p)) of the last assembly: the derivatives at p reuse it.
    last: Mutex<Option<LastCondensation>>,
}

impl Clone for Condensation {
    fn clone(&self) -> Self {
        Self { partition: self.partition.clone(), last: Mutex::new(None) }
    }
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
    /// The DOF map's nodes and directions, for measured shapes (numbered as the condensed
    /// model's DOFs when some DOFs are massless).
    layout: Option<DofLayout>,
    /// The massless DOFs' static condensation, when M has zero rows.
    condensation: Option<Condensation>,
}

impl MatricesModel {
    /// Reads the model file `path` (TOML with `kind = "matrices"`) and the matrices it names
    /// (paths relative to it; a list of files is summed). Every error names the file and the
    /// entry or table at fault. Massless DOFs (zero rows of every mass matrix) are condensed
    /// out statically (see [`massless_dofs`](Self::massless_dofs)).
    pub fn from_toml_file(path: &Path) -> Result<Self, MatricesError> {
        let bytes = eigenfit_core::measurement::measured_csv::read_checked_file(
            path,
            MAX_MODEL_FILE_BYTES,
            "a matrices model file",
        )
        .map_err(|detail| MatricesError::Unreadable { detail })?;
        let text = String::from_utf8(bytes)
            .map_err(|_| MatricesError::invalid(path, "not UTF-8 text: a model file is TOML"))?;
        let file: ModelFile = toml::from_str(&text).map_err(|e| MatricesError::Toml {
            path: path.to_path_buf(),
            detail: eigenfit_core::names::with_serde_hint(&e.to_string()),
        })?;
        if file.kind != "matrices" {
            return Err(MatricesError::invalid(
                path,
                format!("kind = \"{}\": expected \"matrices\"", file.kind),
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        let at = |p: &Path| dir.join(p);
        let labeled = match file.format.as_deref() {
            None | Some("mtx") | Some("matrix-market") => None,
            Some(f @ ("dmig" | "abaqus")) => {
                if file.dofs.is_some() {
                    return Err(MatricesError::invalid(
                        path,
                        format!("format = \"{f}\" takes its DOF map from the files' node and DOF labels: leave out `dofs` (give coordinates with `nodes = \"nodes.csv\"`)"),
                    ));
                }
                let mut every: Vec<&PathBuf> = file.stiffness.paths().iter().chain(file.mass.paths()).collect();
                for t in file.parameter.iter().chain(&file.candidate) {
                    for files in [&t.stiffness, &t.mass].into_iter().flatten() {
                        every.extend(files.paths());
                    }
                }
                Some(crate::labeled_model::read_all(path, dir, f, &every, file.nodes.as_deref())?)
            }
            Some(other) => {
                return Err(MatricesError::invalid(
                    path,
                    format!("format = \"{other}\": expected \"mtx\" (Matrix Market, the default), \"dmig\" or \"abaqus\""),
                ))
            }
        };
        if labeled.is_none() && file.nodes.is_some() {
            return Err(MatricesError::invalid(
                path,
                "`nodes` places the labelled formats' nodes (format = \"dmig\" or \"abaqus\"); a Matrix Market model's DOF map is `dofs`",
            ));
        }
        let read_one = |p: &Path, expected: Option<usize>| -> Result<CscSymmetric, MatricesError> {
            match &labeled {
                Some(l) => Ok(l.matrix(p).clone()),
                None => read_symmetric(&at(p), expected),
            }
        };
        let read_sum =
            |files: &Files, expected: Option<usize>, what: &str| -> Result<CscSymmetric, MatricesError> {
                let paths = files.paths();
                if paths.is_empty() {
                    return Err(MatricesError::invalid(path, format!("{what}: the list of files is empty")));
                }
                let mut sum = read_one(&paths[0], expected)?;
                let n = sum.dim();
                for p in &paths[1..] {
                    let next = read_one(p, Some(n))?;
                    sum = CscSymmetric::combination(1.0, &sum, 1.0, &next);
                }
                Ok(sum)
            };
        let k0 = read_sum(&file.stiffness, None, "`stiffness`")?;
        let n = k0.dim();
        let m0 = read_sum(&file.mass, Some(n), "`mass`")?;
        let read_opt = |p: &Option<Files>, what: &str| -> Result<Option<CscSymmetric>, MatricesError> {
            p.as_ref().map(|p| read_sum(p, Some(n), what)).transpose()
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
            derivative_matrices.push((
                read_opt(&t.stiffness, &format!("{table} `stiffness`"))?,
                read_opt(&t.mass, &format!("{table} `mass`"))?,
            ));
        }
        let params = ParameterSet::new(list).map_err(|e| MatricesError::invalid(path, e.to_string()))?;
        let mut candidate_matrices = Vec::with_capacity(file.candidate.len());
        for (i, t) in file.candidate.iter().enumerate() {
            let table = format!("[[candidate]] {} (`{}`)", i + 1, t.name);
            // The candidate's value is fitted beside the parameters, under its name: a clash
            // would make the fit's parameters ambiguous.
            if params.iter().any(|p| p.name == t.name) {
                return Err(MatricesError::invalid(
                    path,
                    format!("{table}: named like a [[parameter]]: a candidate's name must differ from every parameter's"),
                ));
            }
            if file.candidate[..i].iter().any(|other| other.name == t.name) {
                return Err(MatricesError::invalid(
                    path,
                    format!("{table}: another [[candidate]] has the same name"),
                ));
            }
            if t.scale.is_some() {
                return Err(MatricesError::invalid(
                    path,
                    format!("{table}: `scale` belongs to a [[parameter]]: a candidate is linear"),
                ));
            }
            let (stiffness, mass) = (
                read_opt(&t.stiffness, &format!("{table} `stiffness`"))?,
                read_opt(&t.mass, &format!("{table} `mass`"))?,
            );
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
                Some([a, b]) if a <= b && (a < lower || b > upper) => {
                    return Err(MatricesError::invalid(
                        path,
                        format!(
                            "{table}: plausible = [{}, {}] lies outside the candidate's bounds [{}, {}] (`lower`, `upper`): a value outside them is never fitted",
                            shown_number(a),
                            shown_number(b),
                            shown_number(lower),
                            shown_number(upper)
                        ),
                    ))
                }
                Some([a, b]) if a <= b => (a, b),
                Some([a, b]) => {
                    return Err(MatricesError::invalid(
                        path,
                        format!("{table}: plausible = [{a}, {b}] is not a range"),
                    ))
                }
                None => (lower, upper),
            };
            candidate_matrices.push((table, t.name.clone(), p, plausible, stiffness, mass));
        }
        let dofs = match (&file.dofs, &labeled) {
            (Some(p), _) => {
                let map = read_dof_map(&at(p), n)?;
                DofLayout::new(&map).map_err(|e| MatricesError::invalid(&at(p), e.to_string()))?;
                Some(map)
            }
            (None, Some(l)) => Some(l.dof_map()),
            (None, None) => None,
        };
        let name = file.name.unwrap_or_else(|| path.display().to_string());
        check_every_dof_used(path, n, &k0, &m0, &derivative_matrices, dofs.as_deref())?;
        let mut model = Self::assemble_terms(name, params, k0, m0, derivative_matrices);
        model.dofs = dofs;
        model.condense_massless().map_err(|e| MatricesError::invalid(path, e))?;
        // A map that fails here was refused above already.
        let layout = match &labeled {
            Some(l) => l.layout(),
            None => model.dofs.as_deref().and_then(|d| DofLayout::new(d).ok()),
        };
        model.layout = layout.map(|layout| match &model.condensation {
            Some(c) => layout.renumbered(|j| c.partition.kept_index(j)),
            None => layout,
        });
        for (table, name, p, plausible, stiffness, mass) in candidate_matrices {
            let candidate = model
                .candidate(name, p, plausible, stiffness, mass)
                .map_err(|e| MatricesError::invalid(path, format!("{table}: {e}")))?;
            model.candidates.push(candidate);
        }
        Ok(model)
    }

    /// Sets up the static condensation when some DOFs have no mass in M₀ nor in any ∂M/∂pᵢ,
    /// checking at the nominal values that the massless DOFs are held by stiffness (K_ss
    /// invertible) and that every massed DOF has a positive mass on the diagonal. The error
    /// names the DOF.
    fn condense_massless(&mut self) -> Result<(), String> {
        let n = self.pattern.dim();
        let mut masses = vec![&self.mass.matrix];
        masses.extend(self.derivatives.iter().filter_map(|(_, m)| m.as_ref().map(|t| &t.matrix)));
        let nominal = self.params.nominal_values();
        let m =
            self.combine(&self.mass, nominal.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.1.as_ref())));
        // Every DOF some mass matrix couples (its row or column), whatever the triangle stored.
        let mut coupled = vec![false; n];
        for a in &masses {
            for (c, t) in coupled.iter_mut().zip(touched(a)) {
                *c |= t;
            }
        }
        if let Some(j) = (0..n).find(|&j| {
            let diagonal = m.get(j, j);
            diagonal < 0.0 || (diagonal == 0.0 && coupled[j])
        }) {
            // A negative mass is wrong whatever M couples; a zero one only when M couples the DOF.
            let why =
                if m.get(j, j) < 0.0 { ", a negative mass" } else { ", but M couples it to other DOFs" };
            return Err(format!(
                "{}: its mass on the diagonal is {} at the nominal values{why}: M is not positive \
                 semi-definite (a massless DOF has a zero row and column)",
                self.full_dof_label(j),
                m.get(j, j)
            ));
        }
        let Some(partition) = Partition::of(n, &masses) else { return Ok(()) };
        let (kept, massless) = (partition.kept().len(), partition.massless().len());
        if kept == 0 {
            return Err("the mass matrices are all zero: no DOF has mass".into());
        }
        if kept > MAX_CONDENSED_DOFS || massless > MAX_CONDENSED_DOFS {
            return Err(format!(
                "{massless} of the {n} DOFs have no mass (zero rows of M); they are condensed out statically with \
                 dense matrices, done for at most {MAX_CONDENSED_DOFS} massed and {MAX_CONDENSED_DOFS} massless DOFs \
                 (this model has {kept} and {massless}); give the massless DOFs a mass, or condense them in the FE tool"
            ));
        }
        self.condensation = Some(Condensation { partition, last: Mutex::new(None) });
        self.condensed_t(&nominal).map(|_| ()).map_err(|e| e.to_string())
    }

    /// `DOF j (node N direction D)` with the DOF map, `DOF j` without (j from 1).
    fn full_dof_label(&self, j: usize) -> String {
        match self.dofs.as_deref().and_then(|d| d.get(j)) {
            Some(d) => format!("DOF {} (node {} direction {})", j + 1, d.node, d.direction),
            None => format!("DOF {}", j + 1),
        }
    }

    /// The full K(p) and T(p) = [I; −X(p)], X = K_ss(p)⁻¹K_sm(p) held as K_sm and a sparse factor
    /// of K_ss (never formed densely), remembered for the derivatives at `p`.
    fn condense_at(&self, p: &[f64]) -> Result<(CscSymmetric, Arc<Expansion>), ModelError> {
        let c = self.condensation.as_ref().expect("a condensed model");
        let k =
            self.combine(&self.stiffness, p.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.0.as_ref())));
        let partition = &c.partition;
        if let Some(t) = Expansion::factored(&k, partition.kept().to_vec(), partition.massless().to_vec()) {
            let t = Arc::new(t);
            *c.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((p.to_vec(), Arc::clone(&t)));
            return Ok((k, t));
        }
        // K_ss is singular: the dense condensation finds the massless DOF, pivot by pivot in the
        // model's order, for the message.
        let (_, x) = c.partition.condense(&k).map_err(|at| {
            // A negative pivot is a negative stiffness (an unstable massless DOF), not a missing one.
            let held = if at.1 < 0.0 {
                format!(
                    "has a negative stiffness ({:e} once the massless DOFs before it are held; K_ss, the \
                     stiffness among the {} massless DOFs, is not positive definite there) at {}: a massless \
                     DOF on a negative spring has no static equilibrium; check the stiffness's sign",
                    at.1,
                    c.partition.massless().len(),
                    self.values_text(p)
                )
            } else {
                format!(
                    "is held by no stiffness once the massless DOFs before it are (K_ss, the stiffness among \
                     the {} massless DOFs, is singular there) at {}: its static condensation does not exist; \
                     give it a mass or a stiffness",
                    c.partition.massless().len(),
                    self.values_text(p)
                )
            };
            ModelError::Invalid(format!("massless {} {held}", self.full_dof_label(at.0)))
        })?;
        // The sparse factor refused a K_ss the dense one accepts (a pivot near the 1e-12 limit in
        // another order): the dense X serves.
        let t = Arc::new(c.partition.expansion(&x));
        *c.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((p.to_vec(), Arc::clone(&t)));
        Ok((k, t))
    }

    /// T(p), from the last assembly when it was at `p`.
    fn condensed_t(&self, p: &[f64]) -> Result<Arc<Expansion>, ModelError> {
        let c = self.condensation.as_ref().expect("a condensed model");
        if let Some((q, x)) = c.last.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            if q.as_slice() == p {
                return Ok(Arc::clone(x));
            }
        }
        self.condense_at(p).map(|(_, t)| t)
    }

    /// `name = value, …` of the parameter vector `p`, for messages.
    fn values_text(&self, p: &[f64]) -> String {
        if p.is_empty() {
            return "the nominal values".into();
        }
        self.params.iter().zip(p).map(|(q, v)| format!("{} = {v}", q.name)).collect::<Vec<_>>().join(", ")
    }

    /// A `[[candidate]]`'s effect on this model's DOFs: as read, or for a condensed model its
    /// mass restricted to the massed DOFs (a candidate may not give a massless DOF mass) and
    /// its stiffness projected by T = [I; −X] at the nominal values (exact as a derivative at
    /// the nominal values; a candidate away from the massless DOFs is exact everywhere).
    fn candidate(
        &self,
        name: String,
        p: Parameter,
        plausible: (f64, f64),
        stiffness: Option<CscSymmetric>,
        mass: Option<CscSymmetric>,
    ) -> Result<Candidate, String> {
        let n = self.dofs();
        let (stiffness, mass) = match &self.condensation {
            None => (
                stiffness.map_or_else(|| SparseSymmetric::zeros(n), |a| a.to_sparse_symmetric()),
                mass.map_or_else(|| SparseSymmetric::zeros(n), |a| a.to_sparse_symmetric()),
            ),
            Some(c) => {
                let mass = match mass {
                    Some(m) => {
                        let touched = touched(&m);
                        if let Some(&j) = c.partition.massless().iter().find(|&&j| touched[j]) {
                            return Err(format!(
                                "its `mass` gives massless {} a mass; the model condenses its massless DOFs out, \
                                 so a candidate's mass must lie on DOFs that have mass",
                                self.full_dof_label(j)
                            ));
                        }
                        c.partition.restrict(&m).to_sparse_symmetric()
                    }
                    None => SparseSymmetric::zeros(n),
                };
                let stiffness = match stiffness {
                    Some(k) => {
                        let t = self.condensed_t(&self.params.nominal_values()).map_err(|e| e.to_string())?;
                        SparseSymmetric::congruent(k.to_sparse_symmetric(), t)
                    }
                    None => SparseSymmetric::zeros(n),
                };
                (stiffness, mass)
            }
        };
        Ok(Candidate::linear(name, None, Some(p), plausible, stiffness, mass))
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
        let mut model = Self::assemble_terms(name.into(), params, stiffness, mass, derivatives);
        // A massless DOF that cannot be condensed is reported by `assemble`, naming the DOF.
        let _ = model.condense_massless();
        model
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
            condensation: None,
        }
    }

    /// Number of DOFs of the matrices as read (the DOF map's count); [`dofs`](StructuralModel::dofs)
    /// is the massed DOFs' when some are massless.
    pub fn full_dofs(&self) -> usize {
        self.pattern.dim()
    }

    /// The massless DOFs (0-based indices of the matrices as read): those with a zero row in M₀
    /// and in every ∂M/∂pᵢ, condensed out statically. Empty when every DOF has mass.
    pub fn massless_dofs(&self) -> &[usize] {
        self.condensation.as_ref().map_or(&[], |c| c.partition.massless())
    }

    /// A mode shape of the model (one value per [`dofs`](StructuralModel::dofs)) on every DOF of
    /// the matrices as read: the massless DOFs' values are −X φ with X = K_ss⁻¹K_sm at `p`
    /// (exactly the full eigenvector); the shape itself when no DOF is massless.
    pub fn expand_shape(&self, p: &[f64], shape: &[f64]) -> Result<Vec<f64>, ModelError> {
        if shape.len() != self.dofs() {
            return Err(ModelError::Invalid(format!(
                "a shape of {} values for a model of {} DOFs",
                shape.len(),
                self.dofs()
            )));
        }
        match &self.condensation {
            None => Ok(shape.to_vec()),
            Some(_) => {
                self.params.check(p)?;
                Ok(self.condensed_t(p)?.expand(shape))
            }
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

    /// The DOF map, when the model file gives one: entry i describes DOF i of the matrices as
    /// read (see [`full_dofs`](Self::full_dofs)).
    pub fn dof_map(&self) -> Option<&[Dof]> {
        self.dofs.as_deref()
    }

    /// The DOF map as nodes and directions (measured shapes are tied to DOFs through it), when
    /// the model file gives one; its DOFs are the model's ([`dofs`](StructuralModel::dofs)): a
    /// massless DOF is not among them.
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

/// Largest model TOML file read (bytes), as for any `--model` file: its matrices live in their
/// own files.
const MAX_MODEL_FILE_BYTES: u64 = 64 << 20;

/// Largest DOF map read (bytes): about 60 bytes a DOF, 10⁷ DOFs.
const MAX_DOF_MAP_BYTES: u64 = 1 << 30;

/// Which DOFs a nonzero entry of `a` touches (its row or column).
fn touched(a: &CscSymmetric) -> Vec<bool> {
    let mut out = vec![false; a.dim()];
    for c in 0..a.dim() {
        let (rows, values) = a.column(c);
        for (&r, &v) in rows.iter().zip(values) {
            if v != 0.0 {
                out[r] = true;
                out[c] = true;
            }
        }
    }
    out
}

/// Refuses a DOF that no stiffness or mass matrix touches: it would have neither stiffness
/// nor mass (a size line larger than the model, or a DOF numbering with gaps).
fn check_every_dof_used(
    path: &Path,
    n: usize,
    k0: &CscSymmetric,
    m0: &CscSymmetric,
    derivatives: &[(Option<CscSymmetric>, Option<CscSymmetric>)],
    dofs: Option<&[Dof]>,
) -> Result<(), MatricesError> {
    let mut used = touched(k0);
    let mut mark = |a: &CscSymmetric| {
        for (u, t) in used.iter_mut().zip(touched(a)) {
            *u |= t;
        }
    };
    mark(m0);
    for (k, m) in derivatives {
        for a in [k, m].into_iter().flatten() {
            mark(a);
        }
    }
    let unused: Vec<usize> = (0..n).filter(|&j| !used[j]).collect();
    let Some(&first) = unused.first() else { return Ok(()) };
    let label = match dofs.and_then(|d| d.get(first)) {
        Some(d) => format!("DOF {} (node {} direction {})", first + 1, d.node, d.direction),
        None => format!("DOF {}", first + 1),
    };
    Err(MatricesError::invalid(
        path,
        format!(
            "{label} has no entry in any stiffness or mass matrix ({} of the {n} DOFs have none): \
             the matrices' size line declares more rows than the model has, or the DOF numbering has gaps",
            unused.len()
        ),
    ))
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
    // Bounds are shown as numbers a reader can take in (1e-300, not 300 digits).
    let (n, lo, hi) = (shown_number(nominal), shown_number(lower), shown_number(upper));
    if scale == Scale::Log && (nominal <= 0.0 || lower < 0.0) {
        return Err(format!(
            "scale = \"log\" needs a positive nominal and lower bound (nominal = {n}, lower = {lo})"
        ));
    }
    if lower > upper {
        return Err(format!("lower = {lo} is above upper = {hi}"));
    }
    if nominal < lower || nominal > upper {
        return Err(format!("nominal = {n} lies outside [{lo}, {hi}]"));
    }
    let lower = if scale == Scale::Log { lower.max(f64::MIN_POSITIVE) } else { lower };
    Ok(Parameter::new(name, unit.unwrap_or(""), nominal).with_bounds(lower, upper).with_scale(scale))
}

/// Reads the DOF map: CSV with header `dof,node,direction,x,y,z`, DOFs counted from 1, one row
/// per DOF of the model.
fn read_dof_map(path: &Path, n: usize) -> Result<Vec<Dof>, MatricesError> {
    // Every field spelled out, no `#[serde(flatten)]`: through a flattened struct the csv crate
    // infers each field's type, so a direction written `1` (the universal file's number, which
    // the docs accept) arrived as an integer and was refused as "expected a string".
    #[derive(Deserialize)]
    struct Row {
        dof: usize,
        node: u64,
        direction: String,
        x: f64,
        y: f64,
        z: f64,
    }
    let bytes =
        eigenfit_core::measurement::measured_csv::read_checked_file(path, MAX_DOF_MAP_BYTES, "a DOF map")
            .map_err(|detail| MatricesError::Unreadable { detail })?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(bytes.as_slice());
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
        out[row.dof - 1] =
            Some(Dof { node: row.node, direction: row.direction, x: row.x, y: row.y, z: row.z });
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

    /// The massed DOFs when some are condensed out, else all.
    fn dofs(&self) -> usize {
        match &self.condensation {
            Some(c) => c.partition.kept().len(),
            None => self.pattern.dim(),
        }
    }

    /// `DOF j (node N direction D)` in the file's numbering (from 1), for the massed DOF `j` of a
    /// condensed model too.
    fn dof_label(&self, j: usize) -> String {
        match &self.condensation {
            Some(c) => c
                .partition
                .kept()
                .get(j)
                .map_or_else(|| format!("DOF {}", j + 1), |&f| self.full_dof_label(f)),
            None => self.full_dof_label(j),
        }
    }

    /// K(p), M(p); for a model with massless DOFs the condensed K_c(p) and M_mm(p).
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let m = self.combine(&self.mass, p.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.1.as_ref())));
        if self.condensation.is_some() {
            // Kept as the full sparse pencil: the solvers factor K − σM (sparse, narrow), not
            // the dense K_c.
            let (k, t) = self.condense_at(p)?;
            return Ok(System::condensed(Condensed::new(k, m, t))?);
        }
        let k =
            self.combine(&self.stiffness, p.iter().zip(&self.derivatives).map(|(&v, d)| (v, d.0.as_ref())));
        Ok(System::sparse(k, m)?)
    }

    /// Exact: K and M are linear in every parameter; with massless DOFs ∂K_c/∂pᵢ = Tᵀ(∂K/∂pᵢ)T
    /// (the `condensation` module), exact too, held as ∂K/∂pᵢ and T (it would fill in densely).
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let (dk, dm) = self
            .derivatives
            .get(i)
            .ok_or(ModelError::ParameterIndex { index: i, count: self.params.len() })?;
        self.params.check(p)?;
        let n = self.dofs();
        if let Some(c) = &self.condensation {
            let stiffness = match dk {
                Some(t) => SparseSymmetric::congruent(t.matrix.to_sparse_symmetric(), self.condensed_t(p)?),
                None => SparseSymmetric::zeros(n),
            };
            let mass = dm.as_ref().map_or_else(
                || SparseSymmetric::zeros(n),
                |t| c.partition.restrict(&t.matrix).to_sparse_symmetric(),
            );
            return Ok(SystemDerivative { stiffness, mass });
        }
        let convert = |t: &Option<Term>| {
            t.as_ref().map_or_else(|| SparseSymmetric::zeros(n), |t| t.matrix.to_sparse_symmetric())
        };
        Ok(SystemDerivative { stiffness: convert(dk), mass: convert(dm) })
    }

    fn candidates(&self) -> Vec<Candidate> {
        self.candidates.clone()
    }
}
