//! The sparse eigen-solver, for models that are neither small nor banded (plates, shells, solids
//! from any FE tool, 10⁴–10⁶ DOFs): shift-invert Lanczos (`lanczos.rs`, shared with the banded
//! solver) on faer's fill-reducing sparse Cholesky factor of K + σM, and a Sturm count (the
//! inertia of the sparse LDLᵀ of K − σ′M) proving that no mode below the highest one returned
//! was missed.

use crate::eigen::solver::request_tolerance;
use crate::eigen::{
    apply_sign_rule, check_count, lanczos, lanczos::LanczosWork, lanczos::Locked, lanczos::ShiftInvert,
    shifted_twice, DenseSolver, EigenSolver, ModeRequest, Modes, SolveError, SolvedModes,
};
use crate::matrix::{CscSymmetric, System};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use nalgebra::{DMatrix, DVector};
use std::borrow::Cow;
use std::cell::RefCell;

/// Lowest modes of general sparse systems ([`System::sparse`]; dense and banded systems are
/// converted), in memory linear in the factor's size.
///
/// K + σM = LLᵀ is factored once per solve by faer's supernodal/simplicial sparse Cholesky
/// after an AMD fill-reducing ordering (σ = 0 when K is positive definite and well conditioned,
/// otherwise the dense solver's two shifts, [`shifted_twice`]). Lanczos with full
/// reorthogonalisation on (K + σM)⁻¹M finds the lowest modes in a few steps more than the modes
/// wanted, each step one forward/backward substitution and one M product. A mode counts as
/// converged when its relative inverse residual falls below [`tolerance`](Self::tolerance).
///
/// The Sturm count — the negative pivots of K − σ′M = LDLᵀ (Sylvester's law of inertia) just
/// above the highest mode found — then proves no lower mode was missed, and σ′ is returned by
/// [`lowest_with_next`](EigenSolver::lowest_with_next) as a lower bound on the next eigenvalue.
/// One start vector sees a repeated eigenvalue (a square plate's (m, n) and (n, m) modes) once:
/// when the count shows missed modes, Lanczos is rerun M-orthogonally to the modes found, which
/// finds the missing copies, and the count is repeated. Systems of up to `DENSE_MAX_DOFS` (4002) DOFs fall back to
/// [`DenseSolver`] when that fails too; larger ones report the failure.
///
/// The symbolic factorisation (ordering, elimination tree) depends only on the pattern of K and
/// M and is kept per thread between solves: an update loop pays for it once.
///
/// ```
/// use eigenfit_core::eigen::{DenseSolver, EigenSolver, SparseSolver};
/// use eigenfit_core::matrix::{CscSymmetric, System};
///
/// // A free–fixed chain of 300 unit masses on unit springs.
/// let n = 300;
/// let k = CscSymmetric::from_triplets(
///     n,
///     (0..n).flat_map(|i| {
///         let diagonal = (i, i, if i + 1 < n { 2.0 } else { 1.0 });
///         std::iter::once(diagonal).chain((i + 1 < n).then_some((i + 1, i, -1.0)))
///     }),
/// );
/// let m = CscSymmetric::from_triplets(n, (0..n).map(|i| (i, i, 1.0)));
/// let system = System::sparse(k, m)?;
/// let (modes, next) = SparseSolver::default().lowest_with_next(&system, 4)?;
/// let dense = DenseSolver.lowest(&system, 5)?;
/// for i in 0..4 {
///     assert!((modes.eigenvalues[i] / dense.eigenvalues[i] - 1.0).abs() < 1e-10);
/// }
/// assert!(next > modes.eigenvalues[3] && next <= dense.eigenvalues[4]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseSolver {
    /// Relative inverse-residual below which a mode is converged.
    pub tolerance: f64,
}

impl Default for SparseSolver {
    fn default() -> Self {
        // As the banded solver's: shapes to 1e-12, so sensitivities match the dense solver's.
        Self { tolerance: 1e-12 }
    }
}

/// Largest system handed to the dense solver when the sparse path fails.
const MAX_DENSE_FALLBACK: usize = super::DENSE_MAX_DOFS;
/// Lanczos reruns (against the modes found) allowed after the Sturm count shows a missed mode.
const MAX_RERUNS: usize = 4;

fn backend(detail: impl Into<String>) -> SolveError {
    SolveError::Backend { backend: "sparse", detail: detail.into() }
}

fn not_converged(detail: impl Into<String>) -> SolveError {
    SolveError::NotConverged { backend: "sparse", detail: detail.into() }
}

