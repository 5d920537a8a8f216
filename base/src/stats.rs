//! Statistical tests for Monte Carlo estimates: the distributions behind the checks of the
//! global-illumination checkpoints (a sampler's density by a chi-square test, an estimator's
//! mean by a t-test) and the grader's per-tile comparison of noisy means (Welch).
//!
//! **Maths.** With `x = ν / (ν + t²)`, Student's t with `ν` degrees of freedom has the two-sided
//! tail `P(|T| ≥ |t|) = I_x(ν/2, 1/2)`, where `I_x(a, b)` is the regularized incomplete beta
//! function; the chi-square distribution with `k` degrees of freedom has the upper tail
//! `P(X ≥ x) = Q(k/2, x/2)`, the regularized upper incomplete gamma function. Both are evaluated
//! as in *Numerical Recipes* (Press et al., 3rd ed., §6.2 and §6.4): a series or a continued
//! fraction (modified Lentz), whichever converges fast for the argument, and `ln Γ` by Lanczos'
//! approximation (g = 7, 9 coefficients), good to about 1e-15 relative.
//!
//! Welch's t-test compares two means whose samples have different variances: `t = (m₁ − m₂) /
//! √(s₁²/n₁ + s₂²/n₂)` with the Welch-Satterthwaite degrees of freedom.
//!
//! The tests only the grader uses (its rank test of tile spreads, Šidák's level, binomial
//! bounds) are the grader's own: `raylab_grade::stats`.

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
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
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let sum = C[1..].iter().enumerate().fold(C[0], |s, (i, c)| s + c / (x + i as f64 + 1.0));
    let t = x + G + 0.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// Iterations and tolerance of the series and continued fractions.
const MAX_ITERATIONS: usize = 500;
const EPSILON: f64 = 1e-15;
/// Stands in for zero in Lentz's method.
const TINY: f64 = 1e-300;

/// The continued fraction of `I_x(a, b)` (Numerical Recipes' `betacf`), by modified Lentz.
fn beta_continued_fraction(a: f64, b: f64, x: f64) -> f64 {
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    d = 1.0 / if d.abs() < TINY { TINY } else { d };
    let mut h = d;
    for m in 1..MAX_ITERATIONS {
        let m = m as f64;
        let m2 = 2.0 * m;
        for coefficient in
            [m * (b - m) * x / ((qam + m2) * (a + m2)), -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))]
        {
            d = 1.0 + coefficient * d;
            d = 1.0 / if d.abs() < TINY { TINY } else { d };
            c = 1.0 + coefficient / c;
            if c.abs() < TINY {
                c = TINY;
            }
            h *= d * c;
        }
        // The last factor applied is d · c of the odd step; converged when it is 1.
        if (d * c - 1.0).abs() < EPSILON {
            break;
        }
    }
    h
}

/// The regularized incomplete beta function `I_x(a, b)`, for `a, b > 0` and `x` in `[0, 1]`.
pub fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    // The continued fraction converges fast below the mean; above it, use the symmetry
    // I_x(a, b) = 1 − I_{1−x}(b, a).
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_continued_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_continued_fraction(b, a, 1.0 - x) / b
    }
}

/// The regularized upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)`, `a > 0`, `x ≥ 0`.
pub fn upper_incomplete_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // The series of P(a, x) = 1 − Q(a, x).
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..MAX_ITERATIONS {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * EPSILON {
                break;
            }
        }
        1.0 - front * sum
    } else {
        // The continued fraction of Q(a, x), by modified Lentz.
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..MAX_ITERATIONS {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = 1.0 / if d.abs() < TINY { TINY } else { d };
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < EPSILON {
                break;
            }
        }
        front * h
    }
}

/// `P(|T| ≥ |t|)` for Student's t with `dof > 0` degrees of freedom (real, as Welch's are).
pub fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    incomplete_beta(dof / 2.0, 0.5, dof / (dof + t * t))
}

/// `P(X ≥ x)` for the chi-square distribution with `dof` degrees of freedom.
pub fn chi_square_upper(x: f64, dof: f64) -> f64 {
    upper_incomplete_gamma(dof / 2.0, x / 2.0)
}

/// The mean, the unbiased variance and the count of a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Sample mean.
    pub mean: f64,
    /// Unbiased sample variance (divided by `n − 1`).
    pub variance: f64,
    /// Number of values.
    pub n: f64,
}

impl Summary {
    /// The summary of `values` (at least two).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Summary {
        // Welford's update: one pass, no cancellation between a large sum of squares and mean².
        let (mut n, mut mean, mut m2) = (0.0, 0.0, 0.0);
        for x in values {
            n += 1.0;
            let delta = x - mean;
            mean += delta / n;
            m2 += delta * (x - mean);
        }
        Summary { mean, variance: if n > 1.0 { m2 / (n - 1.0) } else { f64::NAN }, n }
    }

    /// The variance of the mean, `s² / n`.
    pub fn variance_of_mean(&self) -> f64 {
        self.variance / self.n
    }
}

