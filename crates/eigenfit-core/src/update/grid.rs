//! Grids of starting points: every combination of one value per parameter.

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
    use super::tensor_product;

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
