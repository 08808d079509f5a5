//! Modes at speed: the quadratic eigenproblem (λ²M + λ(C + ΩG) + K)x = 0 through its 2n
//! state-space form, solved densely with faer's general (non-symmetric) eigendecomposition, which
//! also returns the left eigenvectors the sensitivities need.

use crate::band::Band;
use crate::error::RotorDynError;
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors};
use faer::{c64, Mat, MatRef, Par};

/// Whirl direction of a mode, from the orbits of its nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Whirl {
    /// The orbit turns with the rotor.
    Forward,
    /// The orbit turns against the rotor.
    Backward,
    /// Straight-line (or nearly so) motion: no direction.
    Mixed,
}

impl Whirl {
    /// The name used in tables, JSON and CSV files.
    pub fn name(self) -> &'static str {
        match self {
            Whirl::Forward => "forward",
            Whirl::Backward => "backward",
            Whirl::Mixed => "mixed",
        }
    }
}

/// Reports give a whirl by its name.
impl serde::Serialize for Whirl {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// One damped mode at one speed.
#[derive(Debug, Clone)]
pub struct Mode {
    /// The eigenvalue λ = −ζωn + iωd (rad/s), Im λ > 0.
    pub eigenvalue: c64,
    /// Right eigenvector of the quadratic problem (n DOFs).
    pub right: Vec<c64>,
    /// Left eigenvector of the quadratic problem: yᴴ(λ²M + λD + K) = 0.
    pub left: Vec<c64>,
    /// Whirl direction.
    pub whirl: Whirl,
}

impl Mode {
    /// Damped natural frequency ωd in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.eigenvalue.im / (2.0 * std::f64::consts::PI)
    }
    /// Undamped natural frequency |λ| in Hz.
    pub fn natural_frequency_hz(&self) -> f64 {
        self.eigenvalue.norm() / (2.0 * std::f64::consts::PI)
    }
    /// Damping ratio ζ = −Re λ / |λ|.
    pub fn damping_ratio(&self) -> f64 {
        -self.eigenvalue.re / self.eigenvalue.norm()
    }
    /// Logarithmic decrement 2πζ/√(1−ζ²) (as ROSS computes it).
    pub fn log_dec(&self) -> f64 {
        let z = self.damping_ratio();
        2.0 * std::f64::consts::PI * z / (1.0 - z * z).sqrt()
    }
}

/// Rows of the state vector that form one node's translations (x, y): whirl is read from them.
pub type TranslationPairs = Vec<(usize, usize)>;

/// Solves the damped gyroscopic problem for its oscillating modes, sorted by damped frequency.
///
/// `d` is the full velocity matrix C + ΩG. Real eigenvalues (over-damped motion) are left out:
/// they have no frequency. `pairs` lists each node's (x, y) DOFs for the whirl direction.
pub fn solve(
    m: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    k: MatRef<'_, f64>,
    pairs: &[(usize, usize)],
    with_left: bool,
) -> Result<Vec<Mode>, RotorDynError> {
    let n = m.nrows();
    // A = [[0, I], [−M⁻¹K, −M⁻¹D]] as ROSS builds it.
    let llt = m
        .llt(faer::Side::Lower)
        .map_err(|_| RotorDynError::Model("the mass matrix is not positive definite".into()))?;
    let minv_k = solve_llt(&llt, k);
    let minv_d = solve_llt(&llt, d);
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    #[allow(clippy::needless_range_loop)]
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -minv_k[(i, j)];
            a[(n + i, n + j)] = -minv_d[(i, j)];
        }
    }
    // Balance first (as LAPACK's dgeev does): the state matrix mixes 1 with K/M entries of
    // 10⁶…10¹², and without balancing the low eigenvalues lose about six digits.
    let scale = balance(&mut a);
    let (values, mut right, mut left) = eigen_real(a.as_ref(), with_left)?;
    for j in 0..2 * n {
        for i in 0..2 * n {
            right[(i, j)] *= scale[i];
            if let Some(l) = left.as_mut() {
                l[(i, j)] /= scale[i];
            }
        }
    }
    let mut modes = Vec::new();
    for (j, &lambda) in values.iter().enumerate() {
        // Keep the member of each conjugate pair with positive damped frequency. A tolerance
        // relative to |λ| keeps a real eigenvalue's round-off imaginary part out.
        if !crate::shift_invert::oscillates(lambda) {
            continue;
        }
        let x: Vec<c64> = (0..n).map(|i| right[(i, j)]).collect();
        let y: Vec<c64> = match &left {
            // State-space left vector w = [w1; w2]: the quadratic one is y = M⁻¹ w2 (M symmetric).
            Some(l) => {
                let mut w2 = Mat::<c64>::zeros(n, 1);
                for i in 0..n {
                    w2[(i, 0)] = l[(n + i, j)];
                }
                let yy = solve_llt_c(&llt, w2.as_ref());
                (0..n).map(|i| yy[(i, 0)]).collect()
            }
            None => Vec::new(),
        };
        let whirl = whirl_of(&x, pairs);
        modes.push(Mode { eigenvalue: lambda, right: x, left: y, whirl });
    }
    modes.sort_by(|a, b| a.eigenvalue.im.total_cmp(&b.eigenvalue.im));
    Ok(modes)
}