/// Welch's t statistic, its degrees of freedom, and the two-sided p-value for `a` and `b` having
/// the same mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Welch {
    /// The statistic.
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub dof: f64,
    /// Two-sided p-value.
    pub p: f64,
}

/// Welch's t-test of equal means.
pub fn welch(a: &Summary, b: &Summary) -> Welch {
    let (va, vb) = (a.variance_of_mean(), b.variance_of_mean());
    let se2 = va + vb;
    if se2 == 0.0 {
        // Two constant samples: equal means pass for certain, different ones fail for certain.
        let p = if a.mean == b.mean { 1.0 } else { 0.0 };
        return Welch { t: if p == 1.0 { 0.0 } else { f64::INFINITY }, dof: f64::INFINITY, p };
    }
    let t = (a.mean - b.mean) / se2.sqrt();
    let dof = se2 * se2 / (va * va / (a.n - 1.0) + vb * vb / (b.n - 1.0));
    Welch { t, dof, p: student_t_two_sided(t, dof) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(got: f64, want: f64, tolerance: f64) {
        assert!((got - want).abs() <= tolerance, "{got} vs {want}");
    }

    /// Γ at integers and halves: (n − 1)! and √π-multiples.
    #[test]
    fn ln_gamma_matches_factorials_and_the_half_integers() {
        close(ln_gamma(1.0), 0.0, 1e-14);
        close(ln_gamma(10.0), 362_880f64.ln(), 1e-12);
        close(ln_gamma(0.5), std::f64::consts::PI.sqrt().ln(), 1e-14);
        close(ln_gamma(2.5), (0.75 * std::f64::consts::PI.sqrt()).ln(), 1e-14);
        close(ln_gamma(0.1), 9.513_507_698_668_732f64.ln(), 1e-12);
    }

    /// Table values of Student's t (two-sided 5% and 1% critical values) and its closed forms:
    /// ν = 1 is Cauchy, `p = 1 − 2 atan(t) / π`; ν = 2 has `p = 1 − t / √(2 + t²)`.
    #[test]
    fn student_t_tails_match_the_tables_and_closed_forms() {
        for (t, dof, p) in [(12.706, 1.0, 0.05), (2.228, 10.0, 0.05), (3.169, 10.0, 0.01), (1.960, 1e7, 0.05)]
        {
            close(student_t_two_sided(t, dof), p, 2e-4);
        }
        for t in [0.1, 1.0, 3.0, 30.0] {
            close(student_t_two_sided(t, 1.0), 1.0 - 2.0 * f64::atan(t) / std::f64::consts::PI, 1e-12);
            close(student_t_two_sided(t, 2.0), 1.0 - t / (2.0 + t * t).sqrt(), 1e-12);
        }
        close(student_t_two_sided(0.0, 7.0), 1.0, 1e-15);
    }

    /// Table values of the chi-square upper tail, and the closed forms for 2 degrees of freedom
    /// (`e^(−x/2)`) and 1 (`erfc(√(x/2))`, at the 5% point 3.841).
    #[test]
    fn chi_square_tails_match_the_tables_and_closed_forms() {
        for (x, dof, p) in
            [(3.841, 1.0, 0.05), (18.307, 10.0, 0.05), (23.209, 10.0, 0.01), (124.342, 100.0, 0.05)]
        {
            close(chi_square_upper(x, dof), p, 2e-4);
        }
        for x in [0.01, 1.0, 5.0, 40.0] {
            close(chi_square_upper(x, 2.0), (-x / 2.0).exp(), 1e-13);
        }
        close(chi_square_upper(0.0, 5.0), 1.0, 0.0);
    }

    /// `I_x(a, 1) = x^a`, `I_x(1, b) = 1 − (1 − x)^b`, and the symmetry `I_x(a, b) = 1 − I_{1−x}(b, a)`.
    #[test]
    fn the_incomplete_beta_function_has_its_closed_forms_and_symmetry() {
        for x in [0.01, 0.3, 0.5, 0.9, 0.999] {
            close(incomplete_beta(3.5, 1.0, x), x.powf(3.5), 1e-13);
            close(incomplete_beta(1.0, 4.0, x), 1.0 - (1.0 - x).powi(4), 1e-13);
            close(incomplete_beta(2.5, 7.0, x), 1.0 - incomplete_beta(7.0, 2.5, 1.0 - x), 1e-13);
        }
    }

    /// Welch's test on two known samples (by hand: means 3 and 5, variances 2.5 and 2.5, n = 5:
    /// t = −2, ν = 8, p = 0.0805 from the t table).
    #[test]
    fn welch_gives_the_textbook_statistic_degrees_of_freedom_and_p() {
        let a = Summary::of([1.0, 2.0, 3.0, 4.0, 5.0]);
        let b = Summary::of([3.0, 4.0, 5.0, 6.0, 7.0]);
        assert_eq!((a.mean, a.variance, a.n), (3.0, 2.5, 5.0));
        let w = welch(&a, &b);
        close(w.t, -2.0, 1e-12);
        close(w.dof, 8.0, 1e-12);
        close(w.p, 0.080_516, 1e-5);
        assert_eq!(welch(&a, &a).p, 1.0);
    }
}
