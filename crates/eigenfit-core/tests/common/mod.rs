//! Shared fixtures for the eigen-sensitivity property tests: a random symmetric-definite
//! [`StructuralModel`] with an exact analytic derivative, its proptest strategy, and the
//! finite-difference helpers the properties compare against.
//!
//! The model is
//!
//! ```text
//! K(p) = s_K · (K0 + Σᵢ cᵢ gᵢ(pᵢ/p̄ᵢ) Aᵢ),   M(p) = s_M · (M0 + Σᵢ cᵢ gᵢ(pᵢ/p̄ᵢ) Bᵢ),
//! ```
//!
//! with K0 a grounded spring chain plus a few random extra springs (SPD), M0 a diagonal mass plus
//! positive consistent-mass couplings (SPD), gᵢ(x) = x^eᵢ with eᵢ ∈ {½, 1, 2, 3}, cᵢ ∈ 10^[-2, 2]
//! (from a soft support to one a hundred times stiffer than the shaft, where the paper notes
//! sensitivities become very small), and each parameter acting as
//!
//! * a support (ground) spring on one DOF: Aᵢ = eⱼeⱼᵀ (the paper's eq. 21 case),
//! * a spring between two DOFs: Aᵢ = (eⱼ − eₗ)(eⱼ − eₗ)ᵀ,
//! * a lumped mass on one DOF: Bᵢ = eⱼeⱼᵀ,
//! * or a spring and a lumped mass together (a "density-like" parameter touching both).
//!
//! Every Aᵢ, Bᵢ is positive semi-definite and gᵢ > 0, so K and M stay SPD for every positive p.
//! The nominal values p̄ᵢ span 10⁻³..10³ (so the derivatives carry the units, 1/p̄ᵢ) while each
//! term's contribution at p ≈ p̄ is cᵢ relative to K0, M0: the parameter *values* span six
//! decades, the *effects* four. The overall scales s_K ∈ 10^[-1, 5] and s_M ∈ 10^[-2, 2] check
//! that every tolerance is relative.
//!
//! Random draws rarely produce closely spaced modes, so a second family, [`NearSymmetric`]
//! (two weakly coupled copies), puts relative gaps down to and below the 1e-3 threshold of the
//! "well conditioned" clause.

#![allow(dead_code)] // each test binary uses a different subset

pub mod runner;

use eigenfit_core::eigen::{DenseSolver, EigenSolver, Modes};
use eigenfit_core::matrix::{SparseSymmetric, System, SystemDerivative};
use eigenfit_core::model::{ModelError, Parameter, ParameterSet, StructuralModel};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

/// What one parameter touches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    GroundSpring,
    Spring,
    Mass,
    SpringAndMass,
}

/// Generation data for one parameter (DOFs as fractions in [0, 1) so they fit any n).
#[derive(Debug, Clone)]
pub struct ParamSpec {
    pub kind: Kind,
    pub dof_a: f64,
    pub dof_b: f64,
    pub exponent: f64,
    pub log10_nominal: f64,
    /// log₁₀ of the term's weight cᵢ relative to K0, M0.
    pub log10_coefficient: f64,
    /// Evaluation point p = ratio · p̄.
    pub ratio: f64,
}

/// Generation data for one random model.
#[derive(Debug, Clone)]
pub struct Spec {
    pub n: usize,
    pub chain: Vec<f64>,
    pub masses: Vec<f64>,
    pub couplings: Vec<f64>,
    pub extra_springs: Vec<(f64, f64, f64)>,
    pub params: Vec<ParamSpec>,
    pub log10_k_scale: f64,
    pub log10_m_scale: f64,
}

/// One parameter's term: K += coef·g(p/p̄)·a, M += coef·g(p/p̄)·b (scales folded into a, b).
#[derive(Debug, Clone)]
pub struct Term {
    pub a: SparseSymmetric,
    pub b: SparseSymmetric,
    pub nominal: f64,
    pub exponent: f64,
}

impl Term {
    fn g(&self, p: f64) -> f64 {
        (p / self.nominal).powf(self.exponent)
    }
    fn dg(&self, p: f64) -> f64 {
        self.exponent * (p / self.nominal).powf(self.exponent - 1.0) / self.nominal
    }
}

/// K(p) = K0 + Σ gᵢ(pᵢ) Aᵢ, M(p) = M0 + Σ gᵢ(pᵢ) Bᵢ with the exact derivative.
#[derive(Debug, Clone)]
pub struct RandomModel {
    pub k0: DMatrix<f64>,
    pub m0: DMatrix<f64>,
    pub terms: Vec<Term>,
    pub params: ParameterSet,
    /// The evaluation point (each pᵢ = ratioᵢ·p̄ᵢ).
    pub point: Vec<f64>,
}