/// Reusable state of one thread's solves.
#[derive(Default)]
struct Workspace {
    /// The pattern (K ∪ M, upper triangle) `symbolic` was computed for.
    pattern: Option<(Vec<usize>, Vec<usize>)>,
    symbolic: Option<SymbolicCholesky<usize>>,
    /// Values of the Cholesky factor L of K + σM.
    llt: Vec<f64>,
    /// Values of the LDLᵀ factor of the Sturm count.
    ldlt: Vec<f64>,
    buffer: Option<MemBuffer>,
    /// The last mass matrix proven positive definite: an update loop solves one M many times.
    checked_mass: Option<CscSymmetric>,
    lanczos: LanczosWork,
    diagonal: Vec<f64>,
    /// What `llt` is the factor of, after a successful eigen-solve (cleared by any other
    /// Cholesky): Nelson's iterative solves precondition with it instead of factoring again.
    held: Option<Held>,
}

/// K and M (on the union pattern) and σ of the factor of K + σM held in [`Workspace::llt`].
struct Held {
    k: CscSymmetric,
    m: CscSymmetric,
    sigma: f64,
}

thread_local! {
    static WORKSPACE: RefCell<Workspace> = RefCell::new(Workspace::default());
}

impl Workspace {
    /// Makes `symbolic` that of `a`'s pattern (computed only when the pattern changed).
    fn prepare(&mut self, a: &CscSymmetric) -> Result<(), SolveError> {
        let same = matches!(&self.pattern, Some((c, r)) if c == a.col_ptr() && r == a.row_idx());
        if same && self.symbolic.is_some() {
            return Ok(());
        }
        self.held = None;
        let symbolic =
            a.symbolic_cholesky().map_err(|e| backend(format!("symbolic factorisation: {e:?}")))?;
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, par),
        ]);
        self.buffer =
            Some(MemBuffer::try_new(req).map_err(|_| backend("out of memory for the factorisation"))?);
        self.llt = vec![0.0; symbolic.len_val()];
        self.ldlt = Vec::new();
        self.symbolic = Some(symbolic);
        self.pattern = Some((a.col_ptr().to_vec(), a.row_idx().to_vec()));
        Ok(())
    }

    /// Factors `a` = LLᵀ into `llt`; false when `a` is not numerically positive definite or,
    /// with `well_conditioned`, when its pivots span more than 7 decades (a nearly singular K,
    /// whose inverse would drown the lowest modes in round-off).
    fn cholesky(&mut self, a: &CscSymmetric, well_conditioned: bool) -> Result<bool, SolveError> {
        self.prepare(a)?;
        self.held = None;
        let (symbolic, buffer) =
            (self.symbolic.as_ref().expect("prepared"), self.buffer.as_mut().expect("prepared"));
        let n = a.dim();
        let matrix = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx()),
            a.values(),
        );
        let ok = symbolic
            .factorize_numeric_llt(
                &mut self.llt,
                matrix,
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(buffer),
                Default::default(),
            )
            .is_ok();
        if !ok || !well_conditioned {
            return Ok(ok);
        }
        factor_diagonal(symbolic, &self.llt, &mut self.diagonal);
        let (lo, hi) = self.diagonal.iter().fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
        // The banded solver's test on the same pivots.
        Ok(lo.is_finite() && lo > 1e-7 * hi)
    }

    /// Number of eigenvalues of K φ = λ M φ below σ: the negative pivots of K − σM = LDLᵀ.
    /// `None` when a pivot vanishes (σ is an eigenvalue to round-off).
    fn count_below(
        &mut self,
        k: &CscSymmetric,
        m: &CscSymmetric,
        sigma: f64,
    ) -> Result<Option<usize>, SolveError> {
        let a = CscSymmetric::combination(1.0, k, -sigma, m);
        if !self.ldlt_factor(&a)? {
            return Ok(None);
        }
        Ok(Some(self.diagonal.iter().filter(|&&d| d < 0.0).count()))
    }

    /// Factors the symmetric (possibly indefinite) `a` = LDLᵀ into `ldlt`, without pivoting,
    /// its D in `diagonal`; false when a pivot is zero or not finite.
    fn ldlt_factor(&mut self, a: &CscSymmetric) -> Result<bool, SolveError> {
        self.prepare(a)?;
        let (symbolic, buffer) =
            (self.symbolic.as_ref().expect("prepared"), self.buffer.as_mut().expect("prepared"));
        self.ldlt.resize(symbolic.len_val(), 0.0);
        let n = a.dim();
        let matrix = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx()),
            a.values(),
        );
        let factored = symbolic.factorize_numeric_ldlt(
            &mut self.ldlt,
            matrix,
            Side::Upper,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(buffer),
            Default::default(),
        );
        if factored.is_err() {
            return Ok(false);
        }
        factor_diagonal(symbolic, &self.ldlt, &mut self.diagonal);
        Ok(self.diagonal.iter().all(|d| d.is_finite() && *d != 0.0))
    }

    /// Solves with the LDLᵀ factor held in `ldlt`, in place.
    fn ldlt_solve(&mut self, x: &mut [f64]) {
        let (symbolic, buffer) =
            (self.symbolic.as_ref().expect("factored"), self.buffer.as_mut().expect("factored"));
        let n = x.len();
        LdltRef::new(symbolic, &self.ldlt).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(buffer),
        );
    }
}