/// Models up to this many DOFs are solved densely; larger ones by shift-invert Arnoldi.
pub const DENSE_DOFS: usize = 160;

/// The `count` lowest oscillating modes: dense for small models, shift-invert Arnoldi on the
/// banded matrices for large ones (falling back to dense when K is singular). With `with_left`
/// also the left vectors, for sensitivities: on the shift-invert route from the transposed
/// problem — if (λ²Mᵀ + λDᵀ + Kᵀ)z = 0 then y = z̄ satisfies yᴴ(λ²M + λD + K) = 0 — matched to
/// the problem's eigenpairs by eigenvalue (a dense solve of the compressor example's 1464
/// states takes seconds; this, milliseconds).
///
/// Rigid-body modes ([`rigid_body`]: a rotor without bearings, whose eigenvalues are zero to
/// round-off) are left out: they are no vibration, no curve of a Campbell diagram and never a
/// critical speed ([`solve_lowest_elastic`] says how many).
pub fn solve_lowest(
    m: &Mat<f64>,
    d: &Mat<f64>,
    k: &Mat<f64>,
    pairs: &[(usize, usize)],
    count: usize,
    with_left: bool,
) -> Result<Vec<Mode>, RotorDynError> {
    let [m, d, k] = [m, d, k].map(Band::from_dense);
    solve_lowest_elastic(Quadratic { m: &m, d: &d, k: &k }, pairs, count, with_left).map(|(modes, _)| modes)
}

/// The quadratic problem (λ²M + λD + K)x = 0 in band storage.
#[derive(Debug, Clone, Copy)]
pub struct Quadratic<'a> {
    /// Mass M.
    pub m: &'a Band,
    /// Velocity matrix D = C + ΩG.
    pub d: &'a Band,
    /// Stiffness K.
    pub k: &'a Band,
}

/// [`solve_lowest`] on band matrices, and the number of rigid-body modes left out below the
/// modes returned.
pub fn solve_lowest_elastic(
    q: Quadratic<'_>,
    pairs: &[(usize, usize)],
    count: usize,
    with_left: bool,
) -> Result<(Vec<Mode>, usize), RotorDynError> {
    let n = q.m.dim();
    let mut ask = count;
    loop {
        let shift_invert = if n > DENSE_DOFS { lowest_shift_invert(q, pairs, ask, with_left) } else { None };
        // The dense route returns every oscillating mode: nothing more to ask for.
        let (all, complete) = match shift_invert {
            Some(modes) => (modes, false),
            None => {
                let [m, d, k] = [q.m, q.d, q.k].map(Band::to_dense);
                (solve(m.as_ref(), d.as_ref(), k.as_ref(), pairs, with_left)?, true)
            }
        };
        let flags = rigid_body(&all, q.m, q.k);
        let dropped = flags.as_ref().map_or(0, |f| f.iter().filter(|&&r| r).count());
        let enough = flags.is_some() && all.len() - dropped >= count;
        if enough || complete || ask >= 2 * n {
            let flags = flags.unwrap_or_else(|| vec![false; all.len()]);
            let mut elastic: Vec<Mode> =
                all.into_iter().zip(flags).filter(|(_, rigid)| !rigid).map(|(mode, _)| mode).collect();
            elastic.truncate(count);
            return Ok((elastic, dropped));
        }
        ask = (ask + dropped.max(4) + 4).min(2 * n);
    }
}