impl RandomModel {
    pub fn from_spec(spec: &Spec) -> Self {
        let n = spec.n;
        let sk = 10f64.powf(spec.log10_k_scale);
        let sm = 10f64.powf(spec.log10_m_scale);
        // Grounded chain: spring 0 to ground, spring i between i−1 and i.
        let mut k0 = DMatrix::zeros(n, n);
        for (i, &k) in spec.chain.iter().enumerate() {
            k0[(i, i)] += k;
            if i > 0 {
                k0[(i - 1, i - 1)] += k;
                k0[(i - 1, i)] -= k;
                k0[(i, i - 1)] -= k;
            }
        }
        for (a, b, k) in &spec.extra_springs {
            let (i, j) = distinct_pair(n, *a, *b);
            k0[(i, i)] += k;
            k0[(j, j)] += k;
            k0[(i, j)] -= k;
            k0[(j, i)] -= k;
        }
        let mut m0 = DMatrix::from_diagonal(&DVector::from_column_slice(&spec.masses));
        for (i, &c) in spec.couplings.iter().enumerate() {
            // c·(eᵢ + eᵢ₊₁)(eᵢ + eᵢ₊₁)ᵀ: PSD, positive off-diagonal like a consistent mass.
            let c = c * spec.masses[i].min(spec.masses[i + 1]);
            for (r, s) in [(i, i), (i, i + 1), (i + 1, i), (i + 1, i + 1)] {
                m0[(r, s)] += c;
            }
        }
        let mut terms = Vec::new();
        let mut params = Vec::new();
        let mut point = Vec::new();
        for (idx, ps) in spec.params.iter().enumerate() {
            let mut a = SparseSymmetric::zeros(n);
            let mut b = SparseSymmetric::zeros(n);
            let j = dof(n, ps.dof_a);
            let (s, t) = distinct_pair(n, ps.dof_a, ps.dof_b);
            let c = 10f64.powf(ps.log10_coefficient);
            match ps.kind {
                Kind::GroundSpring => a.add(j, j, sk * c),
                Kind::Spring => add_spring(&mut a, s, t, sk * c),
                Kind::Mass => b.add(j, j, sm * c),
                Kind::SpringAndMass => {
                    add_spring(&mut a, s, t, sk * c);
                    b.add(s, s, 0.5 * sm * c);
                    b.add(t, t, 0.5 * sm * c);
                }
            }
            let nominal = 10f64.powf(ps.log10_nominal);
            terms.push(Term { a, b, nominal, exponent: ps.exponent });
            params.push(
                Parameter::new(format!("p{idx}"), "unit", nominal).with_bounds(1e-3 * nominal, 1e3 * nominal),
            );
            point.push(ps.ratio * nominal);
        }
        Self {
            k0: k0 * sk,
            m0: m0 * sm,
            terms,
            params: ParameterSet::new(params).expect("valid parameters"),
            point,
        }
    }
}

/// DOF `⌊frac·n⌋` (frac in [0, 1)).
pub fn dof(n: usize, frac: f64) -> usize {
    ((frac * n as f64) as usize).min(n - 1)
}

/// Two distinct DOFs (n ≥ 2).
fn distinct_pair(n: usize, a: f64, b: f64) -> (usize, usize) {
    let i = dof(n, a);
    let j = (i + 1 + dof(n - 1, b)) % n;
    (i, j)
}

fn add_spring(s: &mut SparseSymmetric, i: usize, j: usize, k: f64) {
    s.add(i, i, k);
    s.add(j, j, k);
    s.add(i, j, -k);
}

impl StructuralModel for RandomModel {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn dofs(&self) -> usize {
        self.k0.nrows()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let mut k = self.k0.clone();
        let mut m = self.m0.clone();
        for (t, &pi) in self.terms.iter().zip(p) {
            let g = t.g(pi);
            k += t.a.to_dense() * g;
            m += t.b.to_dense() * g;
        }
        Ok(System::new(k, m)?)
    }
    /// The exact derivative: gᵢ'(pᵢ)·Aᵢ and gᵢ'(pᵢ)·Bᵢ.
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        self.params.check(p)?;
        let t = self.terms.get(i).ok_or(ModelError::ParameterIndex { index: i, count: self.terms.len() })?;
        let dg = t.dg(p[i]);
        let scale = |s: &SparseSymmetric| {
            let mut out = SparseSymmetric::zeros(s.dim());
            for &(r, c, v) in s.entries() {
                out.add(r, c, v * dg);
            }
            out
        };
        Ok(SystemDerivative { stiffness: scale(&t.a), mass: scale(&t.b) })
    }
}

/// The same model WITHOUT a `derivative` override: it gets the trait's finite-difference default.
pub struct FdOnly<'a>(pub &'a RandomModel);