/// The diagonal of a sparse Cholesky factor's values (L's pivots for LLᵀ, D for LDLᵀ), in the
/// factor's (permuted) order — enough for a pivot range or an inertia.
fn factor_diagonal(symbolic: &SymbolicCholesky<usize>, values: &[f64], out: &mut Vec<f64>) {
    out.clear();
    match symbolic.raw() {
        // Column j of L starts with its diagonal entry (rows sorted).
        SymbolicCholeskyRaw::Simplicial(s) => out.extend(s.col_ptr()[..s.ncols()].iter().map(|&p| values[p])),
        // Supernode s: a column-major (pattern + columns) × columns block, its top square holding
        // the diagonal.
        SymbolicCholeskyRaw::Supernodal(s) => {
            for (sn, (&begin, &end)) in s.supernode_begin().iter().zip(s.supernode_end()).enumerate() {
                let cols = end - begin;
                let block = &values[s.col_ptr_for_val()[sn]..s.col_ptr_for_val()[sn + 1]];
                let rows = block.len() / cols;
                out.extend((0..cols).map(|c| block[c * rows + c]));
            }
        }
    }
}

/// The Cholesky factor held in the workspace, as Lanczos' operator (K + σM)⁻¹.
struct FactorSolve<'a> {
    symbolic: &'a SymbolicCholesky<usize>,
    values: &'a [f64],
    buffer: &'a mut MemBuffer,
}

impl ShiftInvert for FactorSolve<'_> {
    fn solve_in_place(&mut self, x: &mut [f64]) {
        let n = x.len();
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        LltRef::new(self.symbolic, self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(self.buffer),
        );
    }
}

/// Bisection steps of [`SparseSolver::shift_below_lowest`]: the shift lands within 2⁻¹² of the
/// upper bound of λ₁ below it, so the inverted spectrum's lowest gaps are of order one.
const SHIFT_BISECTIONS: usize = 12;

/// Converged modes of one shift: eigenvalues ascending, vectors column-major n×count.
struct Found {
    eigenvalues: Vec<f64>,
    vectors: Vec<f64>,
}

impl EigenSolver for SparseSolver {
    fn name(&self) -> &'static str {
        "sparse"
    }

    /// The next eigenvalue's bound is the Sturm count's shift. Eigenvalues only are iterated
    /// less far (`request_tolerance`).
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        let tolerance = request_tolerance(request, self.tolerance);
        let (modes, next) =
            self.solve_with_tolerance(system, request.count, tolerance).map_err(|e| e.located(system))?;
        Ok(SolvedModes::answering(request, modes, next))
    }
}

impl SparseSolver {
    fn solve_with_tolerance(
        &self,
        system: &System,
        count: usize,
        tolerance: f64,
    ) -> Result<(Modes, f64), SolveError> {
        check_count(system, count)?;
        let n = system.dofs();
        // More than half the spectrum: Lanczos has no advantage, the dense solver is exact.
        if 2 * count > n && n <= MAX_DENSE_FALLBACK {
            return DenseSolver.lowest_with_next(system, count);
        }
        // A condensed system is solved on its full sparse pencil (M semi-definite): its massed
        // DOFs' M_mm is checked here instead of the full M's Cholesky factor.
        let condensed = system.condensed_pencil();
        if let Some(c) = condensed {
            let checked = WORKSPACE.with(|ws| ws.borrow().checked_mass.as_ref() == Some(c.restricted_mass()));
            if !checked {
                if system.mass_failure_dof().is_some() {
                    return Err(SolveError::MassNotPositiveDefinite { detail: None, dof: None });
                }
                WORKSPACE.with(|ws| ws.borrow_mut().checked_mass = Some(c.restricted_mass().clone()));
            }
        }
        let pair = match condensed {
            Some(c) => (Cow::Borrowed(c.full_stiffness()), Cow::Borrowed(c.full_mass())),
            None => csc_pair(system),
        };
        let (k, m): (&CscSymmetric, &CscSymmetric) = (&pair.0, &pair.1);
        let found = WORKSPACE.with(|ws| {
            let ws = &mut *ws.try_borrow_mut().map_err(|_| backend("workspace in use (re-entrant solve)"))?;
            Self { tolerance }.solve_sparse(k, m, count, condensed.map(|c| c.kept()), ws)
        });
        match found {
            Ok(Some(found)) => Ok(found),
            Ok(None) | Err(SolveError::Backend { .. } | SolveError::NotConverged { .. })
                if n <= MAX_DENSE_FALLBACK =>
            {
                DenseSolver.lowest_with_next(system, count)
            }
            Ok(None) => Err(not_converged(
                "a mode was missed by Lanczos (Sturm count) and the system is too large for the dense solver",
            )),
            Err(e) => Err(e),
        }
    }

