//! Starts 30–50 % off a truth, shared by the 12-coefficient run-up test (`tests/identify.rs`)
//! and its study (`examples/runup12_starts.rs`).

/// `count` starts, each factor the truth's × (1 + u) or × (1 − u) with u in 0.3…0.5: first all
/// up 40 %, all down 40 %, then a Halton design for the sign and size of each factor's error.
pub fn starts_off(truth: &[f64], count: usize) -> Vec<Vec<f64>> {
    let n = truth.len();
    let uniform = [1.4, 0.6].into_iter().map(|f| truth.iter().map(|t| t * f).collect::<Vec<_>>());
    let mixed = eigenfit_core::update::halton(count, 2 * n).into_iter().map(|u| {
        (0..n)
            .map(|i| {
                let size = 0.3 + 0.2 * u[n + i];
                truth[i] * if u[i] < 0.5 { 1.0 - size } else { 1.0 + size }
            })
            .collect::<Vec<_>>()
    });
    uniform.chain(mixed).take(count).collect()
}
