//! Analytic eigenvalue sensitivities of the damped gyroscopic problem from left and right
//! eigenvectors (Adhikari & Friswell 2001):
//!
//! dλ/dp = −yᴴ(λ²M′ + λD′ + K′)x / yᴴ(2λM + D)x,  D = C + ΩG.
//!
//! Where two eigenvalues coincide (a forward/backward pair of an isotropic rotor at Ω = 0) the
//! eigenvectors are any basis of a 2-D space and the formula above depends on that choice. There
//! the derivatives are the eigenvalues of the small matrix (YᴴBX)⁻¹(−YᴴQ′X) over the cluster,
//! which are the one-sided (p increasing) derivatives of the sorted eigenvalues.

use crate::modal::Mode;
use crate::rotor::Matrices;
use faer::{c64, Mat};

/// The derivative of M, D and K with respect to one parameter (each may be absent = zero).
#[derive(Debug, Clone, Default)]
pub struct MatrixDerivative {
    /// ∂M/∂p.
    pub m: Option<Mat<f64>>,
    /// ∂D/∂p (damping, including any speed-dependent part).
    pub d: Option<Mat<f64>>,
    /// ∂K/∂p.
    pub k: Option<Mat<f64>>,
}

/// Relative distance below which eigenvalues are treated as one cluster.
const CLUSTER_TOLERANCE: f64 = 1e-7;

fn quad_form(y: &[c64], a: &Mat<f64>, x: &[c64]) -> c64 {
    let n = x.len();
    let mut s = c64::new(0.0, 0.0);
    for j in 0..n {
        if x[j] == c64::new(0.0, 0.0) {
            continue;
        }
        let mut col = c64::new(0.0, 0.0);
        for i in 0..n {
            let v = a[(i, j)];
            if v != 0.0 {
                col += y[i].conj() * v;
            }
        }
        s += col * x[j];
    }
    s
}

/// yᴴ Q′(λ) x with Q′ = λ²M′ + λD′ + K′.
fn q_prime(y: &[c64], dq: &MatrixDerivative, lambda: c64, x: &[c64]) -> c64 {
    let mut s = c64::new(0.0, 0.0);
    if let Some(m) = &dq.m {
        s += lambda * lambda * quad_form(y, m, x);
    }
    if let Some(d) = &dq.d {
        s += lambda * quad_form(y, d, x);
    }
    if let Some(k) = &dq.k {
        s += quad_form(y, k, x);
    }
    s
}

/// yᴴ(2λM + D)x.
fn b_form(y: &[c64], mats: &Matrices, lambda: c64, x: &[c64]) -> c64 {
    lambda * 2.0 * quad_form(y, &mats.m, x) + quad_form(y, &mats.d, x)
}

/// dλ/dp for every mode (outer) and parameter (inner). The modes must carry left vectors and
/// be sorted by damped frequency (as `Rotor::modes` returns them).
pub fn eigenvalue_derivatives(mats: &Matrices, modes: &[Mode], params: &[MatrixDerivative]) -> Vec<Vec<c64>> {
    let mut out = vec![vec![c64::new(0.0, 0.0); params.len()]; modes.len()];
    let mut start = 0;
    while start < modes.len() {
        let mut end = start + 1;
        while end < modes.len()
            && (modes[end].eigenvalue - modes[start].eigenvalue).norm()
                <= CLUSTER_TOLERANCE * modes[start].eigenvalue.norm()
        {
            end += 1;
        }
        let cluster = &modes[start..end];
        // yᴴ(2λM + D)x does not depend on the parameter: once per mode, not once per pair.
        let b: Vec<c64> = if cluster.len() == 2 {
            Vec::new()
        } else {
            cluster.iter().map(|m| b_form(&m.left, mats, m.eigenvalue, &m.right)).collect()
        };
        for (p, dq) in params.iter().enumerate() {
            let d = if cluster.len() == 2 {
                pair_derivatives(mats, cluster, dq)
            } else {
                // Single modes (and, as an approximation, larger clusters): the formula as is.
                cluster
                    .iter()
                    .zip(&b)
                    .map(|(m, b)| -q_prime(&m.left, dq, m.eigenvalue, &m.right) / b)
                    .collect()
            };
            for (i, v) in d.into_iter().enumerate() {
                out[start + i][p] = v;
            }
        }
        start = end;
    }
    out
}

/// Derivatives of a double eigenvalue: eigenvalues of N⁻¹P with N = YᴴBX, P = −YᴴQ′X, sorted
/// by imaginary part so they belong to the modes in ascending damped frequency.
fn pair_derivatives(mats: &Matrices, pair: &[Mode], dq: &MatrixDerivative) -> Vec<c64> {
    let lambda = (pair[0].eigenvalue + pair[1].eigenvalue) * 0.5;
    let mut n = [[c64::new(0.0, 0.0); 2]; 2];
    let mut p = [[c64::new(0.0, 0.0); 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            n[i][j] = b_form(&pair[i].left, mats, lambda, &pair[j].right);
            p[i][j] = -q_prime(&pair[i].left, dq, lambda, &pair[j].right);
        }
    }
    let det = n[0][0] * n[1][1] - n[0][1] * n[1][0];
    // S = N⁻¹ P.
    let inv = [[n[1][1] / det, -n[0][1] / det], [-n[1][0] / det, n[0][0] / det]];
    let mut s = [[c64::new(0.0, 0.0); 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            s[i][j] = inv[i][0] * p[0][j] + inv[i][1] * p[1][j];
        }
    }
    let tr = s[0][0] + s[1][1];
    let dt = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let root = (tr * tr * 0.25 - dt).sqrt();
    let mut e = [tr * 0.5 - root, tr * 0.5 + root];
    e.sort_by(|a, b| a.im.total_cmp(&b.im));
    e.to_vec()
}