    /// The lowest modes and the Sturm bound, or `None` when the count still shows a missed mode.
    fn solve_sparse(
        &self,
        k: &CscSymmetric,
        m: &CscSymmetric,
        count: usize,
        kept: Option<&[usize]>,
        ws: &mut Workspace,
    ) -> Result<Option<(Modes, f64)>, SolveError> {
        let n = k.dim();
        // A common pattern for K, M and every K + σM: one symbolic factorisation serves all.
        let pattern = CscSymmetric::combination(0.0, k, 0.0, m);
        let k = &with_pattern(&pattern, k);
        let m = &with_pattern(&pattern, m);
        // The full pencil of a condensed system: M is semi-definite by design (its massed part
        // was checked by the caller). Lanczos in the M inner product sees only the massed
        // entries of its vectors — (K + σM)⁻¹M and the M products read nothing else, and their
        // massed parts are the condensed problem's — so the shapes kept are those entries.
        if kept.is_none() && ws.checked_mass.as_ref() != Some(m) {
            if !ws.cholesky(m, false)? {
                return Err(SolveError::MassNotPositiveDefinite { detail: None, dof: None });
            }
            ws.checked_mass = Some(m.clone());
        }
        let (sigma, mut found) = if ws.cholesky(k, true)? {
            match self.iterate(m, 0.0, count, None, ws) {
                Ok(found) => (0.0, found),
                // A spectrum spread far above zero (λᵢ = 1001, 1002, …): inverted at zero its
                // relative gaps are 1e-3 and Lanczos runs out of steps. Shifted to just below
                // the lowest eigenvalue they become 1, 2, 3, …
                Err(e @ SolveError::NotConverged { .. }) => match self.shift_below_lowest(k, m, ws)? {
                    Some(s) => (-s, self.iterate(m, -s, count, None, ws)?),
                    None => return Err(e),
                },
                Err(e) => return Err(e),
            }
        } else {
            // Rigid-body modes or a nearly singular K: the dense solver's two shifts.
            let scale = k.diagonal_max() / m.diagonal_max();
            let mut last_sigma = 0.0;
            let modes = shifted_twice(scale, |sigma| {
                let shifted = CscSymmetric::combination(1.0, k, sigma, m);
                if !ws.cholesky(&shifted, false)? {
                    return Err(backend("K + σM is not positive definite: K has negative stiffness"));
                }
                last_sigma = sigma;
                let f = self.iterate(m, sigma, count, None, ws)?;
                Ok(to_modes(&f, n, count))
            })?;
            let f = Found {
                eigenvalues: modes.eigenvalues.iter().copied().collect(),
                vectors: modes.shapes.as_slice().to_vec(),
            };
            (last_sigma, f)
        };
        let floor = 1e-11 * k.diagonal_max() / m.diagonal_max();
        // `found` holds every mode found so far (M-orthonormal, ascending), possibly more than
        // `count` after a rerun.
        for _ in 0..=MAX_RERUNS {
            let top = found.eigenvalues[count - 1];
            let mut bound = top + (1e-6 * top.abs()).max(floor);
            let mut below = ws.count_below(k, m, bound)?;
            if below.is_none() {
                // σ′ hit an eigenvalue to round-off: step a little further.
                bound = top + 2.0 * (1e-6 * top.abs()).max(floor);
                below = ws.count_below(k, m, bound)?;
            }
            let Some(below) = below else { return Ok(None) };
            let known = found.eigenvalues.iter().filter(|&&l| l < bound).count();
            if below == known {
                // Every eigenvalue below σ′ is among those found. A repeated eigenvalue cut in
                // two by `count` puts its other copy below σ′ too: that copy is the next one.
                let next = if known > count { found.eigenvalues[count] } else { bound };
                let modes = finish(restricted(to_modes(&found, n, count), kept))?;
                if kept.is_none() {
                    // A condensed system's factor is of its full pencil, not of the system.
                    ws.held = Some(Held { k: k.clone(), m: m.clone(), sigma });
                }
                return Ok(Some((modes, next)));
            }
            if below < known || found.eigenvalues.len() >= n {
                return Ok(None);
            }
            // The missed modes may all be copies of the highest one found (a cluster at `top`:
            // K = cI has one eigenvalue of multiplicity n). A count just below the cluster says
            // so; then the lowest `count` are found (to the count's margin, 1e-6 relative) and
            // the copies, up to n of them, are not chased: the next eigenvalue is one of them.
            let low = top - (1e-6 * top.abs()).max(floor);
            let known_low = found.eigenvalues.iter().filter(|&&l| l < low).count();
            if known_low < count && ws.count_below(k, m, low)? == Some(known_low) {
                let modes = finish(restricted(to_modes(&found, n, count), kept))?;
                if kept.is_none() {
                    // A condensed system's factor is of its full pencil, not of the system.
                    ws.held = Some(Held { k: k.clone(), m: m.clone(), sigma });
                }
                return Ok(Some((modes, found.eigenvalues.get(count).copied().unwrap_or(top))));
            }
            // Missed modes: rerun M-orthogonally to the modes found, on the same factor of
            // K + σM (the count's LDLᵀ has its own values).
            let mut m_vectors = vec![0.0; found.vectors.len()];
            for (v, mv) in found.vectors.chunks_exact(n).zip(m_vectors.chunks_exact_mut(n)) {
                m.mul_add(1.0, v, mv);
            }
            let locked = Locked { vectors: &found.vectors, m_vectors: &m_vectors };
            let more = (below - known).min(n - found.eigenvalues.len());
            let extra = self.iterate(m, sigma, more, Some(locked), ws)?;
            found = merge(found, extra, n);
        }
        Ok(None)
    }

