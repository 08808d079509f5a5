//! The MAC matrix between measured and model shapes, and what it says about the pairing.

/// MAC between measured and model modes at the sensors, and the pairing's diagnosis.
#[derive(Debug, Clone, PartialEq)]
pub struct MacReport {
    /// MAC of measured mode i (rows, in measurement order) with the model mode paired to
    /// measured mode j (columns): a paired set of modes gives a dominant diagonal.
    pub matrix: Vec<Vec<f64>>,
    /// MAC of measured mode i with every model mode considered (columns: model modes 0, 1, …).
    pub full: Vec<Vec<f64>>,
    /// (measured mode number, model mode number, MAC), both numbers counted from 1.
    pub pairing: Vec<(usize, usize, f64)>,
    /// Measured mode numbers whose pair has a MAC below the threshold.
    pub unpaired: Vec<usize>,
    /// Measured mode-number pairs (a, b), a < b, whose model partners come in the opposite
    /// order: the model has these two modes swapped.
    pub swapped: Vec<(usize, usize)>,
    /// Model mode numbers (from 1) below the highest paired one that no measured mode took:
    /// modes the test missed (or the sensors cannot see).
    pub missing: Vec<usize>,
    /// The threshold used.
    pub threshold: f64,
}

impl MacReport {
    /// Builds the report. `measured` are the measured shapes with their 0-based mode numbers;
    /// `model` the model shapes at the same sensors (one per model mode, lowest first);
    /// `paired[i]` the model mode paired with measured mode i.
    pub fn new(measured: &[(usize, &[f64])], model: &[Vec<f64>], paired: &[usize], threshold: f64) -> Self {
        let full: Vec<Vec<f64>> =
            measured.iter().map(|(_, s)| model.iter().map(|m| mac(s, m)).collect()).collect();
        let matrix: Vec<Vec<f64>> = full.iter().map(|row| paired.iter().map(|&k| row[k]).collect()).collect();
        let pairing: Vec<(usize, usize, f64)> = measured
            .iter()
            .zip(paired)
            .enumerate()
            .map(|(i, (&(n, _), &k))| (n + 1, k + 1, matrix[i][i]))
            .collect();
        // A NaN MAC (a zero shape) counts as unpaired too.
        let unpaired = pairing.iter().filter(|p| p.2 < threshold || p.2.is_nan()).map(|p| p.0).collect();
        // Only modes that pair (MAC at or above the threshold) can be swapped: an unpaired one
        // is said as such, its partner is no claim.
        let paired_well = |p: &(usize, usize, f64)| p.2 >= threshold;
        let mut swapped = Vec::new();
        for a in 0..pairing.len() {
            for b in a + 1..pairing.len() {
                if paired_well(&pairing[a])
                    && paired_well(&pairing[b])
                    && (pairing[a].0 < pairing[b].0) != (pairing[a].1 < pairing[b].1)
                {
                    swapped.push((pairing[a].0.min(pairing[b].0), pairing[a].0.max(pairing[b].0)));
                }
            }
        }
        let highest = paired.iter().copied().max().unwrap_or(0);
        let missing = (0..=highest).filter(|k| !paired.contains(k)).map(|k| k + 1).collect();
        Self { matrix, full, pairing, unpaired, swapped, missing, threshold }
    }
}

/// Modal assurance criterion (aᵀb)² / (aᵀa · bᵀb), in [0, 1]; 0 for a zero vector.
///
/// Scale-free: each vector is divided by its largest |entry| before any product is formed, so a
/// shape scaled by 10²⁰⁰ (or 10⁻²⁰⁰) gives the MAC of the unscaled one instead of overflowing
/// (or underflowing) to NaN. NaN when an entry is not finite.
pub fn mac(a: &[f64], b: &[f64]) -> f64 {
    if a.iter().chain(b).any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    let largest = |x: &[f64]| x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let (sa, sb) = (largest(a), largest(b));
    if sa == 0.0 || sb == 0.0 {
        return 0.0;
    }
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (p, q) in a.iter().zip(b) {
        let (p, q) = (p / sa, q / sb);
        ab += p * q;
        aa += p * p;
        bb += q * q;
    }
    (ab * ab / (aa * bb)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_swapped_missing_and_unpaired_modes() {
        let model = vec![vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0], vec![0.0, 0.0, 1.0], vec![1.0, 1.0, 1.0]];
        let a = [0.0, 0.0, 1.0];
        let b = [0.1, 1.0, 0.0];
        let c = [1.0, -1.0, 0.3];
        let measured: Vec<(usize, &[f64])> = vec![(0, &a), (1, &b), (2, &c)];
        let r = MacReport::new(&measured, &model, &[2, 1, 0], 0.6);
        assert_eq!(r.pairing.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(), [(1, 3), (2, 2), (3, 1)]);
        assert_eq!(r.matrix[0][0], 1.0);
        assert!((r.matrix[1][1] - 1.0 / 1.01).abs() < 1e-15);
        // c·e1 = 1, |c|² = 2.09.
        assert!((r.matrix[2][2] - 1.0 / 2.09).abs() < 1e-15);
        assert_eq!(r.unpaired, [3]);
        // Measured mode 3 is unpaired: no swap is claimed with it, only between modes 1 and 2.
        assert_eq!(r.swapped, [(1, 2)]);
        assert!(r.missing.is_empty());
        let r = MacReport::new(&measured[..1], &model, &[2], 0.6);
        assert_eq!(r.missing, [1, 2]);
    }

    #[test]
    fn mac_does_not_care_about_scale() {
        let a = [1.0, -2.0, 0.5, 3.0];
        let b = [0.9, -2.2, 0.4, 3.1];
        let reference = mac(&a, &b);
        assert!(reference > 0.9 && reference < 1.0, "{reference}");
        for scale in [1e200, 1e-200, -1e300, 1e-300] {
            let scaled: Vec<f64> = a.iter().map(|v| v * scale).collect();
            let m = mac(&scaled, &b);
            assert!((m - reference).abs() <= 1e-15, "scale {scale:e}: {m} vs {reference}");
            assert!((mac(&b, &scaled) - reference).abs() <= 1e-15);
        }
        assert_eq!(mac(&[0.0; 4], &b), 0.0);
        assert!(mac(&[f64::INFINITY, 0.0, 0.0, 0.0], &b).is_nan());
    }
}
