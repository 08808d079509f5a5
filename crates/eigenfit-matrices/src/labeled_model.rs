//! A model's matrices in a labelled format (`format = "dmig"` or `"abaqus"`): every file read,
//! the union of their (node, DOF) labels made the model's DOFs (sorted by node, then DOF), each
//! matrix placed on them, and the labels (with coordinates from GRID cards or `nodes`) as the
//! DOF map measured shapes are tied through.

use crate::error::MatricesError;
use crate::labeled::{parse_abaqus, parse_dmig, Label, LabeledMatrix};
use crate::layout::{Dof, DofLayout};
use crate::market::{read_matrix_text, symmetric_from_entries, MAX_DOFS};
use eigenfit_core::matrix::CscSymmetric;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Every matrix of a labelled model on the common DOFs.
#[derive(Debug)]
pub(crate) struct LabeledModel {
    labels: Vec<Label>,
    /// Each file as the model file names it (with its `#NAME`), placed on `labels`.
    matrices: HashMap<PathBuf, CscSymmetric>,
    coordinates: HashMap<u64, [f64; 3]>,
}

/// Direction names of components 1–6.
const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// Reads every file in `paths` (relative to `dir`; a DMIG file may name its matrix as
/// `file.pch#KAAX`) in `format`, with coordinates from `nodes` (`node,x,y,z`) if given.
pub(crate) fn read_all(
    model: &Path,
    dir: &Path,
    format: &str,
    paths: &[&PathBuf],
    nodes: Option<&Path>,
) -> Result<LabeledModel, MatricesError> {
    let mut read: Vec<(PathBuf, PathBuf, LabeledMatrix)> = Vec::with_capacity(paths.len());
    for &p in paths {
        if read.iter().any(|(q, _, _)| q == p) {
            continue;
        }
        let written = p.to_string_lossy();
        let (file, name) = match written.rsplit_once('#') {
            Some((f, n)) if format == "dmig" => (dir.join(f), Some(n.to_string())),
            _ => (dir.join(p), None),
        };
        let text = read_matrix_text(&file)?;
        let parsed = match format {
            "dmig" => parse_dmig(&text, name.as_deref()),
            _ => parse_abaqus(&text),
        }
        .map_err(|detail| MatricesError::Matrix { path: file.clone(), detail })?;
        read.push((p.clone(), file, parsed));
    }
    let mut labels: Vec<Label> =
        read.iter().flat_map(|(_, _, m)| m.entries.iter().flat_map(|&(r, c, _)| [r, c])).collect();
    labels.sort_unstable();
    labels.dedup();
    if labels.len() > MAX_DOFS {
        return Err(MatricesError::invalid(
            model,
            format!("the files label {} DOFs, more than the {MAX_DOFS} a model may have", labels.len()),
        ));
    }
    let index: HashMap<Label, usize> = labels.iter().enumerate().map(|(i, &l)| (l, i)).collect();
    let n = labels.len();
    let mut coordinates = HashMap::new();
    let mut matrices = HashMap::with_capacity(read.len());
    for (written, file, m) in read {
        coordinates.extend(m.coordinates.iter().map(|(&k, &v)| (k, v)));
        let entries: Vec<(usize, usize, f64)> =
            m.entries.iter().map(|&(r, c, v)| (index[&r], index[&c], v)).collect();
        let line_of =
            |r: usize, c: usize| entries.iter().position(|&(a, b, _)| (a, b) == (r, c)).map(|k| m.lines[k]);
        // A message names the model's DOFs (from 1, in label order) and the file's lines.
        let matrix = symmetric_from_entries(n, entries.clone(), &line_of)
            .map_err(|detail| MatricesError::Matrix { path: file.clone(), detail })?;
        matrices.insert(written, matrix);
    }
    if let Some(nodes) = nodes {
        coordinates.extend(read_nodes(&dir.join(nodes))?);
    }
    Ok(LabeledModel { labels, matrices, coordinates })
}

/// `node,x,y,z` rows.
fn read_nodes(path: &Path) -> Result<HashMap<u64, [f64; 3]>, MatricesError> {
    #[derive(serde::Deserialize)]
    struct Row {
        node: u64,
        x: f64,
        y: f64,
        z: f64,
    }
    let bytes = eigenfit_core::measurement::measured_csv::read_checked_file(path, 1 << 30, "a node file")
        .map_err(|detail| MatricesError::Unreadable { detail })?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(bytes.as_slice());
    let mut out = HashMap::new();
    for (line, row) in reader.deserialize::<Row>().enumerate() {
        let row = row.map_err(|e| MatricesError::invalid(path, format!("line {}: {e}", line + 2)))?;
        if ![row.x, row.y, row.z].iter().all(|c| c.is_finite()) {
            return Err(MatricesError::invalid(
                path,
                format!("line {}: node {}: a coordinate is not finite", line + 2, row.node),
            ));
        }
        out.insert(row.node, [row.x, row.y, row.z]);
    }
    Ok(out)
}

impl LabeledModel {
    /// The matrix of the file as the model file names it.
    pub fn matrix(&self, written: &Path) -> &CscSymmetric {
        &self.matrices[written]
    }

    /// The DOF map of the labels: node, direction (x … rz; `dof0` for a scalar point, `dofN`
    /// beyond 6), coordinates (NaN where no file gives them).
    pub fn dof_map(&self) -> Vec<Dof> {
        self.labels
            .iter()
            .map(|&(node, c)| {
                let [x, y, z] = self.coordinates.get(&node).copied().unwrap_or([f64::NAN; 3]);
                let direction = match c {
                    1..=6 => DIRECTIONS[usize::from(c) - 1].to_string(),
                    other => format!("dof{other}"),
                };
                Dof { node, direction, x, y, z }
            })
            .collect()
    }

    /// The layout measured shapes are tied through: the translational and rotational DOFs of
    /// nodes with coordinates; `None` when no node has any.
    pub fn layout(&self) -> Option<DofLayout> {
        let map = self.dof_map();
        let placed: Vec<usize> =
            (0..map.len()).filter(|&i| (1..=6).contains(&self.labels[i].1) && map[i].x.is_finite()).collect();
        if placed.is_empty() {
            return None;
        }
        let dofs: Vec<Dof> = placed.iter().map(|&i| map[i].clone()).collect();
        DofLayout::new(&dofs).ok().map(|l| l.renumbered(|k| placed.get(k).copied()))
    }
}
