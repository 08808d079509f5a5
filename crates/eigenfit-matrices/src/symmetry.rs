//! Parameter symmetries of a matrices model: the permutations π of the parameters for which a
//! structural symmetry (a mirror, a rotation) maps every Kᵢ, Mᵢ onto K_π(i), M_π(i) and K₀, M₀
//! onto themselves. Then p and its permuted vector give the same frequencies, and frequencies
//! alone cannot tell the exchanged parameters apart (the plate's zones mirrored about a centre
//! line).
//!
//! A symmetry is an orthogonal change of DOFs P (a signed permutation of the DOFs for a mirror),
//! and PᵀAP keeps every Frobenius inner product ⟨A, B⟩ = Σ AᵢⱼBᵢⱼ and trace. The permutations
//! found here keep all of them — ⟨Kᵢ, Kⱼ⟩, ⟨Kᵢ, Mⱼ⟩, ⟨Mᵢ, Mⱼ⟩, ⟨Kᵢ, K₀⟩, ⟨Mᵢ, M₀⟩, tr Kᵢ, …
//! — which is necessary, not sufficient: callers confirm an exchange with one eigen-solve
//! before calling two solutions equally good. Cost O(np² · nnz), no factorisation.

use eigenfit_core::matrix::CscSymmetric;

/// Relative difference within which two invariants count as equal (sums of the same products
/// in another order differ by round-off only).
const SAME: f64 = 1e-8;
/// Most permutations returned (a model with more symmetries is reported in part).
const MAX_PERMUTATIONS: usize = 63;

/// ⟨A, B⟩ = Σᵢⱼ AᵢⱼBᵢⱼ over both triangles, from the stored upper parts (a sorted merge per
/// column: O(nnz(A) + nnz(B))).
pub(crate) fn frobenius_dot(a: &CscSymmetric, b: &CscSymmetric) -> f64 {
    let mut sum = 0.0;
    for c in 0..a.dim().min(b.dim()) {
        let ((ra, va), (rb, vb)) = (a.column(c), b.column(c));
        let (mut i, mut j) = (0, 0);
        while i < ra.len() && j < rb.len() {
            match ra[i].cmp(&rb[j]) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    let w = if ra[i] == c { 1.0 } else { 2.0 };
                    sum += w * va[i] * vb[j];
                    i += 1;
                    j += 1;
                }
            }
        }
    }
    sum
}

fn trace(a: &CscSymmetric) -> f64 {
    (0..a.dim()).map(|c| a.get(c, c)).sum()
}

fn same(x: f64, y: f64, scale: f64) -> bool {
    (x - y).abs() <= SAME * x.abs().max(y.abs()).max(scale)
}

/// The non-identity permutations π (π\[i\] = the parameter that parameter i is exchanged with)
/// that keep every invariant of the parameters' matrices, among parameters that `like(i, j)`
/// allows to exchange (same unit, scale and limits). `terms[i]` = (∂K/∂pᵢ, ∂M/∂pᵢ).
pub(crate) fn invariant_permutations(
    k0: &CscSymmetric,
    m0: &CscSymmetric,
    terms: &[(Option<&CscSymmetric>, Option<&CscSymmetric>)],
    like: impl Fn(usize, usize) -> bool,
) -> Vec<Vec<usize>> {
    let np = terms.len();
    // Each parameter's matrices as a list (stiffness, mass), absent ones as None.
    let mats = |i: usize| [terms[i].0, terms[i].1];
    // Own invariants: presence, trace, inner products with K₀ and M₀ of each of its matrices.
    let own: Vec<Vec<f64>> = (0..np)
        .map(|i| {
            mats(i)
                .iter()
                .flat_map(|m| match m {
                    Some(a) => vec![1.0, trace(a), frobenius_dot(a, k0), frobenius_dot(a, m0)],
                    None => vec![0.0; 4],
                })
                .collect()
        })
        .collect();
    // Mutual invariants: gram[i][j] = ⟨Kᵢ,Kⱼ⟩, ⟨Kᵢ,Mⱼ⟩, ⟨Mᵢ,Kⱼ⟩, ⟨Mᵢ,Mⱼ⟩.
    let gram: Vec<Vec<[f64; 4]>> = (0..np)
        .map(|i| {
            (0..np)
                .map(|j| {
                    let dot = |a: Option<&CscSymmetric>, b: Option<&CscSymmetric>| match (a, b) {
                        (Some(a), Some(b)) => frobenius_dot(a, b),
                        _ => 0.0,
                    };
                    let (ki, mi, kj, mj) = (terms[i].0, terms[i].1, terms[j].0, terms[j].1);
                    [dot(ki, kj), dot(ki, mj), dot(mi, kj), dot(mi, mj)]
                })
                .collect()
        })
        .collect();
    // The scale below which an invariant is round-off: each kind's largest value.
    let own_scale: Vec<f64> = (0..own.first().map_or(0, Vec::len))
        .map(|k| own.iter().map(|v| v[k].abs()).fold(0.0, f64::max) * 1e-12)
        .collect();
    let gram_scale: Vec<f64> =
        (0..4).map(|k| gram.iter().flatten().map(|g| g[k].abs()).fold(0.0, f64::max) * 1e-12).collect();
    let own_same = |i: usize, j: usize| (0..own[i].len()).all(|k| same(own[i][k], own[j][k], own_scale[k]));
    let gram_same = |a: (usize, usize), b: (usize, usize)| {
        (0..4).all(|k| same(gram[a.0][a.1][k], gram[b.0][b.1][k], gram_scale[k]))
    };
    let mut found = Vec::new();
    let mut perm: Vec<usize> = Vec::with_capacity(np);
    let mut used = vec![false; np];
    extend(np, &mut perm, &mut used, &mut found, &|i, j, perm: &[usize]| {
        like(i, j)
            && own_same(i, j)
            && (0..=i).all(|k| {
                let pk = if k == i { j } else { perm[k] };
                gram_same((i, k), (j, pk)) && gram_same((k, i), (pk, j))
            })
    });
    found
}