    /// A shift s below the lowest eigenvalue λ₁ and close to it, with K − sM factored in the
    /// workspace; `None` (and K factored again) when none better than zero is found. K is
    /// positive definite (s = 0 works) and λ₁ ≤ minᵢ Kᵢᵢ/Mᵢᵢ (the Rayleigh quotient of a unit
    /// vector): bisection on whether K − sM has a Cholesky factor brackets λ₁ within 2⁻¹² of that
    /// bound — no eigenvalue lies below s, so none is missed, and the Sturm count that follows
    /// checks the modes found as for any shift.
    fn shift_below_lowest(
        &self,
        k: &CscSymmetric,
        m: &CscSymmetric,
        ws: &mut Workspace,
    ) -> Result<Option<f64>, SolveError> {
        let upper = (0..k.dim())
            .filter(|&i| m.get(i, i) > 0.0)
            .map(|i| k.get(i, i) / m.get(i, i))
            .fold(f64::INFINITY, f64::min);
        if !(upper.is_finite() && upper > 0.0) {
            return Ok(None);
        }
        let (mut lo, mut hi) = (0.0, upper);
        for _ in 0..SHIFT_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if ws.cholesky(&CscSymmetric::combination(1.0, k, -mid, m), false)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if lo == 0.0 || !ws.cholesky(&CscSymmetric::combination(1.0, k, -lo, m), true)? {
            // Put back the factor the caller's later steps assume.
            ws.cholesky(k, true)?;
            return Ok(None);
        }
        Ok(Some(lo))
    }

    /// The `count` lowest modes (outside the locked ones) from the factor of K + σM held in
    /// the workspace.
    fn iterate(
        &self,
        m: &CscSymmetric,
        sigma: f64,
        count: usize,
        locked: Option<Locked<'_>>,
        ws: &mut Workspace,
    ) -> Result<Found, SolveError> {
        let n = m.dim();
        let mut op = FactorSolve {
            symbolic: ws.symbolic.as_ref().expect("factored"),
            values: &ws.llt,
            buffer: ws.buffer.as_mut().expect("factored"),
        };
        let ritz = lanczos::largest(&mut op, m, count, self.tolerance, locked, &mut ws.lanczos)
            .ok_or_else(|| {
                not_converged(
                    "Lanczos did not reach its tolerance within its step limit (eigenvalues too closely spaced at \
                     the modes asked for)",
                )
            })?;
        let eigenvalues: Vec<f64> = ritz.mu.iter().map(|&mu| 1.0 / mu - sigma).collect();
        if !eigenvalues.windows(2).all(|w| w[1] >= w[0] - 1e-12 * w[0].abs()) {
            return Err(backend("Lanczos returned eigenvalues out of order"));
        }
        Ok(Found { eigenvalues, vectors: ritz.vectors[..count * n].to_vec() })
    }
}

/// (K, M) of `system` as general sparse matrices: borrowed when stored so, converted from a
/// band or dense storage otherwise.
fn csc_pair(system: &System) -> (Cow<'_, CscSymmetric>, Cow<'_, CscSymmetric>) {
    match (system.sparse_pair(), system.band()) {
        (Some((k, m)), _) => (Cow::Borrowed(k), Cow::Borrowed(m)),
        (None, Some((k, m))) => {
            (Cow::Owned(CscSymmetric::from_banded(k)), Cow::Owned(CscSymmetric::from_banded(m)))
        }
        (None, None) => (
            Cow::Owned(CscSymmetric::from_dense(system.stiffness())),
            Cow::Owned(CscSymmetric::from_dense(system.mass())),
        ),
    }
}