/// How far below the lowest resolved |λ|² (one above round-off) a mode's |λ|² must lie to be a
/// rigid-body mode (see [`rigid_body`]).
pub const RIGID_BODY_GAP: f64 = 1e6;

/// How many times ε ‖K‖∞ ‖x‖² / |xᴴMx| a mode's |λ|² may reach and still be zero to round-off.
/// Generous because a free rotor's zero eigenvalues are double (a rigid motion and its velocity,
/// a Jordan block of the state matrix): round-off δ moves them by √δ, so |λ|² lands at about
/// ε times the state matrix's scale, which the mass-weighted K norm of the shape understates by
/// up to the ratio of the largest to the smallest inertia.
pub const RIGID_BODY_ROUNDOFF: f64 = 1e3;

/// Which of `modes` (of M λ² + D λ + K, ascending) are rigid-body modes, by a scale-free test:
/// |λ|² zero to round-off — |λ|² |xᴴMx| ≤ [`RIGID_BODY_ROUNDOFF`] · ε ‖K‖∞ ‖x‖² — and at least
/// [`RIGID_BODY_GAP`] below the lowest mode that is not (a rotor's elastic modes are within a
/// few decades of each other; a rigid-body zero lies ten or more below them). `None` when no
/// mode of `modes` is resolved from zero: the gap cannot be judged.
pub fn rigid_body(modes: &[Mode], m: &Band, k: &Band) -> Option<Vec<bool>> {
    let k_norm = k.norm_inf();
    let zero: Vec<bool> = modes
        .iter()
        .map(|mode| {
            let x = &mode.right;
            let x2: f64 = x.iter().map(|v| v.norm_sqr()).sum();
            let xmx = m.quadratic_form(x);
            mode.eigenvalue.norm_sqr() * xmx.norm() <= RIGID_BODY_ROUNDOFF * f64::EPSILON * k_norm * x2
        })
        .collect();
    let resolved = modes
        .iter()
        .zip(&zero)
        .filter(|(_, &z)| !z)
        .map(|(mode, _)| mode.eigenvalue.norm_sqr())
        .fold(f64::INFINITY, f64::min);
    if !resolved.is_finite() {
        return None;
    }
    Some(
        modes
            .iter()
            .zip(zero)
            .map(|(mode, z)| z && mode.eigenvalue.norm_sqr() * RIGID_BODY_GAP <= resolved)
            .collect(),
    )
}