/// Depth-first completion of `perm` (assigned for the first parameters) by every consistent
/// choice; complete non-identity permutations go to `found`.
fn extend(
    np: usize,
    perm: &mut Vec<usize>,
    used: &mut [bool],
    found: &mut Vec<Vec<usize>>,
    fits: &dyn Fn(usize, usize, &[usize]) -> bool,
) {
    if found.len() >= MAX_PERMUTATIONS {
        return;
    }
    let i = perm.len();
    if i == np {
        if perm.iter().enumerate().any(|(k, &v)| k != v) {
            found.push(perm.clone());
        }
        return;
    }
    for j in 0..np {
        if !used[j] && fits(i, j, perm) {
            used[j] = true;
            perm.push(j);
            extend(np, perm, used, found, fits);
            perm.pop();
            used[j] = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A fixed–fixed chain of `n` unit masses whose springs are split into zones of equal length
    /// (`weights` scales each zone's springs; equal weights make the chain mirror-symmetric).
    fn chain(n: usize, zones: usize, weights: &[f64]) -> (CscSymmetric, CscSymmetric, Vec<CscSymmetric>) {
        let springs = n + 1;
        let mut zone_mats = vec![DMatrix::zeros(n, n); zones];
        for s in 0..springs {
            let z = s * zones / springs;
            let k = weights[z];
            let (a, b) = (s.checked_sub(1), (s < n).then_some(s));
            let m = &mut zone_mats[z];
            if let Some(a) = a {
                m[(a, a)] += k;
            }
            if let Some(b) = b {
                m[(b, b)] += k;
            }
            if let (Some(a), Some(b)) = (a, b) {
                m[(a, b)] -= k;
                m[(b, a)] -= k;
            }
        }
        let k0 = CscSymmetric::from_dense(&DMatrix::zeros(n, n));
        let m0 = CscSymmetric::from_dense(&DMatrix::identity(n, n));
        (k0, m0, zone_mats.iter().map(CscSymmetric::from_dense).collect())
    }

    fn permutations(k0: &CscSymmetric, m0: &CscSymmetric, zones: &[CscSymmetric]) -> Vec<Vec<usize>> {
        let terms: Vec<_> = zones.iter().map(|z| (Some(z), None)).collect();
        invariant_permutations(k0, m0, &terms, |_, _| true)
    }

    #[test]
    fn the_inner_product_counts_both_triangles() {
        let a = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 2.0]);
        let b = DMatrix::from_row_slice(3, 3, &[1.0, 3.0, 0.5, 3.0, 0.0, 0.0, 0.5, 0.0, 4.0]);
        let expected = a.component_mul(&b).sum();
        let got = frobenius_dot(&CscSymmetric::from_dense(&a), &CscSymmetric::from_dense(&b));
        assert!((got - expected).abs() < 1e-14, "{got} vs {expected}");
    }

    #[test]
    fn a_mirror_symmetric_chain_exchanges_its_outer_and_inner_zones_together() {
        // 4 zones of 5 springs each (19 masses): the mirror maps zone 1 ↔ 4 and 2 ↔ 3 at once.
        let (k0, m0, zones) = chain(19, 4, &[1.0; 4]);
        assert_eq!(permutations(&k0, &m0, &zones), vec![vec![3, 2, 1, 0]]);
    }

    #[test]
    fn an_asymmetric_chain_has_no_symmetry() {
        // One zone's springs stiffer: no permutation keeps the invariants.
        let (k0, m0, zones) = chain(19, 4, &[1.0, 1.0, 1.3, 1.0]);
        assert!(permutations(&k0, &m0, &zones).is_empty());
        // Unlike parameters (here: none may be exchanged) are never permuted.
        let (k0, m0, zones) = chain(19, 4, &[1.0; 4]);
        let terms: Vec<_> = zones.iter().map(|z| (Some(z), None)).collect();
        assert!(invariant_permutations(&k0, &m0, &terms, |i, j| i == j).is_empty());
    }
}