/// Solves (K − σM) xⱼ = bⱼ for every right-hand side in `rhs`, in place, with DOF `pinned`
/// held at zero (its row and column of K − σM replaced by the identity's, its entry of every bⱼ
/// zeroed): the system of Nelson's method, non-singular when σ is a simple eigenvalue and the
/// eigenvector is not zero at `pinned`.
///
/// One sparse LDLᵀ (no pivoting; K − σM is indefinite) of K − σM on the pattern of K ∪ M — the
/// pattern the eigen-solves factor, so the thread's symbolic factorisation (AMD ordering,
/// elimination tree) is reused — and per right-hand side one solve and one step of iterative
/// refinement against the matrix itself. Banded and dense systems are converted. False when a
/// pivot vanishes (σ not simple, or `pinned` a node of the mode).
pub(crate) fn solve_pinned(
    system: &System,
    sigma: f64,
    pinned: usize,
    rhs: &mut [Vec<f64>],
) -> Result<bool, SolveError> {
    // A condensed system: the full K − σM with [b; 0], the massed DOF pinned — its massed part
    // is the condensed solution exactly (block elimination of the non-singular K_ss; pinning a
    // massed DOF leaves K_ss whole).
    if let Some(c) = system.condensed_pencil() {
        rhs.iter_mut().for_each(|b| b[pinned] = 0.0);
        let mut full: Vec<Vec<f64>> = rhs.iter().map(|b| c.lift(b)).collect();
        let pair = (Cow::Borrowed(c.full_stiffness()), Cow::Borrowed(c.full_mass()));
        if !solve_pinned_pair(pair, sigma, c.kept()[pinned], &mut full)? {
            return Ok(false);
        }
        for (b, f) in rhs.iter_mut().zip(&full) {
            b.copy_from_slice(&c.restrict(f));
        }
        return Ok(true);
    }
    solve_pinned_pair(csc_pair(system), sigma, pinned, rhs)
}

/// [`solve_pinned`] on (K, M) given as sparse matrices.
fn solve_pinned_pair(
    pair: (Cow<'_, CscSymmetric>, Cow<'_, CscSymmetric>),
    sigma: f64,
    pinned: usize,
    rhs: &mut [Vec<f64>],
) -> Result<bool, SolveError> {
    let pattern = CscSymmetric::combination(0.0, &pair.0, 0.0, &pair.1);
    let mut a = CscSymmetric::combination(
        1.0,
        &with_pattern(&pattern, &pair.0),
        -sigma,
        &with_pattern(&pattern, &pair.1),
    );
    pin(&mut a, pinned);
    WORKSPACE.with(|ws| {
        let ws = &mut *ws.try_borrow_mut().map_err(|_| backend("workspace in use (re-entrant solve)"))?;
        if !ws.ldlt_factor(&a)? {
            return Ok(false);
        }
        let n = a.dim();
        let mut residual = vec![0.0; n];
        for b in rhs.iter_mut() {
            b[pinned] = 0.0;
            residual.copy_from_slice(b);
            ws.ldlt_solve(b);
            // r = b − A x, then x += A⁻¹ r: recovers the digits an unpivoted LDLᵀ of an
            // indefinite matrix may lose.
            a.mul_add(-1.0, b, &mut residual);
            ws.ldlt_solve(&mut residual);
            b.iter_mut().zip(&residual).for_each(|(x, dx)| *x += dx);
        }
        Ok(true)
    })
}

/// Runs `f` on the factor of K + σM that the thread's last sparse eigen-solve left behind, when
/// that solve was of `system` (same K and M); `None` otherwise (another system solved since, or
/// a banded or dense solver used). `f` gets K and M on the factor's pattern, σ, and the solve
/// (K + σM)⁻¹ applied in place to an n × c column-major block (one pass over the factor for
/// all c columns).
pub(crate) fn with_held_factor<R>(
    system: &System,
    f: impl FnOnce(&CscSymmetric, &CscSymmetric, f64, &mut dyn FnMut(&mut [f64], usize)) -> R,
) -> Result<Option<R>, SolveError> {
    if system.condensed_pencil().is_some() {
        // Solved on its full pencil: no factor of the system's own K + σM is held.
        return Ok(None);
    }
    let pair = csc_pair(system);
    let pattern = CscSymmetric::combination(0.0, &pair.0, 0.0, &pair.1);
    WORKSPACE.with(|ws| {
        let ws = &mut *ws.try_borrow_mut().map_err(|_| backend("workspace in use (re-entrant solve)"))?;
        let Workspace { held: Some(held), symbolic: Some(symbolic), llt, .. } = ws else { return Ok(None) };
        if !held.k.same_pattern(&pattern)
            || held.k != with_pattern(&pattern, &pair.0)
            || held.m != with_pattern(&pattern, &pair.1)
        {
            return Ok(None);
        }
        let mut scratch: Option<(usize, MemBuffer)> = None;
        let mut failed = false;
        let mut solve = |x: &mut [f64], cols: usize| {
            let n = symbolic.nrows();
            if scratch.as_ref().is_none_or(|(c, _)| *c < cols) {
                match MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(cols, Par::Seq)) {
                    Ok(b) => scratch = Some((cols, b)),
                    Err(_) => {
                        failed = true;
                        x.fill(f64::NAN);
                        return;
                    }
                }
            }
            let (_, buffer) = scratch.as_mut().expect("allocated");
            LltRef::new(symbolic, llt).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(x, n, cols),
                Par::Seq,
                MemStack::new(buffer),
            );
        };
        let out = f(&held.k, &held.m, held.sigma, &mut solve);
        if failed {
            return Err(backend("out of memory for a block solve"));
        }
        Ok(Some(out))
    })
}