/// The shift-invert route; `None` (solve densely) when it fails or finds too few modes, or a
/// left vector cannot be matched.
fn lowest_shift_invert(
    q: Quadratic<'_>,
    pairs: &[(usize, usize)],
    count: usize,
    with_left: bool,
) -> Option<Vec<Mode>> {
    // Both members of each pair, plus spares so that heavily damped modes (|λ| well above
    // their damped frequency) are inside the computed set.
    let wanted = 2 * count + 16;
    let oscillating = |found: Vec<(c64, Vec<c64>)>| -> Vec<(c64, Vec<c64>)> {
        found.into_iter().filter(|(l, _)| crate::shift_invert::oscillates(*l)).collect()
    };
    let found = oscillating(crate::shift_invert::nearest_zero(q.m, q.d, q.k, wanted, count)?);
    let mut modes: Vec<Mode> = found
        .into_iter()
        .map(|(lambda, x)| {
            let whirl = whirl_of(&x, pairs);
            Mode { eigenvalue: lambda, right: x, left: Vec::new(), whirl }
        })
        .collect();
    modes.sort_by(|a, b| a.eigenvalue.im.total_cmp(&b.eigenvalue.im));
    if modes.len() < count {
        return None;
    }
    modes.truncate(count);
    if with_left {
        let [mt, dt, kt] = [q.m, q.d, q.k].map(Band::transpose);
        let mut transposed = oscillating(crate::shift_invert::nearest_zero(&mt, &dt, &kt, wanted, count)?);
        for mode in &mut modes {
            // The nearest unused eigenvalue of the transposed problem: the same to round-off.
            let (at, dist) = transposed
                .iter()
                .enumerate()
                .map(|(i, (l, _))| (i, (l - mode.eigenvalue).norm()))
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            if dist > 1e-7 * mode.eigenvalue.norm() {
                return None;
            }
            let (_, z) = transposed.swap_remove(at);
            mode.left = z.into_iter().map(|v| v.conj()).collect();
        }
    }
    Some(modes)
}

fn solve_llt(llt: &faer::linalg::solvers::Llt<f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    use faer::linalg::solvers::Solve;
    llt.solve(b)
}

fn solve_llt_c(llt: &faer::linalg::solvers::Llt<f64>, b: MatRef<'_, c64>) -> Mat<c64> {
    let n = b.nrows();
    let mut re = Mat::<f64>::zeros(n, b.ncols());
    let mut im = Mat::<f64>::zeros(n, b.ncols());
    for j in 0..b.ncols() {
        for i in 0..n {
            re[(i, j)] = b[(i, j)].re;
            im[(i, j)] = b[(i, j)].im;
        }
    }
    let re = solve_llt(llt, re.as_ref());
    let im = solve_llt(llt, im.as_ref());
    Mat::from_fn(n, b.ncols(), |i, j| c64::new(re[(i, j)], im[(i, j)]))
}

/// Diagonal balancing A ← D⁻¹AD with powers of two (Parlett & Reinsch), returning D: rows
/// and columns of comparable norm make the eigenvalues accurate to working precision.
fn balance(a: &mut Mat<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut d = vec![1.0; n];
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            // f = 2^k nearest √(r/c) equalises the column (·f) and row (/f) norms.
            let f = 2f64.powi((0.5 * (r / c).log2()).round() as i32);
            if f != 1.0 && c * f + r / f < 0.95 * (c + r) {
                done = false;
                d[i] *= f;
                for j in 0..n {
                    a[(j, i)] *= f;
                    a[(i, j)] /= f;
                }
            }
        }
        if done {
            break;
        }
    }
    d
}

type EigenParts = (Vec<c64>, Mat<c64>, Option<Mat<c64>>);

