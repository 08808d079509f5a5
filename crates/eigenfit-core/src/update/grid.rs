//! Grids of starting points: every combination of one value per parameter, and a space-filling
//! (Halton) design.

use crate::model::Parameter;

/// The value at fraction `t` ∈ [0, 1] of `p`'s search range: log-spaced when the range is
/// positive and spans more than two decades (whatever the scale), else in the scaled coordinate.
pub(crate) fn search_point(p: &Parameter, t: f64) -> f64 {
    let (lo, hi) = p.search_range();
    if lo > 0.0 && hi / lo > 100.0 {
        (lo.ln() + (hi / lo).ln() * t).exp()
    } else {
        let (a, b) = (p.to_scaled(lo), p.to_scaled(hi));
        p.from_scaled(a + (b - a) * t)
    }
}

/// The first `n` points of the Halton sequence in `dim` dimensions (bases the first primes,
/// index from 1 so no point sits on a corner): a low-discrepancy design that fills the unit
/// cube evenly at any `n`, unlike a tensor grid whose size jumps with the dimension. The one
/// space-filling design of starts (the search for other minima, a run-up's screened starts).
///
/// ```
/// let design = eigenfit_core::update::halton(4, 2);
/// assert_eq!(design[0], [0.5, 1.0 / 3.0]);
/// ```
pub fn halton(n: usize, dim: usize) -> Vec<Vec<f64>> {
    const PRIMES: [u64; 32] = [
        2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97, 101,
        103, 107, 109, 113, 127, 131,
    ];
    let radical_inverse = |mut i: u64, base: u64| {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r
    };
    (1..=n as u64)
        .map(|i| {
            (0..dim)
                .map(|d| match PRIMES.get(d) {
                    Some(&b) => radical_inverse(i, b),
                    // Beyond 32 dimensions: a Weyl sequence on an irrational step per axis.
                    None => (i as f64 * ((d as f64 + 2.0).sqrt() - 1.0)).fract(),
                })
                .collect()
        })
        .collect()
}

/// The tensor-product grid of `axes` (one list of values per parameter), the last parameter
/// varying fastest, cut to its first `most` points (the cut is made as the grid grows, so a grid
/// far beyond `most` is never built).
pub(crate) fn tensor_product(axes: &[Vec<f64>], most: usize) -> Vec<Vec<f64>> {
    let mut points: Vec<Vec<f64>> = vec![Vec::new()];
    for axis in axes {
        points = points
            .into_iter()
            .flat_map(|prefix| {
                axis.iter().map(move |&v| {
                    let mut p = prefix.clone();
                    p.push(v);
                    p
                })
            })
            .take(most)
            .collect();
    }
    points
}

#[cfg(test)]
mod tests {
    use super::{halton, tensor_product};

    #[test]
    fn halton_points_fill_each_axis_evenly() {
        let pts = halton(16, 3);
        assert_eq!(pts.len(), 16);
        assert_eq!(pts[0], [0.5, 1.0 / 3.0, 0.2]);
        for d in 0..3 {
            // Every half of every axis holds about half the points.
            let low = pts.iter().filter(|p| p[d] < 0.5).count();
            assert!((6..=10).contains(&low), "axis {d}: {low} of 16 below 0.5");
            assert!(pts.iter().all(|p| p[d] > 0.0 && p[d] < 1.0));
        }
    }

    #[test]
    fn last_parameter_varies_fastest_and_the_cut_keeps_the_first_points() {
        let axes = [vec![1.0, 2.0], vec![10.0, 20.0, 30.0]];
        let all = tensor_product(&axes, usize::MAX);
        assert_eq!(all.len(), 6);
        assert_eq!(all[0], [1.0, 10.0]);
        assert_eq!(all[1], [1.0, 20.0]);
        assert_eq!(all[5], [2.0, 30.0]);
        assert_eq!(tensor_product(&axes, 4), all[..4]);
        assert_eq!(tensor_product(&[], 4), [Vec::<f64>::new()]);
    }
}