/// Replaces row and column `j` of `a` by the identity's (the pattern kept).
fn pin(a: &mut CscSymmetric, j: usize) {
    let n = a.dim();
    let col_ptr = a.col_ptr().to_vec();
    let rows = a.row_idx().to_vec();
    let values = a.values_mut();
    for c in 0..n {
        for p in col_ptr[c]..col_ptr[c + 1] {
            let r = rows[p];
            if r == j || c == j {
                values[p] = if r == c { 1.0 } else { 0.0 };
            }
        }
    }
}

/// `a` on the (larger) pattern `pattern`: zeros where `a` stores nothing.
fn with_pattern(pattern: &CscSymmetric, a: &CscSymmetric) -> CscSymmetric {
    if pattern.same_pattern(a) {
        return a.clone();
    }
    let mut out = pattern.clone();
    out.values_mut().fill(0.0);
    let fits = out.add_scaled_within(1.0, a);
    debug_assert!(fits, "the union pattern holds every entry");
    out
}

/// Two sets of modes (M-orthogonal to each other) as one, ascending.
fn merge(a: Found, b: Found, n: usize) -> Found {
    let mut all: Vec<(f64, &[f64])> = a
        .eigenvalues
        .iter()
        .copied()
        .zip(a.vectors.chunks_exact(n))
        .chain(b.eigenvalues.iter().copied().zip(b.vectors.chunks_exact(n)))
        .collect();
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    Found {
        eigenvalues: all.iter().map(|x| x.0).collect(),
        vectors: all.iter().flat_map(|x| x.1.iter().copied()).collect(),
    }
}

/// The lowest `count` modes of `found`.
fn to_modes(found: &Found, n: usize, count: usize) -> Modes {
    Modes {
        // After a rerun `found` may hold more modes than asked for (10⁶-DOF plate: 11 of 10).
        eigenvalues: DVector::from_column_slice(&found.eigenvalues[..count]),
        shapes: DMatrix::from_column_slice(n, count, &found.vectors[..n * count]),
    }
}

/// `modes` with their shapes' rows `kept` only (all rows for `None`): a condensed system's
/// modes from its full pencil's.
fn restricted(modes: Modes, kept: Option<&[usize]>) -> Modes {
    match kept {
        None => modes,
        Some(kept) => Modes {
            shapes: DMatrix::from_fn(kept.len(), modes.shapes.ncols(), |i, c| modes.shapes[(kept[i], c)]),
            eigenvalues: modes.eigenvalues,
        },
    }
}