/// Eigenvalues, right and (optionally) left eigenvectors of a real matrix, unpacked from
/// LAPACK's real storage of conjugate pairs (columns j, j+1 = real and imaginary parts).
fn eigen_real(a: MatRef<'_, f64>, with_left: bool) -> Result<EigenParts, RotorDynError> {
    let n = a.nrows();
    let par = Par::Seq;
    let mut ur = Mat::<f64>::zeros(n, n);
    let mut ul = Mat::<f64>::zeros(n, n);
    let mut s_re = Diag::<f64>::zeros(n);
    let mut s_im = Diag::<f64>::zeros(n);
    let want_left = if with_left { ComputeEigenvectors::Yes } else { ComputeEigenvectors::No };
    let mut mem =
        MemBuffer::new(evd_scratch::<f64>(n, want_left, ComputeEigenvectors::Yes, par, Default::default()));
    evd_real(
        a,
        s_re.as_mut(),
        s_im.as_mut(),
        if with_left { Some(ul.as_mut()) } else { None },
        Some(ur.as_mut()),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .map_err(|e| RotorDynError::Solver(format!("the eigen-solver did not converge ({e:?})")))?;
    let s_re = s_re.column_vector();
    let s_im = s_im.column_vector();
    let mut values = vec![c64::new(0.0, 0.0); n];
    let mut right = Mat::<c64>::zeros(n, n);
    let mut left = if with_left { Some(Mat::<c64>::zeros(n, n)) } else { None };
    let mut j = 0;
    while j < n {
        if s_im[j] == 0.0 || j + 1 == n {
            values[j] = c64::new(s_re[j], 0.0);
            for i in 0..n {
                right[(i, j)] = c64::new(ur[(i, j)], 0.0);
                if let Some(l) = left.as_mut() {
                    l[(i, j)] = c64::new(ul[(i, j)], 0.0);
                }
            }
            j += 1;
        } else {
            values[j] = c64::new(s_re[j], s_im[j]);
            values[j + 1] = c64::new(s_re[j], -s_im[j]);
            for i in 0..n {
                right[(i, j)] = c64::new(ur[(i, j)], ur[(i, j + 1)]);
                right[(i, j + 1)] = c64::new(ur[(i, j)], -ur[(i, j + 1)]);
                if let Some(l) = left.as_mut() {
                    l[(i, j)] = c64::new(ul[(i, j)], ul[(i, j + 1)]);
                    l[(i, j + 1)] = c64::new(ul[(i, j)], -ul[(i, j + 1)]);
                }
            }
            j += 2;
        }
    }
    Ok((values, right, left))
}

/// Whirl of a mode as ROSS classifies it: the orbit of every shaft node that moves is
/// followed; all forward → forward, all backward → backward, otherwise mixed. An orbit
/// x(t) = Re(x e^{iωt}), y(t) = Re(y e^{iωt}) turns from x towards y (forward, the sense of
/// rotation about z) when Im(x̄·y) < 0. Nodes that do not move (amplitude below 10⁻⁶ of the
/// largest: a node of the mode shape, whose orbit is round-off) are skipped, where ROSS counts
/// them; a mode whose orbits are all straight lines (a non-rotating rotor) is mixed.
pub fn whirl_of(x: &[c64], pairs: &[(usize, usize)]) -> Whirl {
    let size = |&(ix, iy): &(usize, usize)| x[ix].norm_sqr() + x[iy].norm_sqr();
    let largest = pairs.iter().map(size).fold(0.0, f64::max);
    if largest == 0.0 {
        return Whirl::Mixed;
    }
    let (mut forward, mut backward) = (0usize, 0usize);
    for pair in pairs {
        let s = size(pair);
        if s < 1e-12 * largest {
            continue;
        }
        let turn = -2.0 * (x[pair.0].conj() * x[pair.1]).im / s;
        if turn.abs() <= WHIRL_TOLERANCE {
            continue;
        } else if turn > 0.0 {
            forward += 1;
        } else {
            backward += 1;
        }
    }
    // Like ROSS: one direction at every moving node, else mixed. Numerically straight orbits
    // (round-off decides their sense) do not count against a direction the others agree on.
    match (forward, backward) {
        (f, 0) if f > 0 => Whirl::Forward,
        (0, b) if b > 0 => Whirl::Backward,
        _ => Whirl::Mixed,
    }
}

/// Orbits flatter than this (|minor/major| below about 10⁻¹⁰) are lines.
pub const WHIRL_TOLERANCE: f64 = 2e-10;

/// Modal assurance criterion of two complex shapes.
pub fn mac(a: &[c64], b: &[c64]) -> f64 {
    let mut dot = c64::new(0.0, 0.0);
    let (mut na, mut nb) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        dot += x.conj() * y;
        na += x.norm_sqr();
        nb += y.norm_sqr();
    }
    if na == 0.0 || nb == 0.0 {
        0.0
    } else {
        dot.norm_sqr() / (na * nb)
    }
}