impl StructuralModel for FdOnly<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.0.parameters()
    }
    fn dofs(&self) -> usize {
        self.0.dofs()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.0.assemble(p)
    }
}

fn param_spec() -> impl Strategy<Value = ParamSpec> {
    (
        prop_oneof![
            Just(Kind::GroundSpring),
            Just(Kind::Spring),
            Just(Kind::Mass),
            Just(Kind::SpringAndMass)
        ],
        0.0..1.0f64,
        0.0..1.0f64,
        prop::sample::select(vec![1.0, 2.0, 0.5, 3.0]),
        -3.0..3.0f64,
        -2.0..2.0f64,
        0.5..2.0f64,
    )
        .prop_map(|(kind, dof_a, dof_b, exponent, log10_nominal, log10_coefficient, ratio)| ParamSpec {
            kind,
            dof_a,
            dof_b,
            exponent,
            log10_nominal,
            log10_coefficient,
            ratio,
        })
}

/// Random model of 2..=`max_n` DOFs with 1..=4 parameters.
pub fn spec(max_n: usize) -> impl Strategy<Value = Spec> {
    (2usize..=max_n).prop_flat_map(|n| {
        (
            Just(n),
            prop::collection::vec(0.3..3.0f64, n),
            prop::collection::vec(0.5..2.0f64, n),
            prop::collection::vec(0.0..0.3f64, n - 1),
            prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, 0.1..1.0f64), 0..4),
            prop::collection::vec(param_spec(), 1..=4),
            -1.0..5.0f64,
            -2.0..2.0f64,
        )
            .prop_map(|(n, chain, masses, couplings, extra_springs, params, lk, lm)| Spec {
                n,
                chain,
                masses,
                couplings,
                extra_springs,
                params,
                log10_k_scale: lk,
                log10_m_scale: lm,
            })
    })
}

/// All n modes at `p`.
pub fn all_modes(model: &impl StructuralModel, p: &[f64]) -> (System, Modes) {
    let sys = model.assemble(p).expect("assembles");
    let modes = DenseSolver.lowest(&sys, sys.dofs()).expect("solves");
    (sys, modes)
}

/// All n modes at `p`, each from the most accurate solve available: the lowest ⌊n/2⌋ from a
/// solve of just those (the dense solver then reduces the inverted problem, accurate relative to
/// each λ), the rest from the full solve (accurate to ε·λmax, i.e. relative ε·λmax/λₖ).
///
/// Finite-difference references use this. The full solve's error in a low λₖ is not only larger
/// (ε·λmax) but SMOOTH in p, so it survives differencing with a tiny step-to-step scatter: on a
/// close-pair draw the full-solve FD of dλ₁/dp was 1.6e-7 (natural scale) off the analytic value
/// while its Richardson estimates agreed to 9e-12; from the low-mode solve it was 2e-12 off.
pub fn reference_modes(model: &impl StructuralModel, p: &[f64]) -> Modes {
    let (sys, mut modes) = all_modes(model, p);
    let half = sys.dofs() / 2;
    if half > 0 {
        let low = DenseSolver.lowest(&sys, half).expect("solves");
        modes.eigenvalues.rows_mut(0, half).copy_from(&low.eigenvalues);
        modes.shapes.columns_mut(0, half).copy_from(&low.shapes);
    }
    modes
}

/// Relative gap of mode k to its neighbours: min over l ≠ k of |λₖ − λₗ| / max(|λₖ|, |λₗ|).
pub fn relative_gap(lambda: &DVector<f64>, k: usize) -> f64 {
    (0..lambda.len())
        .filter(|&l| l != k)
        .map(|l| (lambda[k] - lambda[l]).abs() / lambda[k].abs().max(lambda[l].abs()))
        .fold(f64::INFINITY, f64::min)
}

/// Modes below this relative gap are "not well conditioned" for the FD comparisons and skipped.
pub const MIN_RELATIVE_GAP: f64 = 1e-3;

/// Relative steps of the finite-difference sweep (× |pᵢ|).
pub const STEPS: [f64; 8] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6];

pub use eigenfit_core::testing::richardson;

/// Richardson estimates of df/dpᵢ for every step of [`STEPS`] (f returns all modes at once, so
/// one sweep serves every mode).
pub struct Sweep(Vec<(f64, DVector<f64>)>);

impl Sweep {
    pub fn new<F>(p: &[f64], i: usize, mut f: F) -> Self
    where
        F: FnMut(&[f64]) -> DVector<f64>,
    {
        Self(STEPS.iter().map(|&h| (h, richardson(p, i, h, &mut f))).collect())
    }