/// Rejects non-finite results and applies the sign rule.
fn finish(mut modes: Modes) -> Result<Modes, SolveError> {
    if modes.eigenvalues.iter().chain(modes.shapes.iter()).any(|v| !v.is_finite()) {
        return Err(backend("non-finite result"));
    }
    apply_sign_rule(&mut modes.shapes);
    Ok(modes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
    };
    use faer::sparse::linalg::SupernodalThreshold;

    /// A rectangular grid of masses with springs to neighbours and to ground: a 2-D pattern
    /// that no band ordering keeps narrow. `square` makes every (i, j)/(j, i) mode pair repeat.
    fn grid(nx: usize, ny: usize, square: bool) -> System {
        let id = |i: usize, j: usize| i * ny + j;
        let n = nx * ny;
        let mut k = Vec::new();
        let (kx, ky) = if square { (1.0, 1.0) } else { (1.0, 1.37) };
        for i in 0..nx {
            for j in 0..ny {
                let mut diag = 0.0;
                // Fixed edges all round: ground springs at the border.
                if i == 0 || i + 1 == nx {
                    diag += kx;
                }
                if j == 0 || j + 1 == ny {
                    diag += ky;
                }
                if i + 1 < nx {
                    k.push((id(i, j), id(i + 1, j), -kx));
                    diag += kx;
                }
                if i > 0 {
                    diag += kx;
                }
                if j + 1 < ny {
                    k.push((id(i, j), id(i, j + 1), -ky));
                    diag += ky;
                }
                if j > 0 {
                    diag += ky;
                }
                k.push((id(i, j), id(i, j), diag));
            }
        }
        let m = (0..n).map(|i| (i, i, 1.0 + 0.1 * ((i * 7919) % 13) as f64 * if square { 0.0 } else { 1.0 }));
        System::sparse(CscSymmetric::from_triplets(n, k), CscSymmetric::from_triplets(n, m)).unwrap()
    }

    fn check_against_dense(system: &System, count: usize) {
        let (modes, next) = SparseSolver::default().lowest_with_next(system, count).unwrap();
        assert_eq!((modes.eigenvalues.len(), modes.shapes.ncols()), (count, count));
        let dense = DenseSolver.lowest(system, count + 1).unwrap();
        for i in 0..count {
            let rel = (modes.eigenvalues[i] / dense.eigenvalues[i] - 1.0).abs();
            assert!(rel < 1e-10, "mode {i}: {} vs {}", modes.eigenvalues[i], dense.eigenvalues[i]);
        }
        assert!(next > modes.eigenvalues[count - 1] && next <= dense.eigenvalues[count]);
        // Mass-normalised shapes.
        let (k, m) = (system.stiffness(), system.mass());
        let phi = &modes.shapes;
        let mtm = phi.transpose() * m * phi;
        assert!((mtm - DMatrix::identity(count, count)).amax() < 1e-9);
        let ktk = phi.transpose() * k * phi;
        assert!(
            (ktk - DMatrix::from_diagonal(&modes.eigenvalues)).amax() < 1e-9 * modes.eigenvalues[count - 1]
        );
    }

    #[test]
    fn grid_modes_match_the_dense_solver() {
        check_against_dense(&grid(23, 19, false), 10);
    }

    #[test]
    fn repeated_eigenvalues_of_a_square_grid_are_all_found() {
        // Modes (1,2) and (2,1) of a square coincide: one Lanczos run sees one of each pair, the
        // Sturm count sees both, the rerun against the found modes supplies the other.
        check_against_dense(&grid(24, 24, true), 8);
    }

    #[test]
    fn a_count_that_splits_a_repeated_pair_reports_the_other_copy_as_next() {
        // Square grid: λ₂ = λ₃ exactly (modes (1,2) and (2,1)); two modes asked for.
        let system = grid(20, 20, true);
        let (modes, next) = SparseSolver::default().lowest_with_next(&system, 2).unwrap();
        let dense = DenseSolver.lowest(&system, 3).unwrap();
        assert!((dense.eigenvalues[2] / dense.eigenvalues[1] - 1.0).abs() < 1e-12, "the pair is repeated");
        for i in 0..2 {
            assert!((modes.eigenvalues[i] / dense.eigenvalues[i] - 1.0).abs() < 1e-10);
        }
        assert!((next / dense.eigenvalues[2] - 1.0).abs() < 1e-10, "next {next}");
    }

    #[test]
    fn rigid_body_modes_are_found_through_a_shift() {
        // A free–free chain: one zero eigenvalue, K singular.
        let n = 150;
        let k = CscSymmetric::from_triplets(
            n,
            (0..n).flat_map(|i| {
                let d = if i == 0 || i + 1 == n { 1.0 } else { 2.0 };
                std::iter::once((i, i, d)).chain((i + 1 < n).then_some((i, i + 1, -1.0)))
            }),
        );
        let m = CscSymmetric::from_triplets(n, (0..n).map(|i| (i, i, 1.0)));
        let system = System::sparse(k, m).unwrap();
        let modes = SparseSolver::default().lowest(&system, 3).unwrap();
        let dense = DenseSolver.lowest(&system, 3).unwrap();
        assert!(modes.eigenvalues[0].abs() < 1e-9);
        for i in 1..3 {
            assert!((modes.eigenvalues[i] / dense.eigenvalues[i] - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn sturm_count_agrees_with_the_dense_spectrum_in_both_factor_layouts() {
        let system = grid(17, 13, false);
        let (k, m) = system.sparse_pair().unwrap();
        let all = DenseSolver.lowest(&system, system.dofs()).unwrap().eigenvalues;
        for threshold in [SupernodalThreshold::FORCE_SIMPLICIAL, SupernodalThreshold::FORCE_SUPERNODAL] {
            let pattern = CscSymmetric::combination(0.0, k, 0.0, m);
            let (k, m) = (with_pattern(&pattern, k), with_pattern(&pattern, m));
            let mut ws = Workspace::default();
            let n = k.dim();
            let symbolic = factorize_symbolic_cholesky(
                SymbolicSparseColMatRef::new_checked(n, n, k.col_ptr(), None, k.row_idx()),
                Side::Upper,
                SymmetricOrdering::Amd,
                CholeskySymbolicParams { supernodal_flop_ratio_threshold: threshold, ..Default::default() },
            )
            .unwrap();
            ws.buffer = Some(MemBuffer::new(StackReq::any_of(&[
                symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
                symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            ])));
            ws.llt = vec![0.0; symbolic.len_val()];
            ws.symbolic = Some(symbolic);
            ws.pattern = Some((k.col_ptr().to_vec(), k.row_idx().to_vec()));
            for (idx, sigma) in
                [(0, 0.5 * all[0]), (10, 0.5 * (all[9] + all[10])), (40, 0.5 * (all[39] + all[40]))]
            {
                assert_eq!(ws.count_below(&k, &m, sigma).unwrap(), Some(idx), "{threshold:?} at σ = {sigma}");
            }
        }
    }
}
