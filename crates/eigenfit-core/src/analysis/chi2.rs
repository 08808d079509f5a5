//! The χ² distribution (the probability that noise alone explains a misfit) and the normal
//! quantiles the intervals and ambiguity tests use.

/// P(χ²_ν > x): the upper tail of the χ² distribution with `dof` degrees of freedom.
pub fn chi2_upper_tail(x: f64, dof: usize) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    if x.is_nan() || x == f64::INFINITY {
        return 0.0; // an infinite (or undefined) misfit is never explained by noise
    }
    1.0 - regularized_lower_gamma(dof as f64 / 2.0, x / 2.0)
}

/// x with P(χ²_ν > x) = `tail` (bisection on [`chi2_upper_tail`], to 1e-12 relative; `tail` in
/// (0, 1)): the threshold of a χ² test at significance `tail`.
pub fn chi2_quantile_upper(tail: f64, dof: usize) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 10.0 + 10.0 * dof as f64);
    while chi2_upper_tail(hi, dof) > tail {
        hi *= 2.0;
    }
    while hi - lo > 1e-12 * hi {
        let mid = 0.5 * (lo + hi);
        if chi2_upper_tail(mid, dof) > tail {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// 1.96: the two-sided 95 % quantile of the normal distribution.
pub(crate) const Z_95: f64 = 1.959_963_984_540_054;

/// z with P(Z > z) = `tail` for a standard normal Z (bisection on P(Z² ≥ z²) = 2·tail; `tail`
/// in (0, 0.5)).
pub(crate) fn normal_quantile_upper(tail: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if chi2_upper_tail(mid * mid, 1) > 2.0 * tail {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(a, x) = γ(a, x)/Γ(a) by its series (x < a + 1) or Lentz's continued fraction (otherwise).
fn regularized_lower_gamma(a: f64, x: f64) -> f64 {
    let ln_prefactor = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..500 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum * ln_prefactor.exp()).clamp(0.0, 1.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..500 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (1.0 - ln_prefactor.exp() * h).clamp(0.0, 1.0)
    }
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; relative error ~1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let series = G[1..].iter().enumerate().fold(G[0], |s, (i, &g)| s + g / (x + i as f64 + 1.0));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + series.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_normal_quantile_matches_its_tables() {
        assert!((normal_quantile_upper(0.025) - Z_95).abs() < 1e-6);
        // 0.025/10 (ten alternatives compared): 2.807; 0.005: 2.576.
        assert!((normal_quantile_upper(0.0025) - 2.807_033_768).abs() < 1e-6);
        assert!((normal_quantile_upper(0.005) - 2.575_829_304).abs() < 1e-6);
    }

    #[test]
    fn the_chi2_quantile_matches_its_tables() {
        // Abramowitz & Stegun table 26.8: χ²_0.95(1) = 3.841, (2) = 5.991, (4) = 9.488, (17) = 27.587.
        for (dof, q) in [
            (1, 3.841_458_820_694_124),
            (2, 5.991_464_547_107_979),
            (4, 9.487_729_036_781_154),
            (17, 27.587_111_638_275_33),
        ] {
            assert!((chi2_quantile_upper(0.05, dof) - q).abs() < 1e-9 * q, "dof {dof}");
        }
    }

    #[test]
    fn matches_tabulated_quantiles() {
        // χ²_{0.95} quantiles: ν = 1: 3.841, ν = 4: 9.488, ν = 10: 18.307, ν = 30: 43.773.
        for (x, dof) in [
            (3.841_458_820_694_124, 1),
            (9.487_729_036_781_154, 4),
            (18.307_038_053_275_146, 10),
            (43.772_971_825_742_19, 30),
        ] {
            assert!((chi2_upper_tail(x, dof) - 0.05).abs() < 1e-9, "ν = {dof}: {}", chi2_upper_tail(x, dof));
        }
        // ν = 2 has the closed form e^{−x/2}.
        assert!((chi2_upper_tail(3.0, 2) - (-1.5f64).exp()).abs() < 1e-14);
        assert_eq!(chi2_upper_tail(0.0, 3), 1.0);
    }
}