    /// The best estimate of rows `rows` among steps h ≤ `max_step`, and its error estimate.
    ///
    /// Why a sweep and not one step: the truncation error of the Richardson estimate is
    /// O((h·c/gap)⁴), c the parameter's coupling of mode k to its neighbours (unknown, often
    /// ≪ 1), while its round-off error is ε_solve/h, and for an eigenvector ε_solve ~
    /// ε·(λmax/λₖ)/gap reaches 1e-9 near the 1e-3 gap threshold — so no fixed step suits every
    /// draw (a fixed h = gap/100 measured 1.4e-5 error on a 2×2-DOF near-symmetric case where
    /// h = 1e-3 gives 1e-7). The classical remedy: truncation falls and round-off rises as h
    /// shrinks, so they balance where consecutive estimates agree best; take that estimate,
    /// with the disagreement as its error estimate. Steps above the mode's relative gap are
    /// excluded: there the perturbed modes may swap order.
    pub fn best(&self, max_step: f64, rows: std::ops::Range<usize>) -> (DVector<f64>, f64) {
        let usable: Vec<&DVector<f64>> =
            self.0.iter().filter(|(h, _)| *h <= max_step).map(|(_, r)| r).collect();
        assert!(usable.len() >= 2, "gap below the smallest steps");
        let len = rows.len();
        usable
            .windows(2)
            .map(|w| {
                let a = w[0].rows(rows.start, len).into_owned();
                let diff = (&a - w[1].rows(rows.start, len)).amax();
                (a, diff)
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap()
    }
}

/// All modes at `q` (flattened column-major), each sign-aligned with the mode of the same index
/// at p (`base`) in the M(p) inner product, so that differences of modes are meaningful.
pub fn aligned_modes(
    model: &impl StructuralModel,
    q: &[f64],
    base: &Modes,
    m_base: &DMatrix<f64>,
) -> DVector<f64> {
    let mut shapes = reference_modes(model, q).shapes;
    for (mut col, b) in shapes.column_iter_mut().zip(base.shapes.column_iter()) {
        if col.dot(&(m_base * b)) < 0.0 {
            col.neg_mut();
        }
    }
    DVector::from_column_slice(shapes.as_slice())
}

/// Two copies of a [`RandomModel`] joined DOF-by-DOF by weak springs κ: copy A follows the
/// parameters, copy B is frozen at the evaluation point. At that point the structure is
/// symmetric, so every mode of the single model splits into a symmetric/antisymmetric pair a
/// relative ~κ/λ apart, and a parameter acting on copy A alone couples the two strongly
/// (dφ ~ coupling / gap). This is the family that exercises the gap filter and the step choice.
#[derive(Debug, Clone)]
pub struct NearSymmetric {
    pub inner: RandomModel,
    pub kappa: f64,
    frozen: System,
}

impl NearSymmetric {
    pub fn new(inner: RandomModel, log10_kappa: f64) -> Self {
        let frozen = inner.assemble(&inner.point).expect("assembles");
        let kappa = 10f64.powf(log10_kappa) * inner.k0.amax();
        Self { inner, kappa, frozen }
    }
}

impl StructuralModel for NearSymmetric {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn dofs(&self) -> usize {
        2 * self.inner.dofs()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        let n = self.inner.dofs();
        let (ka, ma) = self.inner.assemble(p)?.into_parts();
        let mut k = DMatrix::zeros(2 * n, 2 * n);
        let mut m = DMatrix::zeros(2 * n, 2 * n);
        k.view_mut((0, 0), (n, n)).copy_from(&ka);
        m.view_mut((0, 0), (n, n)).copy_from(&ma);
        k.view_mut((n, n), (n, n)).copy_from(self.frozen.stiffness());
        m.view_mut((n, n), (n, n)).copy_from(self.frozen.mass());
        for l in 0..n {
            k[(l, l)] += self.kappa;
            k[(n + l, n + l)] += self.kappa;
            k[(l, n + l)] -= self.kappa;
            k[(n + l, l)] -= self.kappa;
        }
        Ok(System::new(k, m)?)
    }
    /// Exact: the inner derivative, on copy A only.
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let d = self.inner.derivative(p, i)?;
        let dim = self.dofs();
        let copy = |s: &SparseSymmetric| {
            let mut out = SparseSymmetric::zeros(dim);
            for &(r, c, v) in s.entries() {
                out.add(r, c, v);
            }
            out
        };
        Ok(SystemDerivative { stiffness: copy(&d.stiffness), mass: copy(&d.mass) })
    }
}

/// A [`NearSymmetric`] model of 2×(2..=`max_half`) DOFs, κ ∈ 10^[-4, -1]·max|K0|.
pub fn near_symmetric(max_half: usize) -> impl Strategy<Value = (Spec, f64)> {
    (spec(max_half), -4.0..-1.0f64)
}
